#include "exitance/runtime/bundle/seam_stitching.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <unordered_map>

#include "exitance/runtime/bundle/seam_discontinuity.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"

namespace exitance {
namespace {

bool is_colour_channel(const std::string& name) {
  if (name == "R" || name == "G" || name == "B") return true;
  return name.size() > 2 && name[name.size() - 2] == '.' &&
         (name.back() == 'R' || name.back() == 'G' || name.back() == 'B') && name != "error.Y";
}

using TexelWeights = std::vector<std::pair<size_t, double>>;

// A texel as a weighted sum of covered texels (itself if covered; the dilation's average of its
// earlier-filled neighbours if not), memoized. A never-filled texel maps to itself: a constant.
// dilate_into_gutter fills in pass k exactly the texels at Chebyshev distance k from the nearest
// covered texel (8 neighbours per pass), so a texel's pass is found in the window around it
// without running the dilation over the page.
class DilationMap {
 public:
  DilationMap(int width, int height, const std::vector<float>& coverage, int passes)
      : width_(width), height_(height), coverage_(coverage), passes_(std::max(0, passes)) {}

  // 0 covered, k in 1..passes filled by pass k, -1 never filled.
  int pass(size_t texel) {
    auto found = pass_memo_.find(texel);
    if (found != pass_memo_.end()) return found->second;
    const int x = int(texel % size_t(width_)), y = int(texel / size_t(width_));
    int best = coverage_[texel] > 0 ? 0 : -1;
    for (int dy = -passes_; dy <= passes_; ++dy)
      for (int dx = -passes_; dx <= passes_; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= width_ || ny >= height_) continue;
        if (!(coverage_[size_t(ny) * size_t(width_) + size_t(nx)] > 0)) continue;
        const int distance = std::max(std::abs(dx), std::abs(dy));
        if (best == -1 || distance < best) best = distance;
      }
    pass_memo_.emplace(texel, best);
    return best;
  }

  const TexelWeights& weights(size_t texel) {
    auto found = memo_.find(texel);
    if (found != memo_.end()) return found->second;
    TexelWeights result;
    const int p = pass(texel);
    if (p <= 0) {
      result.push_back({texel, 1.0});
    } else {
      const int x = int(texel % size_t(width_)), y = int(texel / size_t(width_));
      std::vector<size_t> sources;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width_ || ny >= height_) continue;
          const size_t j = size_t(ny) * size_t(width_) + size_t(nx);
          const int q = pass(j);
          if (q != -1 && q < p) sources.push_back(j);
        }
      std::unordered_map<size_t, double> sum;
      for (size_t j : sources)
        for (const auto& [covered, w] : weights(j)) sum[covered] += w / double(sources.size());
      result.assign(sum.begin(), sum.end());
    }
    return memo_.emplace(texel, std::move(result)).first->second;
  }

 private:
  int width_, height_;
  const std::vector<float>& coverage_;
  int passes_;
  std::unordered_map<size_t, int> pass_memo_;
  std::unordered_map<size_t, TexelWeights> memo_;
};

// One page's least-squares system: rows = seam samples, columns = covered texels in footprints.
struct PageSystem {
  std::vector<size_t> unknown_texel;                  // column -> texel
  std::vector<Eigen::Triplet<double>> row_terms;      // on unknowns
  std::vector<std::vector<std::pair<size_t, double>>> row_constants;  // on never-filled texels
  size_t rows = 0;
};

PageSystem page_system(const formats::LightmapImage& page, const std::vector<SeamSample>& samples, int page_index,
                       DilationMap& dilation) {
  PageSystem system;
  std::unordered_map<size_t, size_t> column_of;
  for (const SeamSample& s : samples) {
    if (s.page != page_index) continue;
    std::unordered_map<size_t, double> row, constants;
    for (int side = 0; side < 2; ++side) {
      const BilinearTaps taps = bilinear_taps(page.width, page.height, side == 0 ? s.side_a : s.side_b);
      const double sign = side == 0 ? 1.0 : -1.0;
      for (size_t k = 0; k < 4; ++k) {
        if (taps.weight[k] == 0) continue;
        for (const auto& [texel, w] : dilation.weights(taps.texel[k]))
          (dilation.pass(texel) == 0 ? row : constants)[texel] += sign * taps.weight[k] * w;
      }
    }
    for (const auto& [texel, w] : row) {
      auto [it, inserted] = column_of.emplace(texel, system.unknown_texel.size());
      if (inserted) system.unknown_texel.push_back(texel);
      system.row_terms.emplace_back(int(system.rows), int(it->second), w);
    }
    system.row_constants.emplace_back(constants.begin(), constants.end());
    ++system.rows;
  }
  return system;
}

