// The C API over exitance::loader::Bundle: every entry point catches every exception and turns it
// into an ExitanceError plus a thread-local message, so no C++ exception crosses into C.
#include "exitance/loader/exitance_loader.h"

#include <atomic>
#include <new>
#include <stdexcept>
#include <string>

#include "exitance/loader/bundle.h"

struct ExitanceBundle {
  explicit ExitanceBundle(exitance::loader::Bundle&& b) : bundle(std::move(b)) {}
  std::atomic<uint32_t> references{1};
  exitance::loader::Bundle bundle;
};

namespace {

using exitance::formats::FileAccessError;
using exitance::formats::FormatError;
using exitance::loader::Bundle;

struct LastError {
  ExitanceError code = EXITANCE_ERROR_NONE;
  std::string message;
};
thread_local LastError last_error;

ExitanceError set_error(ExitanceError code, const std::string& message) {
  last_error.code = code;
  last_error.message = message;
  return code;
}

class NotPresent : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Runs body (which returns nothing or throws) and reports its outcome as an error code.
template <typename Body>
ExitanceError guarded(const char* function, Body&& body) {
  try {
    body();
    return set_error(EXITANCE_ERROR_NONE, "");
  } catch (const FileAccessError& e) {
    return set_error(EXITANCE_ERROR_IO, e.what());
  } catch (const FormatError& e) {
    return set_error(EXITANCE_ERROR_INVALID_FILE, e.what());
  } catch (const NotPresent& e) {
    return set_error(EXITANCE_ERROR_NOT_PRESENT, std::string(function) + ": " + e.what());
  } catch (const std::logic_error& e) {  // out_of_range, invalid_argument
    return set_error(EXITANCE_ERROR_INVALID_ARGUMENT, std::string(function) + ": " + e.what());
  } catch (const std::bad_alloc&) {
    return set_error(EXITANCE_ERROR_OUT_OF_MEMORY, std::string(function) + ": out of memory");
  } catch (const std::exception& e) {
    return set_error(EXITANCE_ERROR_UNKNOWN, std::string(function) + ": " + e.what());
  } catch (...) {
    return set_error(EXITANCE_ERROR_UNKNOWN, std::string(function) + ": unknown error");
  }
}

void require(bool condition, const char* what) {
  if (!condition) throw std::invalid_argument(what);
}

exitance::loader::Point3 point3(const float* p) { return {p[0], p[1], p[2]}; }

}  // namespace

