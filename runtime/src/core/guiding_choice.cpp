#include "exitance/runtime/core/guiding_choice.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "exitance/common/guiding_auto_strategy.h"
#include "exitance/common/rng.h"
#include "exitance/runtime/core/estimates.h"

namespace exitance {

GuidingChoice::GuidingChoice(std::vector<uint32_t> texel_region, uint32_t region_count, uint32_t pilot,
                             uint32_t statistics_from, uint64_t seed, double measuring_share, bool records_on_host)
    : texel_region_(std::move(texel_region)),
      sums_(records_on_host ? texel_region_.size() * 2 : 0),
      regions_(region_count),
      pilot_(pilot),
      statistics_from_(std::min(statistics_from, pilot)),
      seed_(seed),
      measuring_below_(measuring_share >= 1 ? UINT64_MAX : uint64_t(std::max(0.0, measuring_share) * 0x1.0p64)),
      measuring_share_(std::clamp(measuring_share, 0.0, 1.0)) {
  if (pilot_ < 2 || (pilot_ & (pilot_ - 1)) != 0) throw std::invalid_argument("GuidingChoice: the pilot must be a power of two >= 2");
  for (uint32_t r : texel_region_) {
    if (r >= region_count) throw std::invalid_argument("GuidingChoice: a texel's region is out of range");
    ++regions_[r].texels;
  }
}

bool GuidingChoice::measuring(size_t texel) const {
  return splitmix64(seed_ ^ 0x3EA5B1C9D07F2E61ull ^ uint64_t(texel)) < measuring_below_ || measuring_below_ == UINT64_MAX;
}

uint32_t GuidingChoice::strategy_sample_index(size_t texel, uint32_t sample, bool guided) const {
  if (abandoned_) return sample;  // no candidate sample was taken: the unguided sequence, unbroken
  return auto_strategy_sample_index(measuring(texel) ? kAutoMeasuring : 0u, sample, pilot_, guided);
}

bool GuidingChoice::sample_guided(size_t texel, uint32_t sample) const {
  return auto_sample_guided(strategy_word(texel), sample, pilot_);
}

uint32_t GuidingChoice::strategy_word(size_t texel) const {
  if (abandoned_) return kAutoDecided;  // unguided, at its own index (strategy_sample_index)
  // The measuring bit stays after the choice: the texel's sample indices depend on its pilot.
  const uint32_t word = measuring(texel) ? kAutoMeasuring : 0u;
  if (decided_) return word | kAutoDecided | (texel_guided_[texel] != 0 ? kAutoGuided : 0u);
  // Which half of the pilot is guided: a hash of (seed, texel) with its own salt (see the header).
  const bool guided_first = !candidate_half_second_ && (splitmix64(seed_ ^ 0x6A1D1C401CE5A17Bull ^ uint64_t(texel)) >> 63) != 0;
  return word != 0 && guided_first ? word | kAutoGuidedFirst : word;
}

void GuidingChoice::abandon() {
  if (!candidate_half_second_) throw std::logic_error("GuidingChoice::abandon: candidate samples may have been taken");
  abandoned_ = decided_ = true;
  texel_guided_.assign(texel_region_.size(), 0);
  texels_guided_ = 0;
}

void GuidingChoice::record(size_t texel, uint32_t sample, bool guided, double luminance, uint64_t rays,
                           uint64_t guided_vertices) {
  if (decided_ || sample < statistics_from_ || sample >= pilot_) return;
  if (sums_.empty()) throw std::logic_error("GuidingChoice::record: made for sums recorded elsewhere (add_sums)");
  StrategySums& s = sums_[texel * 2 + (guided ? 1 : 0)];
  const double y2 = luminance * luminance;
  ++s.samples;
  s.sum += luminance;
  s.sum_squared += y2;
  s.sum_cubed += y2 * luminance;
  s.sum_fourth += y2 * y2;
  s.rays += rays;
  s.guided_vertices += guided_vertices;
}

void GuidingChoice::add_sums(size_t texel, bool guided, const StrategySums& add) {
  if (decided_) return;
  if (sums_.empty()) sums_.resize(texel_region_.size() * 2);
  StrategySums& s = sums_[texel * 2 + (guided ? 1 : 0)];
  s.samples += add.samples;
  s.sum += add.sum;
  s.sum_squared += add.sum_squared;
  s.sum_cubed += add.sum_cubed;
  s.sum_fourth += add.sum_fourth;
  s.rays += add.rays;
  s.guided_vertices += add.guided_vertices;
}

const StrategySums& GuidingChoice::sums(size_t texel, bool guided) const {
  static const StrategySums none;
  return sums_.empty() ? none : sums_[texel * 2 + (guided ? 1 : 0)];
}

uint32_t GuidingChoice::pilot_for(uint32_t spp, uint32_t learning_samples) {
  if (spp == 0 || spp >= 4 * learning_samples) return learning_samples;
  uint32_t pilot = 4;
  while (pilot * 2 <= spp / 4) pilot *= 2;
  return pilot;
}

void GuidingChoice::decide() {
  double sum = 0;
  uint64_t samples = 0;
  for (const StrategySums& s : sums_) sum += s.sum, samples += s.samples;
  decide(samples > 0 ? kErrorFloorFraction * sum / double(samples) : 0.0);
}

namespace {

constexpr double kUnboundedRatio = 1e30;  // finite, so the manifest's JSON can hold it

// A texel's sample variance and the variance of that estimate (iid samples: mu4 / n - sigma^4 (n - 3)
// / (n (n - 1)), with the central moments from the raw sums).
void sample_variance(const StrategySums& s, double& variance, double& variance_of_variance) {
  const double n = s.samples, m = s.sum / n;
  const double m2 = std::max(0.0, s.sum_squared / n - m * m);
  const double m4 = std::max(0.0, (s.sum_fourth - 4 * m * s.sum_cubed + 6 * m * m * s.sum_squared) / n - 3 * m * m * m * m);
  variance = m2 * n / (n - 1);
  variance_of_variance = std::max(0.0, m4 / n - variance * variance * (n - 3) / (n * (n - 1)));
}

}  // namespace

double EfficiencyEvidence::efficiency_ratio() const {
  if (texels_measured == 0) return 0.0;
  const double unguided = relative_variance[0] * cost_per_sample(0), guided = relative_variance[1] * cost_per_sample(1);
  // Guided without any variance against an unguided one with some: guiding pays without bound.
  return guided > 0 ? unguided / guided : unguided > 0 ? kUnboundedRatio : 0.0;
}

double EfficiencyEvidence::z() const {
  if (texels_measured == 0) return 0.0;
  const double cu = cost_per_sample(0), cg = cost_per_sample(1);
  const double d = relative_variance[0] * cu - relative_variance[1] * cg;
  const double se = std::sqrt(cu * cu * variance_of_variance[0] + cg * cg * variance_of_variance[1]);
  return se > 0 ? d / se : d > 0 ? kUnboundedRatio : d < 0 ? -kUnboundedRatio : 0.0;
}

ChoiceBasis choose(const EfficiencyEvidence& region, const EfficiencyEvidence& scene, bool& guided) {
  const double own = region.z(), all = scene.z();
  if (std::fabs(own) > kChoiceZ) return guided = own > 0, ChoiceBasis::Region;
  if (std::fabs(all) > kChoiceZ) return guided = all > 0, ChoiceBasis::Scene;
  guided = false;
  return ChoiceBasis::Default;
}

namespace {

void add(EfficiencyEvidence& to, const EfficiencyEvidence& e, double sign = 1) {
  to.texels_measured = uint32_t(int64_t(to.texels_measured) + int64_t(sign) * int64_t(e.texels_measured));
  for (int k = 0; k < 2; ++k) {
    // Clamped: a leave-one-out difference may round below 0.
    to.relative_variance[k] = std::max(0.0, to.relative_variance[k] + sign * e.relative_variance[k]);
    to.variance_of_variance[k] = std::max(0.0, to.variance_of_variance[k] + sign * e.variance_of_variance[k]);
    to.samples[k] = std::max(0.0, to.samples[k] + sign * e.samples[k]);
    to.cost[k] = std::max(0.0, to.cost[k] + sign * e.cost[k]);
  }
}

}  // namespace

void GuidingChoice::decide(double floor) {
  if (sums_.empty()) sums_.resize(texel_region_.size() * 2);  // nothing was added: every texel unmeasured
  // Serial, in texel order: the same sums give the same doubles on every run and thread count.
  std::vector<EfficiencyEvidence> texel(texel_region_.size()), region(regions_.size());
  scene_ = {};
  for (size_t i = 0; i < texel_region_.size(); ++i) {
    EfficiencyEvidence& t = texel[i];
    const StrategySums* s = &sums_[i * 2];
    for (int k = 0; k < 2; ++k) {
      t.samples[k] = s[k].samples;
      t.cost[k] = double(s[k].rays) + guided_vertex_cost_ * double(s[k].guided_vertices) +
                  (k == 1 ? guided_sample_cost_ * double(s[k].samples) : 0.0);
      if (k == 1) t.cost[k] *= guided_cost_factor_;
    }
    // Both strategies' variances are weighted by the same (pooled mean + floor)^2, so the comparison
    // is the one relMSE makes, and bright texels do not outvote dim ones.
    const double mean = s[0].samples + s[1].samples > 0 ? (s[0].sum + s[1].sum) / double(s[0].samples + s[1].samples) : 0.0;
    const double scale = (mean + floor) * (mean + floor);
    if (s[0].samples >= 2 && s[1].samples >= 2 && scale > 0) {
      t.texels_measured = 1;
      for (int k = 0; k < 2; ++k) {
        double variance = 0, variance_of_variance = 0;
        sample_variance(s[k], variance, variance_of_variance);
        t.relative_variance[k] = variance / scale;
        t.variance_of_variance[k] = variance_of_variance / (scale * scale);
      }
    }
    add(region[texel_region_[i]], t);
    add(scene_, t);
  }
  for (size_t r = 0; r < regions_.size(); ++r) {
    RegionChoice& out = regions_[r];
    const EfficiencyEvidence& e = region[r];
    out.texels_measured = e.texels_measured;
    for (int k = 0; k < 2; ++k) out.relative_variance[k] = e.relative_variance[k], out.cost_per_sample[k] = e.cost_per_sample(k);
    out.efficiency_ratio = e.efficiency_ratio();
    out.z = e.z();
    out.basis = choose(e, scene_, out.guided);
  }
  // Each texel: its region's and the scene's evidence without its own samples (see the header).
  texel_guided_.assign(texel_region_.size(), 0);
  texels_guided_ = 0;
  for (size_t i = 0; i < texel_region_.size(); ++i) {
    EfficiencyEvidence others = region[texel_region_[i]], everyone_else = scene_;
    add(others, texel[i], -1);
    add(everyone_else, texel[i], -1);
    bool guided = false;
    choose(others, everyone_else, guided);
    texel_guided_[i] = guided;
    texels_guided_ += guided;
    regions_[texel_region_[i]].texels_guided += guided;
  }
  decided_ = true;
}

double GuidingChoice::candidate_share(uint32_t begin, uint32_t samples) const {
  if (decided_) return guided_share();
  const uint32_t from = std::max(begin, pilot_ / 2), to = std::min(begin + samples, pilot_);
  return to > from ? measuring_share_ * double(to - from) / double(samples) : 0.0;
}

size_t GuidingChoice::regions_guided() const {
  size_t n = 0;
  for (const RegionChoice& r : regions_) n += r.guided ? 1 : 0;
  return n;
}

}  // namespace exitance
