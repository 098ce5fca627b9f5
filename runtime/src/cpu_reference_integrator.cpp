#include "exitance/runtime/cpu_reference_integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/light_sampler.h"
#include "exitance/runtime/material_eval.h"
#include "exitance/runtime/ray_offset.h"
#include "exitance/runtime/rng.h"
#include "exitance/runtime/sampling.h"

namespace exitance {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr int kMaxRecordedBounces = 16;

// Per-sample contributions to E/pi, split by the number of diffuse reflections between the
// light and the texel (0 = direct).
struct PathContributions {
  Vec3 by_bounce[kMaxRecordedBounces + 1];  // the last slot gathers every deeper bounce
  int recorded = 0;
  void add(int bounce, Vec3 value) { by_bounce[std::min(bounce, recorded)] += value; }
  Vec3 total() const {
    Vec3 sum{0, 0, 0};
    for (int k = 0; k <= recorded; ++k) sum += by_bounce[k];
    return sum;
  }
};

// Spot falloff of the KHR_lights_punctual reference implementation (squared linear ramp in cos).
float spot_attenuation(const PunctualLight& light, Vec3 light_to_point) {
  const float cd = dot(light.direction, light_to_point);
  const float scale = 1.0f / std::max(0.001f, light.cos_inner - light.cos_outer);
  const float t = std::clamp((cd - light.cos_outer) * scale, 0.0f, 1.0f);
  return t * t;
}

Vec3 interpolated_normal(const Scene& scene, uint32_t triangle, float b1, float b2) {
  const Vec3* n = &scene.normals[size_t(triangle) * 3];
  const Vec3 v = n[0] * (1.0f - b1 - b2) + n[1] * b1 + n[2] * b2;
  const float len = length(v);
  return len > 0 ? v / len : Vec3{0, 0, 0};
}

Vec3 surface_position(const Scene& scene, uint32_t triangle, float b1, float b2) {
  const Vec3* p = &scene.positions[size_t(triangle) * 3];
  return p[0] * (1.0f - b1 - b2) + p[1] * b1 + p[2] * b2;
}

}  // namespace

struct CpuReferenceIntegrator::Impl {
  const Scene& scene;
  EmbreeScene embree;
  LightSampler lights;

  explicit Impl(const Scene& s) : scene(s), embree(s), lights(s) {}

  Vec3 sky_radiance(Vec3 direction) const {
    return lights.environment().enabled() ? lights.environment().radiance(direction) : scene.sky.constant;
  }

  // Estimate of (1/pi) * integral of direct radiance * cos over the hemisphere at `x`,
  // from one sample of each light strategy. MIS partners are the cosine-sampled rays.
  Vec3 next_event(const SurfacePoint& x, Pcg32& rng, uint64_t& rays) const {
    Vec3 result{0, 0, 0};
    const Vec3 origin = offset_ray_origin(x.position, x.geometric_normal, embree.extent());
    if (lights.has_area_lights()) {
      const float uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
      const AreaLightSample s = lights.sample_area_light(uc, u1, u2);
      const Vec3 to_light = s.position - x.position;
      const float distance2 = dot(to_light, to_light);
      const float distance = std::sqrt(distance2);
      if (distance > 0) {
        const Vec3 wi = to_light / distance;
        const float cos_x = dot(x.shading_normal, wi);
        float cos_l = -dot(s.normal, wi);
        const Material& m = scene.materials[scene.triangle_material[s.triangle]];
        if (m.double_sided) cos_l = std::fabs(cos_l);
        if (cos_x > 0 && dot(x.geometric_normal, wi) > 0 && cos_l > 0) {
          const Vec3 light_normal_toward_x = dot(s.normal, wi) < 0 ? s.normal : -s.normal;
          const Vec3 target = offset_ray_origin(s.position, light_normal_toward_x, embree.extent());
          const Vec3 span = target - origin;
          const float span_length = length(span);
          ++rays;
          if (span_length > 0 && !embree.occluded(origin, span / span_length, span_length)) {
            const float pdf_light = s.pdf_area * distance2 / cos_l;
            const float pdf_cosine = cos_x * kInvPi;
            const float weight = power_heuristic(pdf_light, pdf_cosine);
            const Vec3 le = emitted_radiance(scene, s.triangle, s.b1, s.b2);
            result += le * (cos_x * kInvPi * weight / pdf_light);
          }
        }
      }
    }
    if (lights.has_punctual_lights()) {
      float probability = 0;
      const PunctualLight& light = lights.sample_punctual(rng.uniform(), probability);
      Vec3 wi;
      float distance = kInfinity;
      float falloff = 1.0f;
      if (light.type == PunctualLight::Type::Directional) {
        wi = -light.direction;
      } else {
        const Vec3 to_light = light.position - x.position;
        distance = length(to_light);
        wi = to_light / distance;
        falloff = 1.0f / (distance * distance);
        if (light.type == PunctualLight::Type::Spot) falloff *= spot_attenuation(light, -wi);
      }
      const float cos_x = dot(x.shading_normal, wi);
      if (distance > 0 && falloff > 0 && cos_x > 0 && dot(x.geometric_normal, wi) > 0 && probability > 0) {
        ++rays;
        if (!embree.occluded(origin, wi, distance))
          result += light.intensity * (falloff * cos_x * kInvPi / probability);
      }
    }
    if (lights.environment().enabled()) {
      float pdf_env = 0;
      const Vec3 wi = lights.environment().sample(rng.uniform(), rng.uniform(), pdf_env);
      const float cos_x = dot(x.shading_normal, wi);
      if (pdf_env > 0 && cos_x > 0 && dot(x.geometric_normal, wi) > 0) {
        ++rays;
        if (!embree.occluded(origin, wi, kInfinity)) {
          const float weight = power_heuristic(pdf_env, cos_x * kInvPi);
          result += lights.environment().radiance(wi) * (cos_x * kInvPi * weight / pdf_env);
        }
      }
    }
    return result;
  }

