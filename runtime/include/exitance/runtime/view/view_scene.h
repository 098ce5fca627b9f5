// What exitance-view renders from: a bundle opened by the loader (lightmap pages, probes) and its
// scene.bin (triangles, materials, instances, cameras, sky, BVH4). No lighting code: the tool links
// the loader and formats only, so an engine team can run it anywhere.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/formats/scene_file.h"
#include "exitance/loader/bundle.h"

namespace exitance::view {

struct ViewScene {
  loader::Bundle bundle;
  formats::SceneFile scene;
  // Per scene.bin instance (= manifest instance): 1 when some live lightmap texel lies on one of its
  // triangles. An engine lights such an object from its lightmap; the others from the probes.
  std::vector<uint8_t> instance_has_texels;
  // Every page holds the nine L1 SH layers of `bake --directional sh1` (kSh1Channels): lightmap E/pi
  // is then evaluated at the pixel's (normal-mapped) normal (docs/view.md, "Directional lightmaps").
  bool has_sh1_layers = false;
};

// The directional layers' channels, axis-major: sh1.x.R, sh1.x.G, sh1.x.B, sh1.y.R, ..., sh1.z.B.
inline constexpr const char* kSh1Channels[9] = {"sh1.x.R", "sh1.x.G", "sh1.x.B", "sh1.y.R", "sh1.y.G",
                                                "sh1.y.B", "sh1.z.R", "sh1.z.G", "sh1.z.B"};

// Opens BUNDLE and BUNDLE/scene.bin and checks that they describe the same instances. Throws
// ViewInputError (one line naming the file and the problem) for a missing or malformed bundle, a
// bundle without scene.bin, or instances that disagree.
ViewScene open_view_scene(const std::string& bundle_directory);

}  // namespace exitance::view
