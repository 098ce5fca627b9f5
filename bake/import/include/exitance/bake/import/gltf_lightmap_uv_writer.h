// `bake --write-gltf FILE`: the input glTF written again with the lightmap UVs bake generated, so an
// engine can sample the lightmap with them.
#pragma once
#include <string>
#include <vector>

#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

// One glTF mesh's generated UVs: 3 per mesh triangle, numbered as the importer numbers them (its
// triangle primitives in order, strips and fans unrolled; MeshWithoutLightmapUvs).
struct MeshLightmapUvs {
  int mesh = -1;
  std::vector<Vec2> corner_uv;
};

// Writes `input` to `output` (a .gltf; every buffer embedded as a data URI, images referenced as the
// input references them) with each listed mesh's UVs as TEXCOORD_<uv_set> of its triangle
// primitives, which become indexed TRIANGLES whose vertices are split where the UVs differ: every
// attribute and morph target is remapped. A primitive without TEXCOORD_0 that gets TEXCOORD_1 also
// gets them as TEXCOORD_0 (glTF numbers sets from 0). The file is written beside `output` and
// renamed. Throws InputError for an output name that is not .gltf, std::runtime_error when writing fails.
void write_gltf_with_lightmap_uvs(const std::string& input, const std::string& output, int uv_set,
                                  const std::vector<MeshLightmapUvs>& meshes, Diagnostics& diagnostics);

}  // namespace exitance