extern "C" {

ExitanceError exitance_bundle_open(const char* directory, ExitanceBundle** out_bundle) {
  if (out_bundle) *out_bundle = nullptr;
  return guarded(__func__, [&] {
    require(directory && out_bundle, "directory and out_bundle must not be NULL");
    *out_bundle = new ExitanceBundle(Bundle::open(directory));
  });
}

void exitance_bundle_retain(ExitanceBundle* bundle) {
  guarded(__func__, [&] {
    require(bundle, "bundle must not be NULL");
    bundle->references.fetch_add(1, std::memory_order_relaxed);
  });
}

void exitance_bundle_release(ExitanceBundle* bundle) {
  guarded(__func__, [&] {
    if (bundle && bundle->references.fetch_sub(1, std::memory_order_acq_rel) == 1) delete bundle;
  });
}

ExitanceError exitance_last_error(void) { return last_error.code; }
const char* exitance_last_error_message(void) { return last_error.message.c_str(); }

uint32_t exitance_bundle_page_count(const ExitanceBundle* bundle) {
  uint32_t count = 0;
  guarded(__func__, [&] {
    require(bundle, "bundle must not be NULL");
    count = uint32_t(bundle->bundle.pages().size());
  });
  return count;
}

ExitanceError exitance_bundle_page(const ExitanceBundle* bundle, uint32_t page, ExitancePageInfo* out_info) {
  return guarded(__func__, [&] {
    require(bundle && out_info, "bundle and out_info must not be NULL");
    const auto& info = bundle->bundle.pages().at(page);
    *out_info = {info.width, info.height, uint32_t(info.channels.size()), info.file.c_str()};
  });
}

const char* exitance_bundle_page_channel(const ExitanceBundle* bundle, uint32_t page, uint32_t channel) {
  const char* name = nullptr;
  guarded(__func__, [&] {
    require(bundle, "bundle must not be NULL");
    name = bundle->bundle.pages().at(page).channels.at(channel).c_str();
  });
  return name;
}

uint32_t exitance_bundle_instance_count(const ExitanceBundle* bundle) {
  uint32_t count = 0;
  guarded(__func__, [&] {
    require(bundle, "bundle must not be NULL");
    count = uint32_t(bundle->bundle.instances().size());
  });
  return count;
}

ExitanceError exitance_bundle_instance(const ExitanceBundle* bundle, uint32_t instance, ExitanceInstanceInfo* out_info) {
  return guarded(__func__, [&] {
    require(bundle && out_info, "bundle and out_info must not be NULL");
    const auto& info = bundle->bundle.instances().at(instance);
    *out_info = {info.node, info.mesh, info.page, {}, info.name.c_str()};
    for (int i = 0; i < 4; ++i) out_info->scale_offset[i] = info.scale_offset[i];
  });
}

ExitanceError exitance_bundle_lightmap(const ExitanceBundle* bundle, uint32_t instance, float u, float v, float out_rgb[3]) {
  return guarded(__func__, [&] {
    require(bundle && out_rgb, "bundle and out_rgb must not be NULL");
    const auto rgb = bundle->bundle.lightmap(instance, {u, v});
    for (int c = 0; c < 3; ++c) out_rgb[c] = rgb[c];
  });
}

int exitance_bundle_has_probes(const ExitanceBundle* bundle) {
  int has = 0;
  guarded(__func__, [&] {
    require(bundle, "bundle must not be NULL");
    has = bundle->bundle.has_probes() ? 1 : 0;
  });
  return has;
}

ExitanceError exitance_bundle_probe_grid(const ExitanceBundle* bundle, ExitanceProbeGridInfo* out_info) {
  return guarded(__func__, [&] {
    require(bundle && out_info, "bundle and out_info must not be NULL");
    const auto* grid = bundle->bundle.probe_grid();
    if (!grid) throw NotPresent("the bundle has no probes");
    for (int a = 0; a < 3; ++a) {
      out_info->origin[a] = grid->origin[a];
      out_info->spacing[a] = grid->spacing[a];
      out_info->counts[a] = grid->counts[a];
    }
  });
}

ExitanceError exitance_bundle_probe_sh(const ExitanceBundle* bundle, const float point[3], float out_sh[27], int* out_usable) {
  return guarded(__func__, [&] {
    require(bundle && point && out_sh, "bundle, point and out_sh must not be NULL");
    if (!bundle->bundle.has_probes()) throw NotPresent("the bundle has no probes");
    const auto result = bundle->bundle.probe_sh(point3(point));
    for (int i = 0; i < 27; ++i) out_sh[i] = result.sh[i / 3][i % 3];
    if (out_usable) *out_usable = result.usable ? 1 : 0;
  });
}

ExitanceError exitance_bundle_probe_irradiance_over_pi(const ExitanceBundle* bundle, const float point[3],
                                                       const float normal[3], float out_rgb[3], int* out_usable) {
  return guarded(__func__, [&] {
    require(bundle && point && normal && out_rgb, "bundle, point, normal and out_rgb must not be NULL");
    if (!bundle->bundle.has_probes()) throw NotPresent("the bundle has no probes");
    const auto result = bundle->bundle.probe_irradiance_over_pi(point3(point), point3(normal));
    for (int c = 0; c < 3; ++c) out_rgb[c] = result.irradiance_over_pi[c];
    if (out_usable) *out_usable = result.usable ? 1 : 0;
  });
}

int exitance_bundle_has_svo(const ExitanceBundle* bundle) {
  int has = 0;
  guarded(__func__, [&] {
    require(bundle, "bundle must not be NULL");
    has = bundle->bundle.has_svo() ? 1 : 0;
  });
  return has;
}

ExitanceError exitance_bundle_svo_info(const ExitanceBundle* bundle, ExitanceSvoInfo* out_info) {
  return guarded(__func__, [&] {
    require(bundle && out_info, "bundle and out_info must not be NULL");
    const auto* svo = bundle->bundle.octree();
    if (!svo) throw NotPresent("the bundle has no SVO");
    for (int a = 0; a < 3; ++a) {
      out_info->bounds_min[a] = svo->origin[a];
      out_info->bounds_max[a] = svo->origin[a] + svo->size;
    }
    out_info->depth = svo->depth;
  });
}

ExitanceError exitance_bundle_svo_exitance(const ExitanceBundle* bundle, const float point[3], uint32_t max_level,
                                           const float normal[3], float out_rgb[3], uint32_t* out_level_reached,
                                           int* out_found) {
  return guarded(__func__, [&] {
    require(bundle && point && normal && out_rgb, "bundle, point, normal and out_rgb must not be NULL");
    if (!bundle->bundle.has_svo()) throw NotPresent("the bundle has no SVO");
    const auto result = bundle->bundle.svo_exitance(point3(point), max_level, point3(normal));
    for (int c = 0; c < 3; ++c) out_rgb[c] = result.exitance[c];
    if (out_level_reached) *out_level_reached = result.level;
    if (out_found) *out_found = result.found ? 1 : 0;
  });
}

}  // extern "C"
