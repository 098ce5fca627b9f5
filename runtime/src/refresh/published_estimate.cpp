#include "exitance/runtime/refresh/published_estimate.h"

#include <algorithm>
#include <stdexcept>

namespace exitance {
namespace {

void check_shapes(const LightmapEstimate& a, const LightmapEstimate& b, const char* call) {
  if (a.texels.size() != b.texels.size() || a.recorded_bounces != b.recorded_bounces || a.has_sh1() != b.has_sh1() ||
      a.light_layers != b.light_layers)
    throw std::invalid_argument(std::string(call) + ": the estimates differ in texels, recorded bounces, light layers or sh1 layers");
}

double channel_sum(const Vec3& v) { return double(v[0]) + double(v[1]) + double(v[2]); }

// Copies texel i (its sums, layers and sh1 sums) from `from` into `to`.
void copy_texel(const LightmapEstimate& from, LightmapEstimate& to, size_t i) {
  const size_t n = from.texels.size();
  to.texels[i] = from.texels[i];
  for (int k = 0; k < from.recorded_bounces; ++k)
    for (size_t c = 0; c < 3; ++c) to.bounces[(size_t(k) * n + i) * 3 + c] = from.bounces[(size_t(k) * n + i) * 3 + c];
  for (int k = 0; k < from.light_layers; ++k)
    for (size_t c = 0; c < 3; ++c) to.light_sums[(size_t(k) * n + i) * 3 + c] = from.light_sums[(size_t(k) * n + i) * 3 + c];
  if (from.has_sh1())
    for (size_t k = 0; k < 9; ++k) to.sh1[i * 9 + k] = from.sh1[i * 9 + k];
}

}  // namespace

LightmapEstimate add_change(const LightmapEstimate& base, const LightmapEstimate& change) {
  check_shapes(base, change, "add_change");
  LightmapEstimate sum = base;
  const size_t n = base.texels.size();
  for (size_t i = 0; i < n; ++i) {
    const TexelAccumulator& b = base.texels[i];
    const TexelAccumulator& d = change.texels[i];
    if (d.samples == 0) continue;
    if (b.samples == 0) {
      sum.texels[i] = TexelAccumulator{};
      continue;
    }
    // Over the two's samples: the mean is the sum of the means, the variance of the mean the sum of
    // the variances.
    const double m = double(b.samples) + double(d.samples);
    const Vec3 vb = base.variance_of_mean(i), vd = change.variance_of_mean(i);
    double mean[3], variance[3];
    for (int c = 0; c < 3; ++c) {
      mean[c] = b.total[c] / b.samples + d.total[c] / d.samples;
      variance[c] = double(vb[c]) + double(vd[c]);
    }
    TexelAccumulator& t = sum.texels[i];
    set_total_sums(t, uint32_t(m), mean, variance);
    for (int c = 0; c < 3; ++c) t.direct[c] = m * (b.direct[c] / b.samples + d.direct[c] / d.samples);
    for (int k = 0; k < base.recorded_bounces; ++k)
      for (size_t c = 0; c < 3; ++c) {
        const size_t at = (size_t(k) * n + i) * 3 + c;
        sum.bounces[at] = m * (base.bounces[at] / b.samples + change.bounces[at] / d.samples);
      }
    for (int k = 0; k < base.light_layers; ++k)
      for (size_t c = 0; c < 3; ++c) {
        const size_t at = (size_t(k) * n + i) * 3 + c;
        sum.light_sums[at] = m * (base.light_sums[at] / b.samples + change.light_sums[at] / d.samples);
      }
    if (base.has_sh1())
      for (size_t k = 0; k < 9; ++k) sum.sh1[i * 9 + k] = m * (base.sh1[i * 9 + k] / b.samples + change.sh1[i * 9 + k] / d.samples);
  }
  return sum;
}

bool can_be_change_base(const LightmapEstimate& estimate) {
  bool some = false;
  for (const TexelAccumulator& t : estimate.texels) {
    if (t.samples == 1) return false;
    some = some || t.samples >= 2;
  }
  return some;
}

LightmapEstimate publish_change(const LightmapEstimate& previous, const LightmapEstimate& base, const LightmapEstimate& change) {
  check_shapes(base, change, "publish_change");
  check_shapes(previous, change, "publish_change");
  LightmapEstimate published = add_change(base, change);
  for (size_t i = 0; i < change.texels.size(); ++i) {
    const Vec3 d = change.mean_total(i);
    const double squared = double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2];
    const uint32_t choice = publish_after_change(base.texels[i].samples, change.texels[i].samples, squared,
                                                 channel_sum(change.variance_of_mean(i)));
    if (choice == kPublishPrevious) copy_texel(previous, published, i);
    if (choice == kPublishBase) copy_texel(base, published, i);
  }
  return published;
}

LightmapEstimate publish_restart(const LightmapEstimate& previous, const LightmapEstimate& refreshed) {
  check_shapes(previous, refreshed, "publish_restart");
  LightmapEstimate published = refreshed;
  for (size_t i = 0; i < refreshed.texels.size(); ++i) {
    const Vec3 k = previous.mean_total(i), f = refreshed.mean_total(i);
    double difference = 0;
    for (int c = 0; c < 3; ++c) difference += (double(f[c]) - k[c]) * (double(f[c]) - k[c]);
    const TexelAccumulator& r = refreshed.texels[i];
    const bool all_zero = r.total[0] == 0 && r.total[1] == 0 && r.total[2] == 0;
    const uint32_t choice =
        publish_after_restart(previous.texels[i].samples, r.samples, difference, channel_sum(previous.variance_of_mean(i)),
                              channel_sum(refreshed.variance_of_mean(i)), all_zero);
    if (choice == kPublishPrevious) copy_texel(previous, published, i);
  }
  return published;
}

}  // namespace exitance
