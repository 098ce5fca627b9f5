// What a bake asks of an integrator, whatever the backend.
#pragma once
#include <cstdint>
#include <functional>

namespace exitance {

struct IntegratorSettings {
  uint32_t spp = 128;              // samples per texel; 0 = until the time budget ends
  double time_budget_seconds = 0;  // 0 = no budget
  double target_relative_error = 0;  // stop a texel when its relative standard error is below this; 0 = off
  int max_bounces = -1;            // diffuse bounces after the first hit; -1 = until Russian roulette
  uint64_t seed = 0;
  int recorded_bounces = 4;        // layers bounce0 (= direct) .. bounce<K-1> kept separately
  int russian_roulette_start = 3;  // first bounce at which roulette may end a path
  int safety_bounce_cap = 4096;    // never reached by paths of albedo < 0.998 in practice; documented
  uint32_t sampling_strategy = 0;  // continuation directions: kStrategyCosine (path.h); guided strategies later
  std::function<void(double fraction_done, uint64_t rays)> progress;  // called between passes
};

// Sums of per-sample estimates of E/pi (RGB, doubles so long runs keep precision).
}  // namespace exitance