  // One path sample of E/pi at the texel.
  void trace(const SurfacePoint& texel, const IntegratorSettings& settings, Pcg32& rng, PathContributions& out,
             uint64_t& rays) const {
    SurfacePoint x = texel;
    Vec3 throughput{1, 1, 1};
    for (int depth = 0;; ++depth) {
      out.add(depth, throughput * next_event(x, rng, rays));
      const Vec3 local = sample_cosine_hemisphere(rng.uniform(), rng.uniform());
      const Vec3 wi = to_world(local, x.shading_normal);
      const float cos_g = dot(wi, x.geometric_normal);
      // A direction under the geometric surface would leave through the back: it carries no light here.
      if (!(cos_g > 0) || local.z <= 0) return;
      const float pdf_cosine = local.z * kInvPi;
      const Vec3 origin = offset_ray_origin(x.position, x.geometric_normal, embree.extent());
      ++rays;
      const Hit hit = embree.intersect(origin, wi, kInfinity);
      if (!hit.found) {
        float weight = 1.0f;
        if (lights.environment().enabled()) weight = power_heuristic(pdf_cosine, lights.environment().pdf(wi));
        out.add(depth, throughput * sky_radiance(wi) * weight);
        return;
      }
      const Material& material = scene.materials[scene.triangle_material[hit.triangle]];
      const bool front = dot(wi, hit.geometric_normal) < 0;
      if (front || material.double_sided) {
        const Vec3 le = emitted_radiance(scene, hit.triangle, hit.b1, hit.b2);
        if (max_component(le) > 0) {
          const float cos_l = std::fabs(dot(wi, hit.geometric_normal));
          const float pdf_light = lights.area_pdf(hit.triangle) * hit.distance * hit.distance / cos_l;
          out.add(depth, throughput * le * power_heuristic(pdf_cosine, pdf_light));
        }
      }
      // Back faces of single-sided surfaces absorb (glTF culls them; light cannot leave through them).
      if (!front && !material.double_sided) return;
      if (settings.max_bounces >= 0 && depth + 1 > settings.max_bounces) return;
      if (depth + 1 >= settings.safety_bounce_cap) return;
      throughput *= diffuse_albedo(scene, hit.triangle, hit.b1, hit.b2);
      if (depth + 1 >= settings.russian_roulette_start) {
        const float survive = std::min(1.0f, max_component(throughput));
        if (!(survive > 0) || rng.uniform() >= survive) return;
        throughput = throughput / survive;
      } else if (max_component(throughput) <= 0) {
        return;
      }
      x.geometric_normal = front ? hit.geometric_normal : -hit.geometric_normal;
      x.position = surface_position(scene, hit.triangle, hit.b1, hit.b2);
      Vec3 n = interpolated_normal(scene, hit.triangle, hit.b1, hit.b2);
      if (!front) n = -n;
      // Shading normals that face away from the geometric side would sample into the surface.
      x.shading_normal = dot(n, x.geometric_normal) > 0.05f ? n : x.geometric_normal;
    }
  }

