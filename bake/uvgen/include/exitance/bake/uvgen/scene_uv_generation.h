// The importer's meshes without lightmap UVs (MeshWithoutLightmapUvs) get generated UVs, written
// into Scene::lightmap_uv of every instance: one set per glTF mesh, shared by its instances, packed
// for the smallest of them so the 2-texel gap between charts holds at every rectangle the atlas
// layout gives them (see lightmap_uv_generation.h for why the density must be known here).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/uvgen/lightmap_uv_generation.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct MeshUvReport {
  int mesh = -1;
  std::string name;
  std::string missing_set;  // "" with --uv generate
  UvGenerationStats stats;
  double seconds = 0;
  std::vector<Vec2> corner_uv;  // per mesh corner (MeshWithoutLightmapUvs::indices), for --write-gltf
};

// `texel_density`: the layout's texels per scene unit; `max_side_texels`: the layout's usable page
// side (max page minus both paddings). progress(fraction) covers all meshes.
std::vector<MeshUvReport> generate_missing_lightmap_uvs(Scene& scene, const std::vector<MeshWithoutLightmapUvs>& meshes,
                                                        double texel_density, int max_side_texels,
                                                        const std::function<void(double)>& progress);

}  // namespace exitance
