// Re-lighting a baked bundle from its scene.bin on the GPU, with no offline stage: what
// exitance-relight runs, through the runtime's RefreshSession (refresh/refresh_session.h). A
// relight never reads the input's lightmaps, probe coefficients or voxel exitance: it recomputes
// them all, in frames when a per-frame budget or a frame count is given.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "exitance/runtime/refresh/refresh_session.h"

namespace exitance {

// Bad input (exit status 2): the session's BundleInputError.
using RelightInputError = BundleInputError;

struct RelightOptions {
  std::string bundle;              // the input bundle folder (manifest.json + scene.bin + svo.bin ...)
  std::string output;              // empty: the input bundle, replaced atomically
  std::string edits_file;          // EDITS.json (docs/edits.md) applied before the refresh; empty: none
  // Limits; the lightmap refresh ends at whichever comes first.
  std::optional<uint32_t> spp;     // samples per texel; default: the bake's, or none with --time
  double time_budget_seconds = 0;  // > 0: the whole lightmap refresh
  double frame_budget_ms = 0;      // > 0: each frame (refresh call)
  uint32_t frames = 0;             // > 0: at most this many frames
  bool from_baked = true;          // start from the bundle's baked lightmap (RefreshSessionOptions::start_from_baked)
  bool light_layers = true;        // keep the estimate per light layer (RefreshSessionOptions::light_layers)
  // Keep them in a whole run too (no --frames, --budget-ms or --spp-before-edits), so that the bundle
  // written holds them (docs/bundle.md "Light layers"); off: a whole run only pays for them.
  bool whole_run_light_layers = false;
  uint32_t priority_samples = 32;  // RefreshSessionOptions::priority_samples (--priority-samples)
  uint32_t samples_before_edits = 0;  // > 0: refresh this many samples per texel before applying the edits
  bool page_images = false;        // with frames: after each frame, the page images an engine samples written (publish_page_images), timed
  bool frame_errors = true;        // with frames: each frame's estimated error (a read-back of the sums between frames)
  // > 0: --denoise [--denoise-radius]: the written lightmap's indirect light filtered in texture
  // space with this radius (RefreshSession::set_denoise_radius: what frames show is filtered too).
  int denoise_radius = 0;
  std::optional<uint64_t> seed;    // default: the bake's
  int device_index = -1;           // Vulkan device; -1 = prefer a discrete GPU
  bool validation = false;         // Vulkan validation layers; any message fails the relight
  bool stage_statistics = false;   // GPU time, rays and lane efficiency per wavefront stage (slower; benchmarks)
  uint32_t traversal_rays = 0;     // > 0: also time this many incoherent closest-hit rays alone (benchmarks)
  // "path" (progressive path tracing, frames) or "bounces" (the per-bounce mode in one run: no
  // --frames or --budget-ms; RefreshSession::bake_per_bounce).
  std::string integrator = "path";
  // "off", "grid" or "svo" (guided path tracing of the whole lightmap in one run, as bake --guiding
  // grid|svo on the Vulkan backend; svo's octree is the bundle's svo.bin: no --frames or --budget-ms;
  // RefreshSession::bake_guided).
  std::string guiding = "off";
  // "off" or "on": next-event estimation guided by emitter distributions learned during a whole run
  // (bake --emitter-guiding on; path tracing of the whole lightmap in one run, as --guiding).
  std::string emitter_guiding = "off";
  // "off" or "on": light subpaths the texels' paths connect to (bake --light-paths on; not with
  // --emitter-guiding on, --guiding or integrator "bounces"). With a time, frame count or frame budget
  // the progressive refresh's passes connect (RefreshSessionOptions::light_subpaths); else one whole run.
  std::string light_paths = "off";
  // Path tracing (unguided, or with light_paths "on") of the whole lightmap in one run, as `bake
  // --backend vulkan` lights it (RefreshSession::bake_path: its passes, --time counted from the run's
  // start, the read-back inside the lighting), instead of refresh calls: what the guided whole runs
  // (guiding, emitter_guiding) are compared with. Not with frames, a frame budget, guiding, the
  // per-bounce integrator or a share.
  bool whole_run = false;
  // With integrator "bounces": where the layer caches are built, "device" or "host" (the path before
  // the device built them, for A/B timing; the same results bit for bit).
  std::string bounce_caches = "device";
  // > 0: --share R/N, a benchmark of one rank's share of a split bake: rank `share_rank` of
  // `share_ranks` (the texel range bake under mpirun gives it) by path tracing in one run
  // (RefreshSession::bake_path), alone on this device; needs --spp; writes no bundle (the other
  // ranks' texels are empty). 0: the usual relight.
  int share_ranks = 0;
  int share_rank = 0;
  // Stage reporting: (stage, fraction done, rays so far).
  std::function<void(const std::string&, double, uint64_t)> progress;
};

// Runs the relight and writes the bundle atomically (nothing is written on failure; nothing at all
// with share_ranks > 0). Returns the run report (the manifest's "relight" entry, plus per-frame
// figures when frames were asked for; with share_ranks > 0 the run entry alone).
// Throws RelightInputError for bad input and std::runtime_error for other failures (no Vulkan
// device, device loss).
nlohmann::json relight_bundle(const RelightOptions& options);

}  // namespace exitance