  // Incident radiance at `origin` from direction -`direction` (see ProbeEstimate in the header).
  Vec3 radiance_along_ray(Vec3 origin, Vec3 direction, const IntegratorSettings& settings, Pcg32& rng,
                          uint64_t& rays, bool& backface) const {
    backface = false;
    ++rays;
    const Hit hit = embree.intersect(origin, direction, kInfinity);
    if (!hit.found) return sky_radiance(direction);
    const Material& material = scene.materials[scene.triangle_material[hit.triangle]];
    const bool front = dot(direction, hit.geometric_normal) < 0;
    if (!front && !material.double_sided) {
      backface = true;
      return {0, 0, 0};
    }
    Vec3 radiance = emitted_radiance(scene, hit.triangle, hit.b1, hit.b2);
    const Vec3 albedo = diffuse_albedo(scene, hit.triangle, hit.b1, hit.b2);
    if (max_component(albedo) <= 0) return radiance;
    SurfacePoint x;
    x.geometric_normal = front ? hit.geometric_normal : -hit.geometric_normal;
    x.position = surface_position(scene, hit.triangle, hit.b1, hit.b2);
    Vec3 n = interpolated_normal(scene, hit.triangle, hit.b1, hit.b2);
    if (!front) n = -n;
    x.shading_normal = dot(n, x.geometric_normal) > 0.05f ? n : x.geometric_normal;
    PathContributions contributions;
    contributions.recorded = 0;
    trace(x, settings, rng, contributions, rays);
    return radiance + albedo * contributions.total();
  }
};

CpuReferenceIntegrator::CpuReferenceIntegrator(const Scene& scene) : impl_(new Impl(scene)) {}
CpuReferenceIntegrator::~CpuReferenceIntegrator() { delete impl_; }

LightmapEstimate CpuReferenceIntegrator::bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const size_t texel_count = gbuffer.texels.size();
  LightmapEstimate estimate;
  estimate.recorded_bounces = std::clamp(settings.recorded_bounces, 1, kMaxRecordedBounces);
  estimate.texels.resize(texel_count);
  estimate.bounces.assign(size_t(estimate.recorded_bounces) * texel_count * 3, 0.0);
  std::vector<uint8_t> converged(texel_count, 0);
  tbb::combinable<uint64_t> rays_per_thread([] { return uint64_t(0); });
  tbb::combinable<uint64_t> nonfinite_per_thread([] { return uint64_t(0); });

  const uint32_t spp_limit = settings.spp == 0 ? std::numeric_limits<uint32_t>::max() : settings.spp;
  const bool timed = settings.time_budget_seconds > 0;
  uint32_t done = 0;
  while (done < spp_limit) {
    // Small passes early so progress and the time budget are honoured; larger later.
    const uint32_t pass = std::min<uint32_t>(spp_limit - done, done < 4 ? 1u : (done < 64 ? 4u : 16u));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, texel_count, 64), [&](const tbb::blocked_range<size_t>& range) {
      uint64_t& rays = rays_per_thread.local();
      uint64_t& nonfinite = nonfinite_per_thread.local();
      PathContributions contributions;
      for (size_t i = range.begin(); i != range.end(); ++i) {
        if (converged[i]) continue;
        const LiveTexel& texel = gbuffer.texels[i];
        const SurfacePoint point{texel.position, texel.geometric_normal, texel.shading_normal};
        TexelAccumulator& acc = estimate.texels[i];
        for (uint32_t s = done; s < done + pass; ++s) {
          Pcg32 rng(settings.seed, i, s);
          contributions = PathContributions{};
          contributions.recorded = estimate.recorded_bounces;
          impl_->trace(point, settings, rng, contributions, rays);
          const Vec3 total = contributions.total();
          if (!is_finite(total)) {
            ++nonfinite;
            continue;  // counted and reported; an unbiased estimator never produces these
          }
          for (int c = 0; c < 3; ++c) {
            acc.total[c] += total[c];
            acc.total_squared[c] += double(total[c]) * double(total[c]);
            acc.direct[c] += contributions.by_bounce[0][c];
          }
          for (int k = 0; k < estimate.recorded_bounces; ++k)
            for (int c = 0; c < 3; ++c)
              estimate.bounces[(size_t(k) * texel_count + i) * 3 + size_t(c)] += contributions.by_bounce[k][c];
          ++acc.samples;
        }
        if (settings.target_relative_error > 0 && acc.samples >= 16) {
          const Vec3 mean = estimate.mean_total(i);
          const Vec3 var = estimate.variance_of_mean(i);
          const float lum = luminance(mean);
          if (lum > 0 && std::sqrt(luminance(var)) <= settings.target_relative_error * lum) converged[i] = 1;
        }
      }
    });
    done += pass;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    const uint64_t rays_so_far = rays_per_thread.combine(std::plus<uint64_t>());
    if (settings.progress) {
      const double by_spp = settings.spp ? double(done) / double(settings.spp) : 0.0;
      const double by_time = timed ? elapsed / settings.time_budget_seconds : 0.0;
      settings.progress(std::min(1.0, std::max(by_spp, by_time)), rays_so_far);
    }
    if (timed && elapsed >= settings.time_budget_seconds) break;
    if (settings.target_relative_error > 0 &&
        std::all_of(converged.begin(), converged.end(), [](uint8_t c) { return c != 0; }))
      break;
  }
  estimate.rays = rays_per_thread.combine(std::plus<uint64_t>());
  estimate.nonfinite_samples = nonfinite_per_thread.combine(std::plus<uint64_t>());
  estimate.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return estimate;
}

