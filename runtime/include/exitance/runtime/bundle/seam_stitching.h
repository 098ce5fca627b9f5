// Seam stitching (issue 13): least squares over the texels that bilinear lookups on seams read, as
// in "Seamless: seam erasure" (Liu, Ferguson, Jacobson 2017) and Godot's lightmapper:
//   minimize  sum over seam samples (bilinear_A(p) - bilinear_B(p))^2 + lambda sum (x - x_orig)^2
// per colour channel, by conjugate gradient (Eigen).
//
// It runs on the assembled pages, after the gutter dilation, because a lookup on a chart's border
// reads gutter texels: the gutter is what the engine sees there. The unknowns are only the covered
// texels; a gutter texel in a footprint enters as the average the dilation made of covered texels
// (the same passes, so the solve sees the linear map dilate_into_gutter applies). Afterwards the
// gutter is dilated again from the stitched texels, which then reproduces exactly the values the
// solve assumed. Texels outside every seam footprint are never changed.
#pragma once
#include <vector>

#include "exitance/runtime/bundle/seam_discontinuity.h"
#include "exitance/runtime/bundle/seam_samples.h"
#include "exitance/formats/lightmap_exr.h"

namespace exitance {

struct SeamStitchSettings {
  float samples_per_texel = 3;   // seam samples per texel of edge length
  // lambda, against a weight of 1 per sample: how much a texel holds to its own value. The seam
  // terms see only differences, so lambda alone fixes the sides' common level (at their values'
  // mean, whatever its size) and otherwise only leaves a remainder ~lambda/(lambda + 3/4) of each
  // difference. Not 0, which would leave the system singular; 0.005 left 3-9 % of the discontinuity
  // on the benchmark sphere (0.02: 7-10 %, 0.001: 2-3 % at 3x the solve time; bench/results/seams.md).
  double value_weight = 0.005;
  int dilation_passes = 2;       // the assembly's gutter dilation (AssemblyOptions::dilation_texels), >= 0
};

struct SeamStitchReport {
  size_t edges = 0;
  size_t samples = 0;
  size_t texels_adjusted = 0;    // covered texels that were unknowns of the solve
  double discontinuity_before = 0, discontinuity_after = 0;  // seam_discontinuity.h
  double texel_relative_error = 0;  // mean error.Y of the seam texels: the noise to compare with
};

// Stitches the colour channels ("R", "G", "B" and every "<layer>.R/G/B") of `pages` in place;
// "A", "valid" and "error.Y" are left alone (error.Y describes the estimate, not the stitched value).
// A page without "A" (coverage) is skipped. Never writes a non-finite value: a channel whose solve
// fails keeps its values.
SeamStitchReport stitch_lightmap_seams(std::vector<formats::LightmapImage>& pages, const std::vector<SeamEdge>& seams,
                                       const SeamStitchSettings& settings = {});

// The same report without changing the pages (--seams off): texels_adjusted 0, after = before.
SeamStitchReport measure_lightmap_seams(const std::vector<formats::LightmapImage>& pages,
                                        const std::vector<SeamEdge>& seams, const SeamStitchSettings& settings = {});

// Both, page by page, for pages assembled one at a time (a seam's two sides are on one page):
// page(p, image) for every page in ascending order stitches page p (or, with `stitch` false, only
// measures it), and report() after the last is what stitch_lightmap_seams / measure_lightmap_seams
// report for the pages together.
class SeamStitcher {
 public:
  SeamStitcher(const std::vector<SeamEdge>& seams, const SeamStitchSettings& settings, bool stitch);
  SeamStitcher(const SeamStitcher&) = delete;
  SeamStitcher& operator=(const SeamStitcher&) = delete;
  void page(size_t p, formats::LightmapImage& image);
  SeamStitchReport report() const;

 private:
  SeamStitchSettings settings_;
  bool stitch_;
  size_t edges_;
  std::vector<SeamSample> samples_;
  SeamDiscontinuityMeter before_, after_;
  size_t texels_adjusted_ = 0;
};

}  // namespace exitance
