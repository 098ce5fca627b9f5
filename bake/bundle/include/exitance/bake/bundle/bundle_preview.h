// bake --preview (docs/bundle.md, "preview/"): pictures of a bundle for people, written into the
// bundle's staging folder with the rest of it. The lightmap pages as exitance-view's PNG tone curve
// shows them, and views rendered by the exitance_view library from the staged bundle: one per glTF
// camera, or one automatic view when the scene has none.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/lightmap_exr.h"

namespace exitance {

// Writes folder/preview/lightmap-<page>.png for every page and, when `folder` holds scene.bin
// (and the manifest and pages it refers to), folder/preview/view-<name>.png, `view_width` pixels
// wide. Without scene.bin, the block's views_skipped says why (`no_scene_reason`, the manifest's
// scene.skipped). Throws std::runtime_error when a file cannot be written.
formats::PreviewInfo write_bundle_preview(const std::filesystem::path& folder,
                                          const std::vector<formats::LightmapImage>& pages, uint32_t view_width,
                                          const std::string& no_scene_reason);

}  // namespace exitance
