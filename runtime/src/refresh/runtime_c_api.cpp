// The C API over RefreshSession: every entry point catches every exception and turns it into an
// ExitanceRuntimeError plus a thread-local message, so no C++ exception crosses into C.
#include "exitance/runtime/exitance_runtime.h"
#include "exitance/runtime/exitance_runtime_vulkan.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>

#include "exitance/formats/format_error.h"
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/refresh/refresh_session.h"
#include "exitance/runtime/refresh/refreshed_bundle.h"

struct ExitanceRuntime {
  std::unique_ptr<exitance::RefreshSession> session;
  std::vector<exitance::AtlasPage> pages;  // sizes, for the checks of read_page
};

namespace {

using namespace exitance;

struct LastError {
  ExitanceRuntimeError code = EXITANCE_RUNTIME_OK;
  std::string message;
};
thread_local LastError last_error;

ExitanceRuntimeError set_error(ExitanceRuntimeError code, const std::string& message) {
  last_error.code = code;
  last_error.message = message;
  return code;
}

class NoDevice : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <typename Body>
ExitanceRuntimeError guarded(const char* function, Body&& body) {
  try {
    body();
    return set_error(EXITANCE_RUNTIME_OK, "");
  } catch (const SceneEditError& e) {
    return set_error(EXITANCE_RUNTIME_BAD_EDIT, e.what());
  } catch (const BundleInputError& e) {
    return set_error(EXITANCE_RUNTIME_BAD_BUNDLE, e.what());
  } catch (const formats::FormatError& e) {
    return set_error(EXITANCE_RUNTIME_BAD_BUNDLE, e.what());
  } catch (const NoDevice& e) {
    return set_error(EXITANCE_RUNTIME_NO_DEVICE, std::string(function) + ": " + e.what());
  } catch (const BundleWriteError& e) {
    return set_error(EXITANCE_RUNTIME_IO, std::string(function) + ": " + e.what());
  } catch (const std::logic_error& e) {  // invalid_argument, out_of_range
    return set_error(EXITANCE_RUNTIME_INVALID_ARGUMENT, std::string(function) + ": " + e.what());
  } catch (const std::bad_alloc&) {
    return set_error(EXITANCE_RUNTIME_UNKNOWN, std::string(function) + ": out of host memory");
  } catch (const std::exception& e) {  // device loss, fence timeout, out of device memory
    return set_error(EXITANCE_RUNTIME_DEVICE_FAILED, std::string(function) + ": " + e.what());
  } catch (...) {
    return set_error(EXITANCE_RUNTIME_UNKNOWN, std::string(function) + ": unknown error");
  }
}

void require(bool condition, const char* what) {
  if (!condition) throw std::invalid_argument(what);
}

// exitance_runtime_open and _open_on_device (`device` null: the runtime's own device).
void open_runtime(const char* bundle, const ExitanceRuntimeOptions* options, const ExitanceRuntimeVulkanDevice* device,
                  ExitanceRuntime** out_runtime) {
  require(bundle != nullptr, "bundle is NULL");
  require(out_runtime != nullptr, "out_runtime is NULL");
  RefreshSessionOptions session_options;
  if (options) {
    session_options.device.device_index = options->device_index;
    if (options->has_seed) session_options.seed = options->seed;
    require(options->light_layers_off == 0 || options->light_layers_off == 1, "options->light_layers_off must be 0 or 1");
    session_options.light_layers = options->light_layers_off == 0;
  }
  if (device) {
    VulkanExternalDevice external;
    external.instance = device->instance;
    external.physical_device = device->physical_device;
    external.device = device->device;
    external.queue = device->queue;
    external.queue_family = device->queue_family;
    external.api_version = device->api_version;
    external.enabled_features = device->enabled_features;
    external.timeline_semaphore = device->timeline_semaphore != 0;
    if (!external.instance || !external.physical_device || !external.device || !external.queue)
      throw std::invalid_argument("device needs its instance, physical_device, device and queue");
    session_options.device.external_device = external;
  }
  auto runtime = std::make_unique<ExitanceRuntime>();
  if (!device && enumerate_vulkan_devices().empty()) throw NoDevice("no Vulkan device (no loader, driver or device)");
  try {
    runtime->session = RefreshSession::open(bundle, session_options);
  } catch (const BundleInputError&) {
    throw;
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw NoDevice(e.what());  // creating the backend: no usable device, or the scene needs what it lacks
  }
  runtime->pages = runtime->session->persisted().gbuffer.pages;
  *out_runtime = runtime.release();
}

int dilation_texels(const ExitanceRuntime* runtime) { return runtime->session->page_dilation_texels(); }

}  // namespace

