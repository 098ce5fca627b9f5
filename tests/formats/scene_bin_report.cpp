// scene_bin_report SCENE.gltf OUT.bin [TEXEL_DENSITY]: runs the offline stage's geometry part
// (import, atlas layout at the default or given density, texel raster, unocclude, GPU BVH, probe
// placement), writes scene.bin and prints its size by section next to the lightmap pages' raw size.
// How the figures in the scene.bin report were made:
//   build/tests/formats/scene_bin_report build/samples/building.gltf /tmp/building-scene.bin
#include <cstdio>
#include <filesystem>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/bake/probes/probe_placement.h"
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/scene_file_conversion.h"

using namespace exitance;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s SCENE.gltf OUT.bin [TEXEL_DENSITY]\n", argv[0]);
    return 2;
  }
  AtlasSettings atlas;
  if (argc > 3) atlas.texel_density = std::stof(argv[3]);
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(argv[1], "", atlas, diagnostics);
  const formats::SceneBvh bvh = to_scene_bvh(build_bvh4(p.scene));
  const EmbreeScene embree(p.scene);
  const formats::ProbeGrid probes = place_probes(p.scene, embree, nullptr, ProbePlacementSettings{}).grid;
  const formats::SceneFile file = make_scene_file(p.scene, p.gbuffer, p.layout, &probes, bvh);
  formats::write_scene_file(argv[2], file);

  const double mib = 1024.0 * 1024.0;
  uint64_t atlas_texels = 0;
  for (const auto& [w, h] : p.layout.page_sizes) atlas_texels += uint64_t(w) * uint64_t(h);
  const size_t t = file.triangles.count(), x = file.texels.texels.size();
  std::printf("%s: density %.3g texels/unit, %zu pages, %llu atlas texels, %zu live, %zu moved\n", argv[1],
              p.layout.texel_density, p.layout.page_sizes.size(), (unsigned long long)atlas_texels, x,
              file.texels.moved.size());
  const uint64_t file_size = std::filesystem::file_size(argv[2]);
  const uint64_t triangle_bytes = t * (128 + 4 + 4), bvh_bytes = file.bvh.nodes.size() * 112;
  const uint64_t texel_bytes = x * formats::kSceneTexelSize;
  const uint64_t partial_bytes = file.texels.partial_coverage.size() * formats::kScenePartialCoverageSize;
  const uint64_t moved_bytes = file.texels.moved.size() * formats::kSceneMovedTexelSize;
  const uint64_t probe_bytes = file.probes.probes.size() * 16;
  // Version 2: textures and the environment map (20-byte head + f32 pixels), vertex colours.
  uint64_t texture_bytes = 0;
  for (const formats::TextureRecord& tex : file.textures) texture_bytes += 20 + 4 * (tex.rgb.size() + tex.alpha.size());
  if (file.sky_environment.width != 0)
    texture_bytes += 20 + 4 * (file.sky_environment.rgb.size() + file.sky_environment.alpha.size());
  const uint64_t colour_bytes = 16 * file.vertex_color.size();
  std::printf(
      "scene.bin %.2f MiB: %zu triangles %.2f MiB (incl. leaf slots and texel sizes), BVH %zu nodes %.2f MiB, "
      "texels %.2f MiB, partial coverage %zu %.2f MiB, moved %zu %.3f MiB, probes %zu %.3f MiB, "
      "textures %zu %.3f MiB, vertex colours %.3f MiB, header and named records %.3f MiB\n",
      double(file_size) / mib, t, double(triangle_bytes) / mib, file.bvh.nodes.size(), double(bvh_bytes) / mib,
      double(texel_bytes) / mib, file.texels.partial_coverage.size(), double(partial_bytes) / mib,
      file.texels.moved.size(), double(moved_bytes) / mib, file.probes.probes.size(), double(probe_bytes) / mib,
      file.textures.size(), double(texture_bytes) / mib, double(colour_bytes) / mib,
      double(file_size - triangle_bytes - bvh_bytes - texel_bytes - partial_bytes - moved_bytes - probe_bytes -
             texture_bytes - colour_bytes) /
          mib);
  std::printf("lightmap pages uncompressed (float32 R,G,B,A + direct.RGB + indirect.RGB = 40 B/texel): %.2f MiB\n",
              double(atlas_texels * 40) / mib);
  return 0;
}
