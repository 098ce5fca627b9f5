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
};

// Opens BUNDLE and BUNDLE/scene.bin and checks that they describe the same instances. Throws
// ViewInputError (one line naming the file and the problem) for a missing or malformed bundle, a
// bundle without scene.bin, or instances that disagree.
ViewScene open_view_scene(const std::string& bundle_directory);

}  // namespace exitance::view