// Solves (R^T R + lambda I) x = lambda x0 - R^T c for every colour channel and writes x back. The
// matrix is the same for all channels: one sparse Cholesky factorization (LDL^T, fill-reducing
// ordering) and one back-substitution per channel, where conjugate gradient solved each channel
// from scratch (issue 33: 13.9-27 s for 218 k texels on the open city). Conjugate gradient stays as
// the fallback should the factorization fail (it cannot for lambda > 0: the matrix is SPD).
void solve_page(formats::LightmapImage& page, const PageSystem& system, double lambda) {
  const int n = int(system.unknown_texel.size());
  if (n == 0) return;
  Eigen::SparseMatrix<double> r(int(system.rows), n);
  r.setFromTriplets(system.row_terms.begin(), system.row_terms.end());
  Eigen::SparseMatrix<double> identity(n, n);
  identity.setIdentity();
  const Eigen::SparseMatrix<double> normal = Eigen::SparseMatrix<double>(r.transpose() * r) + lambda * identity;
  std::vector<std::vector<float>*> channels;
  for (auto& [name, values] : page.channels)
    if (is_colour_channel(name)) channels.push_back(&values);
  if (channels.empty()) return;
  const int k = int(channels.size());
  Eigen::MatrixXd x0(n, k), c(int(system.rows), k);
  for (int ch = 0; ch < k; ++ch) {
    const std::vector<float>& values = *channels[size_t(ch)];
    for (int j = 0; j < n; ++j) x0(j, ch) = values[system.unknown_texel[size_t(j)]];
    for (size_t row = 0; row < system.rows; ++row) {
      double sum = 0;
      for (const auto& [texel, w] : system.row_constants[row]) sum += w * values[texel];
      c(int(row), ch) = sum;
    }
  }
  const Eigen::MatrixXd rhs = lambda * x0 - Eigen::MatrixXd(r.transpose() * c);
  Eigen::MatrixXd x;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor(normal);
  if (factor.info() == Eigen::Success) {
    x = factor.solve(rhs);
  } else {
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
    cg.setTolerance(1e-7);  // relative residual; the pages hold floats (24-bit mantissa)
    cg.setMaxIterations(10 * n + 100);
    cg.compute(normal);
    x.resize(n, k);
    for (int ch = 0; ch < k; ++ch) x.col(ch) = cg.solveWithGuess(rhs.col(ch), x0.col(ch));
  }
  for (int ch = 0; ch < k; ++ch) {
    if (!x.col(ch).allFinite()) continue;  // keep the unstitched values
    std::vector<float>& values = *channels[size_t(ch)];
    // Irradiance is never negative: a texel that was not keeps to >= 0 (the solve can overshoot
    // where a bright texel's footprint neighbours a dark one).
    for (int j = 0; j < n; ++j)
      values[system.unknown_texel[size_t(j)]] = float(x0(j, ch) >= 0 ? std::max(0.0, x(j, ch)) : x(j, ch));
  }
}

}  // namespace

SeamStitcher::SeamStitcher(const std::vector<SeamEdge>& seams, const SeamStitchSettings& settings, bool stitch)
    : settings_(settings),
      stitch_(stitch),
      edges_(seams.size()),
      samples_(seam_samples(seams, settings.samples_per_texel)),
      before_(samples_),
      after_(samples_) {}

void SeamStitcher::page(size_t p, formats::LightmapImage& image) {
  before_.page(p, image);
  if (!stitch_) return;
  const auto coverage = image.channels.find("A");
  const bool has_samples = std::any_of(samples_.begin(), samples_.end(), [&](const SeamSample& s) { return s.page == int(p); });
  if (has_samples && coverage != image.channels.end()) {
    DilationMap dilation(image.width, image.height, coverage->second, settings_.dilation_passes);
    const PageSystem system = page_system(image, samples_, int(p), dilation);
    if (!system.unknown_texel.empty()) {
      solve_page(image, system, settings_.value_weight);
      texels_adjusted_ += system.unknown_texel.size();
      std::vector<float*> colour;
      for (auto& [name, values] : image.channels)
        if (is_colour_channel(name)) colour.push_back(values.data());
      dilate_into_gutter(image.width, image.height, coverage->second, colour, settings_.dilation_passes);
    }
  }
  after_.page(p, image);
}

SeamStitchReport SeamStitcher::report() const {
  SeamStitchReport report;
  report.edges = edges_;
  report.samples = samples_.size();
  const SeamDiscontinuity before = before_.result();
  report.discontinuity_before = before.mean_relative_difference;
  report.texel_relative_error = before.mean_texel_relative_error;
  report.discontinuity_after = stitch_ ? after_.result().mean_relative_difference : report.discontinuity_before;
  report.texels_adjusted = texels_adjusted_;
  return report;
}

SeamStitchReport measure_lightmap_seams(const std::vector<formats::LightmapImage>& pages,
                                        const std::vector<SeamEdge>& seams, const SeamStitchSettings& settings) {
  SeamStitcher stitcher(seams, settings, false);
  for (size_t p = 0; p < pages.size(); ++p) stitcher.page(p, const_cast<formats::LightmapImage&>(pages[p]));  // measured only
  return stitcher.report();
}

SeamStitchReport stitch_lightmap_seams(std::vector<formats::LightmapImage>& pages, const std::vector<SeamEdge>& seams,
                                       const SeamStitchSettings& settings) {
  SeamStitcher stitcher(seams, settings, true);
  for (size_t p = 0; p < pages.size(); ++p) stitcher.page(p, pages[p]);
  return stitcher.report();
}

}  // namespace exitance
