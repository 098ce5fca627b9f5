// The CPU reference: an unbiased, deliberately simple path tracer of incident irradiance
// (stored as E/pi) at lightmap texels, on Embree. Every faster backend is checked against it.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

class EmbreeScene;

class CpuReferenceIntegrator final : public Integrator {
 public:
  // Shares the offline stage's scene and its Embree BVH (built once, also used by the scene checks).
  CpuReferenceIntegrator(std::shared_ptr<const LightingScene> scene, std::shared_ptr<const EmbreeScene> embree);
  // Copies `scene` and builds both (tests and tools that hold only a Scene).
  explicit CpuReferenceIntegrator(const Scene& scene);
  ~CpuReferenceIntegrator() override;
  CpuReferenceIntegrator(const CpuReferenceIntegrator&) = delete;
  CpuReferenceIntegrator& operator=(const CpuReferenceIntegrator&) = delete;

  std::string backend_name() const override { return "cpu"; }
  std::string device_description() const override;
  LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const override;
  // Uses spp (0 needs a time budget), time_budget_seconds, max_bounces, seed, russian_roulette_start,
  // safety_bounce_cap, progress; probes are independent of the lightmap bake. Also fills the ambient
  // cube (axis_irradiance_sum).
  ProbeEstimate bake_probes(const std::vector<Vec3>& positions, const IntegratorSettings& settings) const override;
  bool auto_guiding_may_measure_light_subpaths(const IntegratorSettings& settings) const override;

 private:
  struct Impl;
  Impl* impl_;
};

// The offline stage's lighting scene: `scene` copied, its BVH4 built by Embree (bvh4_builder.h).
std::shared_ptr<const LightingScene> make_lighting_scene(const Scene& scene);

}  // namespace exitance
