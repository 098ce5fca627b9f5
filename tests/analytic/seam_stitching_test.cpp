// Seam stitching on a known lightmap (runtime/include/exitance/runtime/bundle/seam_stitching.h): two charts that are one surface
// cut along a seam hold a smooth linear function, with a step added on one side. After stitching
// the sides agree (up to the value term's pull, bounded below), texels two or more texels from the
// seam are unchanged bit for bit, and nothing is non-finite.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/runtime/bundle/seam_discontinuity.h"
#include "exitance/runtime/bundle/seam_stitching.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"

namespace exitance {
namespace {

constexpr int kWidth = 40, kHeight = 20;
constexpr int kLeftX0 = 2, kRightX0 = 22, kChartWidth = 12, kY0 = 3, kChartHeight = 14;
constexpr float kStep = 0.3f;

// The surface's smooth lighting at (s, t) in texels along it; s runs across the seam at s = 12.
float smooth(float s, float t) { return 1.0f + 0.02f * s + 0.01f * t; }

// Left chart: s in [0, 12) at x in [2, 14); right chart: s in [12, 24) at x in [22, 34); rows
// y in [3, 17) in both. Its seam: the left chart's right border x = 14 is the right chart's left
// border x = 22. The right chart gets the step. The gutter is dilated as the assembly does.
formats::LightmapImage two_charts_with_a_step(int dilation_passes) {
  formats::LightmapImage page;
  page.width = kWidth;
  page.height = kHeight;
  const size_t n = size_t(kWidth) * kHeight;
  for (const char* name : {"R", "G", "B", "A", "error.Y", "direct.R", "direct.G", "direct.B"})
    page.channels[name].assign(n, 0.0f);
  for (int y = kY0; y < kY0 + kChartHeight; ++y)
    for (int i = 0; i < kChartWidth; ++i)
      for (int side = 0; side < 2; ++side) {
        const size_t at = size_t(y) * kWidth + size_t((side == 0 ? kLeftX0 : kRightX0) + i);
        const float s = float(side * kChartWidth + i) + 0.5f, t = float(y - kY0) + 0.5f;
        const float value = smooth(s, t) + (side == 1 ? kStep : 0.0f);
        for (const char* c : {"R", "G", "B"}) page.channels[c][at] = value;
        for (const char* c : {"direct.R", "direct.G", "direct.B"}) page.channels[c][at] = 0.5f * value;
        page.channels["A"][at] = 1.0f;
        page.channels["error.Y"][at] = 0.01f;
      }
  std::vector<float*> channels;
  for (auto& [name, data] : page.channels)
    if (name != "A") channels.push_back(data.data());
  dilate_into_gutter(kWidth, kHeight, page.channels["A"], channels, dilation_passes);
  return page;
}

std::vector<SeamEdge> the_seam() {
  SeamEdge seam;
  seam.side_a[0] = {float(kLeftX0 + kChartWidth), float(kY0)};
  seam.side_a[1] = {float(kLeftX0 + kChartWidth), float(kY0 + kChartHeight)};
  seam.side_b[0] = {float(kRightX0), float(kY0)};
  seam.side_b[1] = {float(kRightX0), float(kY0 + kChartHeight)};
  return {seam};
}

TEST(SeamStitching, StepAcrossASeamIsErasedAndFarTexelsKeepTheirValues) {
  SeamStitchSettings settings;
  settings.dilation_passes = 4;
  const std::vector<formats::LightmapImage> original = {two_charts_with_a_step(settings.dilation_passes)};
  std::vector<formats::LightmapImage> pages = original;
  const SeamStitchReport report = stitch_lightmap_seams(pages, the_seam(), settings);

  RecordProperty("discontinuity_before", std::to_string(report.discontinuity_before));
  RecordProperty("discontinuity_after", std::to_string(report.discontinuity_after));
  // Before: the step (0.3 on values about 1.25) plus the gutter's constant extension.
  EXPECT_GT(report.discontinuity_before, 0.2);
  // After: the value term (lambda) pulls each texel back toward its old value. Each texel on the
  // seam row is read by >= 3 samples per texel with bilinear weights whose squares sum to >= 1/4
  // per sample, a seam weight k >= 3/4 against lambda, so at the optimum the remaining difference
  // is at most lambda / (lambda + k) of the original one.
  const double lambda = settings.value_weight;
  EXPECT_LT(report.discontinuity_after, lambda / (lambda + 0.75) * report.discontinuity_before);
  // The report measures the pages as written (the gutter dilated again from stitched texels).
  const std::vector<SeamSample> samples = seam_samples(the_seam(), settings.samples_per_texel);
  EXPECT_NEAR(measure_seam_discontinuity(pages, samples).mean_relative_difference, report.discontinuity_after,
              1e-6);
  EXPECT_GT(report.texels_adjusted, 0u);

  // Texels two or more texels from the seam borders, in both charts, are unchanged; nothing is
  // NaN; A and error.Y are never touched.
  for (const auto& [name, values] : pages[0].channels)
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const size_t at = size_t(y) * kWidth + size_t(x);
        ASSERT_TRUE(std::isfinite(values[at])) << name << " at " << x << "," << y;
        const bool chart = original[0].channels.at("A")[at] > 0;
        const bool far_from_seam = x < kLeftX0 + kChartWidth - 2 || (x >= kRightX0 + 2 && x < kWidth);
        if (name == "A" || name == "error.Y" || (chart && far_from_seam)) {
          EXPECT_EQ(values[at], original[0].channels.at(name)[at]) << name << " at " << x << "," << y;
        }
      }
  // Both sides moved toward each other: the left border up, the right border down.
  const size_t row = size_t(kY0 + kChartHeight / 2) * kWidth;
  EXPECT_GT(pages[0].channels["R"][row + kLeftX0 + kChartWidth - 1],
            original[0].channels.at("R")[row + kLeftX0 + kChartWidth - 1]);
  EXPECT_LT(pages[0].channels["R"][row + kRightX0], original[0].channels.at("R")[row + kRightX0]);
}

TEST(SeamStitching, MeasureOnlyChangesNothing) {
  const std::vector<formats::LightmapImage> original = {two_charts_with_a_step(2)};
  const SeamStitchReport report = measure_lightmap_seams(original, the_seam());
  EXPECT_EQ(report.texels_adjusted, 0u);
  EXPECT_EQ(report.discontinuity_after, report.discontinuity_before);
  EXPECT_EQ(report.edges, 1u);
  EXPECT_NEAR(report.texel_relative_error, 0.01, 1e-6);
}

}  // namespace
}  // namespace exitance
