#include "test_manifest.h"

namespace exitance::test {

nlohmann::json make_manifest(const std::optional<formats::ProbeGrid>& probes,
                             const std::optional<formats::SparseVoxelOctree>& svo) {
  using nlohmann::json;
  json manifest = {
      {"format_version", 1},
      {"generator", "exitance tests"},
      {"units", {{"lightmap", "irradiance_over_pi"}, {"probes", "incident_radiance_sh_l2"}, {"length", "scene"}}},
      {"pages", json::array({json{{"file", "lightmap-0.exr"}, {"width", kPage0Width}, {"height", kPage0Height},
                                  {"channels", {"A", "B", "G", "R"}}},
                             json{{"file", "lightmap-1.exr"}, {"width", 4}, {"height", 4}, {"channels", {"A", "B", "G", "R"}}}})},
      {"instances", json::array({json{{"node", 0}, {"name", "Floor"}, {"mesh", 0}, {"page", 0},
                                      {"scale_offset", kInstance0ScaleOffset}, {"rect", {2, 2, 4, 2}}},
                                 json{{"node", 3}, {"name", "Wall"}, {"mesh", 1}, {"page", 1},
                                      {"scale_offset", {1.0f, 1.0f, 0.0f, 0.0f}}}})},
      {"stats", {{"rays", 0}}}};
  if (probes)
    manifest["probes"] = {{"file", "probes.bin"}, {"origin", probes->origin}, {"spacing", probes->spacing},
                          {"counts", probes->counts}, {"sh_order", probes->sh_order}};
  if (svo) {
    const std::array<float, 3> far{svo->origin[0] + svo->size, svo->origin[1] + svo->size, svo->origin[2] + svo->size};
    manifest["svo"] = {{"file", "svo.bin"}, {"bounds", {svo->origin, far}}, {"depth", svo->depth}};
  }
  return manifest;
}

}  // namespace exitance::test
