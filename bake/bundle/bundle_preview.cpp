#include "exitance/bake/bundle/bundle_preview.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>

#include "exitance/bake/bundle/automatic_view.h"
#include "exitance/runtime/view/view_image_output.h"
#include "exitance/runtime/view/view_input_error.h"
#include "exitance/runtime/view/view_render.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPreviewFolder = "preview";
constexpr int kMaxViewEdge = 16384;  // exitance-view's --size limit

std::array<float, 3> array_of(Vec3 v) { return {v.x, v.y, v.z}; }

// E/pi of the page (its R, G, B channels) as a view image, so the page goes through exitance-view's
// PNG writer and tone curve unchanged.
view::ViewImage page_image(const formats::LightmapImage& page) {
  view::ViewImage image;
  image.width = page.width;
  image.height = page.height;
  image.rgb.assign(size_t(page.width) * size_t(page.height) * 3, 0.0f);
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const auto channel = page.channels.find(names[c]);
    if (channel == page.channels.end()) continue;
    for (size_t i = 0; i < channel->second.size(); ++i) image.rgb[i * 3 + size_t(c)] = channel->second[i];
  }
  return image;
}

// A file name from a camera's name: letters, digits, '-' and '_' kept, anything else '_', made
// unique among the views already named.
std::string view_file_name(const std::string& name, std::set<std::string>& taken) {
  std::string base;
  for (const char c : name) base += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  if (base.empty()) base = "camera";
  std::string file = std::string(kPreviewFolder) + "/view-" + base + ".png";
  for (int n = 2; taken.count(file); ++n) file = std::string(kPreviewFolder) + "/view-" + base + "-" + std::to_string(n) + ".png";
  taken.insert(file);
  return file;
}

// Renders and writes one view; returns its manifest entry.
formats::PreviewViewInfo write_view(const fs::path& folder, const view::ViewScene& scene,
                                    const view::PinholeCamera& camera, int width, int height,
                                    const std::string& file, const std::string& camera_name) {
  view::ViewRenderOptions options;
  options.width = width;
  options.height = height;
  view::write_view_image((folder / file).string(), view::render_view(scene, camera, options), 0);
  formats::PreviewViewInfo info;
  info.file = file;
  info.camera = camera_name;
  info.look_from = array_of(camera.eye);
  info.look_at = array_of(camera.eye + camera.forward);
  info.up = array_of(camera.up);
  info.yfov = float(2 * std::atan(camera.tan_half_yfov));
  info.width = uint32_t(width);
  info.height = uint32_t(height);
  return info;
}

std::vector<formats::PreviewViewInfo> write_views(const fs::path& folder, int width) {
  const view::ViewScene scene = view::open_view_scene(folder.string());
  std::vector<formats::PreviewViewInfo> views;
  std::set<std::string> taken;
  for (const formats::CameraRecord& record : scene.scene.cameras) {
    // Orthographic cameras and cameras outside the default scene have no view (as in exitance-view).
    if (record.type != formats::CameraType::Perspective || record.node < 0 ||
        !scene.scene.nodes[size_t(record.node)].in_scene)
      continue;
    view::GltfCameraView gltf;
    try {
      gltf = view::gltf_camera(scene.scene, record.name);
    } catch (const view::ViewInputError&) {
      continue;  // a degenerate camera transform: no picture rather than no bundle
    }
    const int height = gltf.aspect_ratio > 0
                           ? std::clamp(int(std::lround(width / double(gltf.aspect_ratio))), 1, kMaxViewEdge)
                           : width;
    views.push_back(write_view(folder, scene, gltf.camera, width, height, view_file_name(record.name, taken),
                               record.name));
  }
  if (views.empty() && scene.scene.triangles.count() > 0) {
    const AutomaticView automatic = choose_automatic_view(scene);
    const view::PinholeCamera camera =
        view::look_at_camera(automatic.look_from, automatic.look_at, automatic.up, automatic.yfov);
    views.push_back(write_view(folder, scene, camera, width, width, std::string(kPreviewFolder) + "/view-auto.png", ""));
  }
  return views;
}

}  // namespace

formats::PreviewInfo write_bundle_preview(const fs::path& folder, const std::vector<formats::LightmapImage>& pages,
                                          uint32_t view_width, const std::string& no_scene_reason) {
  if (view_width < 1 || view_width > uint32_t(kMaxViewEdge))  // the view library's size range
    throw std::runtime_error("--preview-size: " + std::to_string(view_width) + " is outside 1.." +
                             std::to_string(kMaxViewEdge));
  fs::create_directories(folder / kPreviewFolder);
  formats::PreviewInfo preview;
  try {
    for (size_t p = 0; p < pages.size(); ++p) {
      const std::string file = std::string(kPreviewFolder) + "/lightmap-" + std::to_string(p) + ".png";
      view::write_view_image((folder / file).string(), page_image(pages[p]), 0);
      preview.pages.push_back(file);
    }
    if (fs::exists(folder / "scene.bin"))
      preview.views = write_views(folder, int(view_width));
    else
      preview.views_skipped = "no scene.bin" + (no_scene_reason.empty() ? "" : " (" + no_scene_reason + ")");
  } catch (const view::ViewInputError& e) {  // the view library's errors are about its input: the staged bundle
    throw std::runtime_error(std::string("--preview: ") + e.what());
  }
  if (preview.views.empty() && preview.views_skipped.empty()) preview.views_skipped = "the scene has no triangles";
  return preview;
}

}  // namespace exitance