extern "C" {

ExitanceRuntimeError exitance_runtime_open(const char* bundle, const ExitanceRuntimeOptions* options,
                                           ExitanceRuntime** out_runtime) {
  if (out_runtime) *out_runtime = nullptr;
  return guarded("exitance_runtime_open", [&] { open_runtime(bundle, options, nullptr, out_runtime); });
}

ExitanceRuntimeError exitance_runtime_open_on_device(const char* bundle, const ExitanceRuntimeOptions* options,
                                                     const ExitanceRuntimeVulkanDevice* device,
                                                     ExitanceRuntime** out_runtime) {
  if (out_runtime) *out_runtime = nullptr;
  return guarded("exitance_runtime_open_on_device", [&] {
    require(device != nullptr, "device is NULL");
    require(!options || options->device_index == -1, "options->device_index must be -1 on an engine's device");
    open_runtime(bundle, options, device, out_runtime);
  });
}

void exitance_runtime_release(ExitanceRuntime* runtime) { delete runtime; }

ExitanceRuntimeError exitance_runtime_last_error(void) { return last_error.code; }
const char* exitance_runtime_last_error_message(void) { return last_error.message.c_str(); }

ExitanceRuntimeError exitance_runtime_apply_edits(ExitanceRuntime* runtime, const char* edits_json) {
  return guarded("exitance_runtime_apply_edits", [&] {
    require(runtime != nullptr, "runtime is NULL");
    require(edits_json != nullptr, "edits_json is NULL");
    runtime->session->apply_edits(parse_scene_edits(edits_json, "exitance_runtime_apply_edits"));
  });
}

ExitanceRuntimeError exitance_runtime_refresh(ExitanceRuntime* runtime, double budget_ms, uint32_t max_samples_per_texel,
                                              ExitanceRefreshReport* out_report) {
  return guarded("exitance_runtime_refresh", [&] {
    require(runtime != nullptr, "runtime is NULL");
    const RefreshReport r = runtime->session->refresh({budget_ms, max_samples_per_texel});
    if (out_report)
      *out_report = {r.milliseconds, r.rays, r.samples_added, r.samples_per_texel, r.capped ? 1 : 0};
  });
}

ExitanceRuntimeError exitance_runtime_estimated_relative_mse(ExitanceRuntime* runtime, double* out_relative_mse) {
  return guarded("exitance_runtime_estimated_relative_mse", [&] {
    require(runtime != nullptr, "runtime is NULL");
    require(out_relative_mse != nullptr, "out_relative_mse is NULL");
    *out_relative_mse = RefreshSession::estimated_relative_mse(runtime->session->refreshed_lightmap());
  });
}

uint32_t exitance_runtime_page_count(const ExitanceRuntime* runtime) {
  return runtime ? uint32_t(runtime->pages.size()) : 0;
}

ExitanceRuntimeError exitance_runtime_page_info(const ExitanceRuntime* runtime, uint32_t page,
                                                ExitanceRuntimePageInfo* out_info) {
  return guarded("exitance_runtime_page_info", [&] {
    require(runtime != nullptr && out_info != nullptr, "runtime or out_info is NULL");
    if (page >= runtime->pages.size())
      throw std::out_of_range("page " + std::to_string(page) + " of " + std::to_string(runtime->pages.size()));
    *out_info = {uint32_t(runtime->pages[page].width), uint32_t(runtime->pages[page].height)};
  });
}

namespace {

// Page `page` of what the runtime shows (shown_lightmap) as bake would write it, after checking the
// caller's size (one error naming the page and both sizes).
formats::LightmapImage assembled_page(const ExitanceRuntime* runtime, uint32_t page, uint32_t width, uint32_t height) {
  if (page >= runtime->pages.size())
    throw std::out_of_range("page " + std::to_string(page) + " of " + std::to_string(runtime->pages.size()));
  const AtlasPage& info = runtime->pages[page];
  if (width != uint32_t(info.width) || height != uint32_t(info.height))
    throw std::invalid_argument("page " + std::to_string(page) + " is " + std::to_string(info.width) + " x " +
                                std::to_string(info.height) + ", not " + std::to_string(width) + " x " +
                                std::to_string(height));
  AssemblyOptions assembly;
  assembly.dilation_texels = dilation_texels(runtime);
  std::vector<formats::LightmapImage> pages =
      assemble_lightmap_pages(runtime->session->persisted().gbuffer, runtime->session->shown_lightmap(), assembly);
  return std::move(pages.at(page));
}

}  // namespace

ExitanceRuntimeError exitance_runtime_read_page(ExitanceRuntime* runtime, uint32_t page, float* out_rgb, uint32_t width,
                                                uint32_t height) {
  return guarded("exitance_runtime_read_page", [&] {
    require(runtime != nullptr && out_rgb != nullptr, "runtime or out_rgb is NULL");
    const formats::LightmapImage image = assembled_page(runtime, page, width, height);
    const float* channel[3] = {image.channels.at("R").data(), image.channels.at("G").data(), image.channels.at("B").data()};
    const size_t texels = size_t(width) * height;
    for (size_t i = 0; i < texels; ++i)
      for (int c = 0; c < 3; ++c) out_rgb[i * 3 + size_t(c)] = channel[c][i];
  });
}

ExitanceRuntimeError exitance_runtime_read_page_channel(ExitanceRuntime* runtime, uint32_t page, const char* channel,
                                                        float* out_values, uint32_t width, uint32_t height) {
  return guarded("exitance_runtime_read_page_channel", [&] {
    require(runtime != nullptr && out_values != nullptr && channel != nullptr, "runtime, channel or out_values is NULL");
    const formats::LightmapImage image = assembled_page(runtime, page, width, height);
    const auto found = image.channels.find(channel);
    if (found == image.channels.end()) {
      std::string names;
      for (const auto& entry : image.channels) names += (names.empty() ? "" : ", ") + entry.first;
      throw std::invalid_argument("channel \"" + std::string(channel) + "\" is not in page " + std::to_string(page) +
                                  " (it has " + names + ")");
    }
    std::copy(found->second.begin(), found->second.end(), out_values);
  });
}

ExitanceRuntimeError exitance_runtime_probe_count(const ExitanceRuntime* runtime, uint32_t* out_count) {
  return guarded("exitance_runtime_probe_count", [&] {
    require(runtime != nullptr && out_count != nullptr, "runtime or out_count is NULL");
    const PersistedScene& persisted = runtime->session->persisted();
    *out_count = persisted.has_probe_grid() && runtime->session->manifest().probes ? uint32_t(persisted.probes.probes.size()) : 0u;
  });
}

ExitanceRuntimeError exitance_runtime_read_probes(ExitanceRuntime* runtime, float* out_sh, uint32_t count, uint32_t* out_samples) {
  return guarded("exitance_runtime_read_probes", [&] {
    require(runtime != nullptr && (out_sh != nullptr || count == 0), "runtime or out_sh is NULL");
    const formats::ProbeGrid grid = runtime->session->published_probes();
    if (count != grid.probes.size())
      throw std::invalid_argument("count " + std::to_string(count) + " is not the bundle's " + std::to_string(grid.probes.size()) +
                                  " probes (exitance_runtime_probe_count)");
    for (size_t i = 0; i < grid.probes.size(); ++i) {
      const bool used = formats::probe_is_usable(grid.probes[i]);
      for (size_t k = 0; k < 27; ++k) out_sh[i * 27 + k] = used ? grid.probes[i].sh[k] : 0.0f;
    }
    if (out_samples) *out_samples = runtime->session->probe_samples();
  });
}

ExitanceRuntimeError exitance_runtime_set_probe_budget_share(ExitanceRuntime* runtime, double share) {
  return guarded("exitance_runtime_set_probe_budget_share", [&] {
    require(runtime != nullptr, "runtime is NULL");
    require(share >= 0 && share <= 1, "share is not in [0, 1]");
    runtime->session->set_probe_budget_share(share);
  });
}

ExitanceRuntimeError exitance_runtime_set_light_paths(ExitanceRuntime* runtime, int32_t on, double subpaths_per_sample) {
  return guarded("exitance_runtime_set_light_paths", [&] {
    require(runtime != nullptr, "runtime is NULL");
    require(on == 0 || on == 1, "on must be 0 or 1");
    require(subpaths_per_sample >= 0 && subpaths_per_sample <= 64, "subpaths_per_sample is not 0 (the default) or in (0, 64]");
    runtime->session->set_light_subpaths(on == 1, subpaths_per_sample == 0 ? IntegratorSettings{}.light_subpaths_per_sample
                                                                            : subpaths_per_sample);
  });
}

ExitanceRuntimeError exitance_runtime_voxel_count(const ExitanceRuntime* runtime, uint32_t* out_count) {
  return guarded("exitance_runtime_voxel_count", [&] {
    require(runtime != nullptr && out_count != nullptr, "runtime or out_count is NULL");
    const formats::SparseVoxelOctree* svo = runtime->session->svo();
    *out_count = svo ? uint32_t(svo->nodes.size()) : 0u;
  });
}

ExitanceRuntimeError exitance_runtime_read_voxel_exitance(ExitanceRuntime* runtime, float* out_exitance, uint32_t count) {
  return guarded("exitance_runtime_read_voxel_exitance", [&] {
    require(runtime != nullptr && (out_exitance != nullptr || count == 0), "runtime or out_exitance is NULL");
    const formats::SparseVoxelOctree* bundled = runtime->session->svo();
    const size_t nodes = bundled ? bundled->nodes.size() : 0;
    if (count != nodes)
      throw std::invalid_argument("count " + std::to_string(count) + " is not the bundle's " + std::to_string(nodes) +
                                  " octree nodes (exitance_runtime_voxel_count)");
    if (nodes == 0) return;
    const std::optional<formats::SparseVoxelOctree> shown = runtime->session->published_voxel_exitance();
    for (size_t i = 0; i < nodes; ++i)
      for (size_t k = 0; k < 6; ++k)
        out_exitance[i * 6 + k] = formats::half_to_float(shown->nodes[i].exitance[k]) * shown->exitance_scale;
  });
}

ExitanceRuntimeError exitance_runtime_set_denoise_radius(ExitanceRuntime* runtime, int32_t radius) {
  return guarded("exitance_runtime_set_denoise_radius", [&] {
    require(runtime != nullptr, "runtime is NULL");
    runtime->session->set_denoise_radius(radius);
  });
}

ExitanceRuntimeError exitance_runtime_vulkan_device(const ExitanceRuntime* runtime, ExitanceRuntimeVulkanDevice* out_device) {
  return guarded("exitance_runtime_vulkan_device", [&] {
    require(runtime != nullptr && out_device != nullptr, "runtime or out_device is NULL");
    const VulkanExternalDevice d = runtime->session->integrator().vulkan_device();
    *out_device = {d.instance, d.physical_device, d.device, d.queue, d.queue_family, d.api_version, d.enabled_features,
                   d.timeline_semaphore ? 1 : 0};
  });
}

ExitanceRuntimeError exitance_runtime_publish_page_images(ExitanceRuntime* runtime, ExitanceRuntimePageImage* out_images,
                                                          uint32_t image_count, ExitanceRuntimeImagesReady* out_ready) {
  return guarded("exitance_runtime_publish_page_images", [&] {
    require(runtime != nullptr && out_images != nullptr, "runtime or out_images is NULL");
    if (image_count < runtime->pages.size())
      throw std::invalid_argument("image_count is " + std::to_string(image_count) + ", the bundle has " +
                                  std::to_string(runtime->pages.size()) + " pages");
    const DevicePageImages& images = runtime->session->publish_page_images(dilation_texels(runtime));
    for (size_t p = 0; p < images.pages.size(); ++p)
      out_images[p] = {images.pages[p].image, images.pages[p].view, images.format, images.layout, images.pages[p].width,
                       images.pages[p].height};
    if (out_ready) *out_ready = {images.ready, images.ready_value, images.queue_family};
  });
}

ExitanceRuntimeError exitance_runtime_publish_probes(ExitanceRuntime* runtime, ExitanceRuntimeProbeBuffer* out_buffer,
                                                     ExitanceRuntimeImagesReady* out_ready) {
  return guarded("exitance_runtime_publish_probes", [&] {
    require(runtime != nullptr && out_buffer != nullptr, "runtime or out_buffer is NULL");
    const DeviceProbeBuffer& probes = runtime->session->publish_probe_buffer();
    *out_buffer = {probes.buffer, probes.size, probes.probes};
    if (out_ready) *out_ready = {probes.ready, probes.ready_value, probes.queue_family};
  });
}

ExitanceRuntimeError exitance_runtime_publish_voxel_exitance(ExitanceRuntime* runtime, ExitanceRuntimeVoxelBuffer* out_buffer,
                                                             ExitanceRuntimeImagesReady* out_ready) {
  return guarded("exitance_runtime_publish_voxel_exitance", [&] {
    require(runtime != nullptr && out_buffer != nullptr, "runtime or out_buffer is NULL");
    const DeviceVoxelExitance& voxels = runtime->session->publish_voxel_exitance();
    *out_buffer = {voxels.buffer, voxels.size, voxels.nodes};
    if (out_ready) *out_ready = {voxels.ready, voxels.ready_value, voxels.queue_family};
  });
}

ExitanceRuntimeError exitance_runtime_write_bundle(ExitanceRuntime* runtime, const char* output_folder) {
  return guarded("exitance_runtime_write_bundle", [&] {
    require(runtime != nullptr && output_folder != nullptr, "runtime or output_folder is NULL");
    nlohmann::json report;
    report["api"] = "exitance_runtime_write_bundle";
    write_refreshed_bundle(*runtime->session, output_folder, report);
  });
}

}  // extern "C"
