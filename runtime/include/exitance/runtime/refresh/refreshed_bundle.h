// A RefreshSession's state published as a bundle: probes (the bake's probe_spp and deringing),
// the SVO's radiant exitance and the lightmap pages from the session's lightmap, scene.bin as the
// session holds it, and the manifest with a "relight" entry; all written atomically (nothing is
// written on failure). What exitance-relight and the runtime's C API write.
#pragma once
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "exitance/runtime/refresh/refresh_session.h"

namespace exitance {

// A file of the bundle could not be written (nothing of it was left behind).
class BundleWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// (stage, fraction done, rays so far)
using StageProgress = std::function<void(const std::string&, double, uint64_t)>;

// `report`: figures of the caller's run, merged into the manifest's "relight" entry (the function
// adds source, device, samples, rays, estimated errors, probe rays). Returns that entry, plus
// "seconds" (probes, exitance, write) and "output". Throws BundleInputError when the manifest and
// scene.bin disagree, BundleWriteError when a file cannot be written, std::runtime_error when the
// device fails.
// `check_before_write` runs after all computing and before the first file is written (a caller's
// last chance to refuse, e.g. on validation-layer messages).
// The lightmap written is what the session shows (RefreshSession::shown_lightmap): with a denoise
// radius set, its indirect light filtered in texture space on the device (exitance-relight
// --denoise); the bundle then holds no light layers (they are not split into direct and indirect
// light) and the entry gets "denoise" (radius, texels, mean_neighbours, seconds).
nlohmann::json write_refreshed_bundle(RefreshSession& session, const std::string& output, nlohmann::json report,
                                      const StageProgress& progress = {},
                                      const std::function<void()>& check_before_write = {});

}  // namespace exitance
