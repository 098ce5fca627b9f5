// The cache keys of the offline stages (issue 12, "Skip": a changed light re-runs only the lighting;
// a moved mesh re-runs what depends on geometry). Each key is one SHA-256 over exactly what its
// stage reads, plus the program (its executable's hash), a key version and the input path (the
// stages' warnings name the file). What each stage reads, and so hashes:
//
//   layout           world positions, lightmap UVs, triangle->instance, instances (node, mesh,
//                    triangles, transform, name), --texel-density, --max-page, padding, texel cap
//   gbuffer          (raster + unocclude) the layout key, shading normals, the albedo inputs
//                    (base colour factor and texture, metallic, COLOR_0, TEXCOORD_0, textures) and
//                    the ray visibility inputs (below): unocclude traces rays
//   checks           the gbuffer key, visibility, punctual lights' type, name and position (enclosed
//                    lights), which triangles are emissive (zero-area emitters)
//   sealed_texels    the gbuffer key, visibility, punctual lights' type, position and direction
//   voxelize         the layout key (its texel density sets the default depth), positions (the
//                    leaf normals are the triangles' own), --voxel-resolution
//   probe_placement  positions, instances, visibility, the voxelize key (or none), --probes
//
// Visibility: what decides whether a ray stops at a surface or which side is dead: triangle
// materials' alphaMode, cutoff, base alpha, base colour texture, doubleSided, with both UV sets
// (a texture binding may read either), COLOR_0 alpha and the textures. Light intensity and colour, spot cones, emission strength, the sky
// and every lighting option are in no key: they change the lighting stage only.
#pragma once
#include <string>

#include "exitance/bake/bake_options.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct StageCacheKeys {
  std::string layout, gbuffer, checks, sealed_texels, voxelize, probe_placement;
};

// `scene`: after UV generation (the lightmap UVs the layout reads). `program`: the executable's
// identity (program_identity() in bake_cache_key.h).
StageCacheKeys stage_cache_keys(const Scene& scene, const BakeOptions& options, const std::string& program);

}  // namespace exitance
