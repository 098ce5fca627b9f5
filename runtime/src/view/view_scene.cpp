#include "exitance/runtime/view/view_scene.h"

#include <filesystem>

#include "exitance/runtime/view/view_input_error.h"

namespace exitance::view {
namespace fs = std::filesystem;

namespace {

formats::SceneFile read_bundle_scene(const loader::Bundle& bundle, const std::string& directory) {
  const auto& info = bundle.manifest().scene;
  if (info && !info->skipped.empty())
    throw ViewInputError(directory + ": scene.bin: the bake did not write it (" + info->skipped + ")");
  const fs::path path = fs::path(directory) / (info && !info->file.empty() ? info->file : "scene.bin");
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw ViewInputError(path.string() + ": does not exist (views need scene.bin)");
  try {
    return formats::read_scene_file(path.string());
  } catch (const formats::FormatError& e) {
    throw ViewInputError(e.what());
  }
}

}  // namespace

ViewScene open_view_scene(const std::string& bundle_directory) {
  std::error_code ec;
  if (!fs::is_directory(bundle_directory, ec))
    throw ViewInputError(bundle_directory + ": is not a bundle folder (it does not exist or is not a folder)");
  ViewScene view{[&] {
                   try {
                     return loader::Bundle::open(bundle_directory);
                   } catch (const formats::FormatError& e) {
                     throw ViewInputError(e.what());
                   }
                 }(),
                 {},
                 {}};
  view.scene = read_bundle_scene(view.bundle, bundle_directory);
  const auto& manifest_instances = view.bundle.instances();
  const auto& scene_instances = view.scene.instances;
  if (manifest_instances.size() != scene_instances.size())
    throw ViewInputError(bundle_directory + ": scene.bin has " + std::to_string(scene_instances.size()) +
                         " instances, manifest.json " + std::to_string(manifest_instances.size()));
  for (size_t i = 0; i < scene_instances.size(); ++i) {
    const int32_t node = scene_instances[i].node;
    if (node >= 0 && uint32_t(node) != manifest_instances[i].node)
      throw ViewInputError(bundle_directory + ": instance " + std::to_string(i) + ": scene.bin places node " +
                           std::to_string(node) + ", manifest.json node " + std::to_string(manifest_instances[i].node));
  }
  view.has_sh1_layers = true;
  for (const char* channel : kSh1Channels) view.has_sh1_layers = view.has_sh1_layers && view.bundle.has_lightmap_channel(channel);
  // scene.bin's per-triangle texel size is 0 exactly for triangles without a live texel.
  view.instance_has_texels.assign(scene_instances.size(), 0);
  const auto& texel_size = view.scene.texels.triangle_texel_size;
  for (size_t t = 0; t < texel_size.size(); ++t)
    if (texel_size[t] > 0) view.instance_has_texels[view.scene.triangles.instance[t]] = 1;
  return view;
}

}  // namespace exitance::view