ProbeEstimate CpuReferenceIntegrator::bake_probes(const std::vector<Vec3>& positions,
                                                  const IntegratorSettings& settings) const {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const size_t probe_count = positions.size();
  ProbeEstimate estimate;
  estimate.sh_sum.assign(probe_count, std::array<double, 27>{});
  estimate.axis_irradiance_sum.assign(probe_count, std::array<double, 18>{});
  estimate.samples.assign(probe_count, 0);
  estimate.backface_hits.assign(probe_count, 0);
  tbb::combinable<uint64_t> rays_per_thread([] { return uint64_t(0); });
  tbb::combinable<uint64_t> nonfinite_per_thread([] { return uint64_t(0); });
  const uint32_t spp = settings.spp == 0 ? std::numeric_limits<uint32_t>::max() : settings.spp;
  const bool timed = settings.time_budget_seconds > 0;
  uint32_t done = 0;
  while (done < spp) {
    // One complete stratified set per pass, so stopping on the time budget never leaves strata out.
    const uint32_t pass = std::min<uint32_t>(spp - done, kProbeStratifiedSetSize);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, probe_count, 1), [&](const tbb::blocked_range<size_t>& range) {
      uint64_t& rays = rays_per_thread.local();
      uint64_t& nonfinite = nonfinite_per_thread.local();
      for (size_t i = range.begin(); i != range.end(); ++i) {
        for (uint32_t s = done; s < done + pass; ++s) {
          Pcg32 rng(settings.seed, kProbeRngStreamBase + i, s);
          const float u1 = rng.uniform();
          const float u2 = rng.uniform();
          const Vec3 direction = probe_direction(s - done, pass, u1, u2);
          bool backface = false;
          const Vec3 radiance = impl_->radiance_along_ray(positions[i], direction, settings, rng, rays, backface);
          if (backface) ++estimate.backface_hits[i];
          if (!is_finite(radiance)) {
            ++nonfinite;
            continue;
          }
          const ShBasis y = sh_basis(direction);
          for (int k = 0; k < kShCoefficients; ++k)
            for (int c = 0; c < 3; ++c)
              estimate.sh_sum[i][size_t(k) * 3 + size_t(c)] += double(radiance[c]) * double(y[k]) * (4.0 * kPi);
          for (int axis = 0; axis < 6; ++axis) {
            const float cosine = (axis % 2 ? -1.0f : 1.0f) * direction[axis / 2];
            if (cosine <= 0) continue;
            for (int c = 0; c < 3; ++c)
              estimate.axis_irradiance_sum[i][size_t(axis) * 3 + size_t(c)] += double(radiance[c]) * cosine * 4.0;
          }
          ++estimate.samples[i];
        }
      }
    });
    done += pass;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (settings.progress) {
      const double by_spp = settings.spp ? double(done) / double(settings.spp) : 0.0;
      const double by_time = timed ? elapsed / settings.time_budget_seconds : 0.0;
      settings.progress(std::min(1.0, std::max(by_spp, by_time)), rays_per_thread.combine(std::plus<uint64_t>()));
    }
    if (timed && elapsed >= settings.time_budget_seconds) break;
  }
  estimate.rays = rays_per_thread.combine(std::plus<uint64_t>());
  estimate.nonfinite_samples = nonfinite_per_thread.combine(std::plus<uint64_t>());
  estimate.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return estimate;
}

}  // namespace exitance
