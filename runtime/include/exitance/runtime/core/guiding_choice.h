// `--guiding auto` (issue 11): keep guiding only where it pays, decided from the bake's own samples.
//
// During a pilot a hashed share of the texels (kPilotMeasuringShare) takes as many guided as
// unguided samples (one half of the pilot each, in an order hashed per texel), and for
// each strategy sums the luminance of its samples, their squares and their counted cost. After the
// pilot each region (a group of texels, given by the caller) compares
//   relative variance per sample x cost per sample
// of the two strategies on its texels and keeps the cheaper one for the rest of the bake.
//
// Variance estimates from a pilot are noisy (path samples are heavy-tailed: a region of 16 texels x
// 24 samples per strategy misjudges a white furnace's equal variances by +-30 %), so a region keeps
// guiding on its own evidence only when the difference D = V_u C_u - V_g C_g is significant:
// |D| > kChoiceZ standard errors, from each texel's fourth moment (the variance of its sample
// variance). Where a region's evidence is weak it follows the whole scene's verdict (all texels'
// sums, the same test), and where that is weak too it stays unguided: the cheaper code path, and
// the one that can never be more than the pilot's cost worse than unguided.
//
// Why mixing strategies in one texel's mean stays unbiased: a texel's estimate is the mean of N
// samples with N fixed in advance (by --spp or the pass schedule, never by the sample values).
// Guided and unguided samples are both unbiased estimators of the same E/pi whatever the guide table
// is. In the pilot a texel's strategies follow a hash of (seed, texel), not any sample value. After
// it, a texel's strategy is chosen from the OTHER texels' pilot samples only (leave-one-out, as
// adaptive_sampling_plan.h does): its region's and the scene's sums less its own. Its own samples
// are scrambled Sobol points (path_sampler.h), dependent on each other (that is their
// stratification), so a choice made from its own pilot values could correlate with its later
// samples' errors; other texels' scrambles are independent hashes, so given the choice each of its
// later samples is still uniform: E[Y_s | strategy] = E/pi, and E[mean] = E/pi. The choice changes
// only the variance. (The floor epsilon comes from every texel's mean, a 1/texels coupling, as in the
// adaptive plan; a rule that changed N from the values, like stopping when a texel looks converged,
// would be biased.)
//
// Why halves and not alternate samples: a texel's Sobol samples (path_sampler.h) are stratified over
// aligned blocks of 2^k sample indices, dimension by dimension, and the two strategies draw their
// dimensions for different things. Samples alternating strategies (by parity or by a per-sample coin)
// leave neither strategy's dimensions stratified over the pilot: measured, 1.2-1.4x the relMSE at
// equal samples on the sunlit courtyard up to 256 spp, though unbiased. With the pilot a power of two
// and each strategy on one aligned half, every block of samples a texel takes is a stratified set.
// (By the sample's parity would be worse still: the sampler's index shuffle keeps the low bit, so one
// strategy would see one half of the first dimension only.) Beyond that, each strategy draws its
// samples from its own sequence, indexed by its own count (strategy_sample_index; guided samples on
// a stream of their own, guided_stream): a texel's unguided samples are then a prefix of the Sobol
// sequence an unguided bake uses, not that sequence with holes where the guided half went (a hole of
// 16 in 128 samples is a 16-sample block whose error counts like the 112 others': measured 1.1-1.2x
// the relMSE at equal spp on the courtyard at 16-256 spp, still). That remaining cost is QMC's: a
// texel whose samples are split into two separately stratified sets converges more slowly than one
// set (on the sunlit courtyard, 2 guided samples of 16 raise the relMSE 1.2x), so only a quarter of
// the texels measure; the others stay unguided through the pilot.
//
// Cost is counted, not timed, so the choice (and with it the image) is deterministic per seed and
// independent of the thread count and the machine's load: rays traced, plus a fixed price per guided
// vertex for the work a guided vertex does besides its rays (table lookup, CDF inversion, the
// mixture's pdf in next-event estimation's MIS weight), calibrated once on the CPU backend
// (kGuidedVertexCostInRays, bench/results/guiding-auto.md).
//
// Another guided kind plugs in as the candidate unchanged: the integrator only needs to say, per
// sample, which strategy ran and what it cost. Light subpaths do (IntegratorSettings's
// AutoGuidingCandidate): a "guided" sample is then one whose eye vertices connect to the pass's
// light-subpath pool, its rays count the connections' shadow rays, and each such sample also pays
// its share of the pool's rays (set_guided_sample_cost).
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/common/guiding_auto_strategy.h"

namespace exitance {

// The extra cost of a guided vertex in units of one traced ray (CPU backend, grid guiding), measured
// from per-sample times and counts: bench/results/guiding-auto.md, "Cost model".
constexpr double kGuidedVertexCostInRays = 0.65;
// The same price on the Vulkan backend (docs/lighting-core.md, "`--guiding auto` on the Vulkan
// backend", says why this value): a constant, not a clock, so the choice stays deterministic per seed.
constexpr double kGuidedVertexCostInRaysVulkan = 1.0;
// On the Vulkan backend a connected sample (light subpaths as the candidate) costs more GPU time than
// its counted rays and pool share say (its connection's MIS weights, the pool's reads, less coherent
// shading): measured on an H100 at 1024 spp as time per connected texel-sample over its counted
// cost, 1.54 on the Cornell room and 1.60 on ajar_room at 64 texels/m (bench/results/guiding-auto-gpu.md).
// Its counted cost is multiplied by this constant (no clock: the choice stays deterministic per seed).
constexpr double kConnectedSampleCostFactorVulkan = 1.55;
// Standard errors a difference of efficiency must exceed to count (one-sided 1.3e-3 under a normal).
constexpr double kChoiceZ = 3.0;

// --guiding auto's pilot with the light-subpath candidate, before GuidingChoice::pilot_for shortens it
// for small --spp. Longer than grid guiding's (64, its learning): what connections fix is a heavy
// tail (rare paths through a gap), which a short pilot's sample variance misses. Measured on
// ajar_room, where connections pay ~6x at equal time: the scene's efficiency ratio read 0.82 after
// 32 samples (so auto dropped them), 1.6 after 128, 2.4 after 256 (bench/results/guiding-auto-light-paths.md). Both backends.
constexpr uint32_t kLightSubpathPilotSamples = 256;
// ... and only in bakes of this many pilots at least: --spp, or what a time budget's pass rate
// promises (else the candidate is abandoned in the pilot's first half). Connections can cost far
// more variance than they save (the open city's lit windows), and a pilot's connected samples stay
// in the means of texels that do not connect: at 0.25 texels/m and 20 s (~140 spp, inside the pilot)
// the city read 1.4x the unguided relMSE (bench/results/guiding-auto-light-paths.md).
constexpr uint32_t kLightSubpathPilots = 4;
// Whether a bake of `spp` samples per texel (0: unlimited) has room for kLightSubpathPilots pilots.
inline bool light_subpath_pilots_fit(uint32_t spp) { return spp == 0 || spp >= kLightSubpathPilots * kLightSubpathPilotSamples; }
// Whether a time budget promises kLightSubpathPilots pilots of `pilot` samples: `samples_done`, then
// `seconds_left` at `seconds_per_sample` (each backend measures its rate). False for a NaN rate.
inline bool light_subpath_pilots_promised(double samples_done, double seconds_per_sample, double seconds_left, uint32_t pilot) {
  const double expected = samples_done + seconds_left / seconds_per_sample;
  return expected >= double(kLightSubpathPilots) * double(pilot);
}
// The share of texels that measure both strategies in the pilot (the rest take unguided samples):
// the pilot's cost on QMC-friendly scenes scales with it; a region of 16 texels keeps ~4 measuring
// ones, so regions mostly follow the scene's evidence.
constexpr double kPilotMeasuringShare = 0.25;

// One strategy's pilot sums on one texel.
struct StrategySums {
  uint32_t samples = 0;
  double sum = 0;          // luminance of E/pi
  double sum_squared = 0;
  double sum_cubed = 0;   // with the fourth power: the variance of the sample variance
  double sum_fourth = 0;
  uint64_t rays = 0;
  uint64_t guided_vertices = 0;
};

// Relative variances and costs of the two strategies over some texels, and the verdict they give.
struct EfficiencyEvidence {
  uint32_t texels_measured = 0;          // with >= 2 samples of each strategy and some signal
  double relative_variance[2] = {0, 0};  // [unguided, guided]: sum over texels of s^2 / (mean + eps)^2
  double variance_of_variance[2] = {0, 0};  // of those sums (fourth moments)
  double samples[2] = {0, 0};
  double cost[2] = {0, 0};               // in rays (guided vertices priced by kGuidedVertexCostInRays)
  double cost_per_sample(int k) const { return samples[k] > 0 ? cost[k] / samples[k] : 0.0; }
  // (V x C) unguided / (V x C) guided: > 1 guiding pays; 0 when nothing was measured.
  double efficiency_ratio() const;
  // D / SE(D), D = V_u C_u - V_g C_g: > kChoiceZ guiding pays, < -kChoiceZ it does not.
  double z() const;
};

// Where a region's strategy came from.
enum class ChoiceBasis : uint8_t { Region, Scene, Default };

// What a region measured and chose (for the manifest's stats and tests).
struct RegionChoice {
  uint32_t texels = 0;
  uint32_t texels_measured = 0;   // with >= 2 samples of each strategy and some signal
  double relative_variance[2] = {0, 0};  // [unguided, guided]: sum over texels of s^2 / (mean + eps)^2
  double cost_per_sample[2] = {0, 0};    // in rays (guided vertices priced by kGuidedVertexCostInRays)
  // (V x C) unguided / (V x C) guided: > 1 guiding pays; 0 when nothing was measured.
  double efficiency_ratio = 0;
  double z = 0;  // EfficiencyEvidence::z
  // The verdict of all its texels' evidence (what the manifest reports). Each texel follows the
  // verdict without its own samples (leave-one-out), which agrees but for texels near the threshold.
  bool guided = false;
  ChoiceBasis basis = ChoiceBasis::Default;
  uint32_t texels_guided = 0;  // texels whose own (leave-one-out) choice is guiding
};

class GuidingChoice {
 public:
  // `texel_region`: the region of every texel, in [0, region_count). `pilot`: samples per texel before
  // the choice, a power of two (so its halves are stratified blocks); statistics come from samples [statistics_from, pilot) (earlier ones see a guide that
  // has barely learned, which would understate guiding). `records_on_host` false: the samples are
  // summed elsewhere (the Vulkan device) and come once through add_sums, so the host's table of sums
  // (112 B per texel) is made then, not before the bake's first pass.
  GuidingChoice(std::vector<uint32_t> texel_region, uint32_t region_count, uint32_t pilot, uint32_t statistics_from,
                uint64_t seed, double measuring_share = kPilotMeasuringShare, bool records_on_host = true);

  // The pilot of a bake of `spp` samples per texel (0: unlimited) whose guide learns `learning_samples`:
  // all of them; a bake of fewer spp gets the largest power of two up to a quarter of them, at least 4
  // (powers of two from 4 on are boundaries of the ramp's passes). Both backends.
  static uint32_t pilot_for(uint32_t spp, uint32_t learning_samples);
  // The price of a guided vertex in rays that decide() uses (default kGuidedVertexCostInRays, the
  // CPU's); a backend whose guided vertices cost otherwise sets its own before decide().
  void set_guided_vertex_cost(double rays) { guided_vertex_cost_ = rays; }
  double guided_vertex_cost() const { return guided_vertex_cost_; }
  // A fixed price per guided sample in rays, besides its own rays and vertices (default 0): the
  // light-subpath candidate's share of the pool it connects to (traced once for many samples).
  void set_guided_sample_cost(double rays) { guided_sample_cost_ = rays; }
  // A factor on a guided sample's whole counted cost (default 1): a backend whose guided samples
  // take more time per counted ray than unguided ones (kConnectedSampleCostFactorVulkan).
  void set_guided_cost_factor(double factor) { guided_cost_factor_ = factor; }
  double guided_cost_factor() const { return guided_cost_factor_; }
  // Every measuring texel takes its candidate half of the pilot second (not by the hashed coin):
  // until half the pilot the bake is then an unguided one, which abandon() can keep. Before any sample.
  void set_candidate_half_second() { candidate_half_second_ = true; }
  // Ends the pilot in its first half (with set_candidate_half_second, so no candidate sample was
  // taken): every texel unguided from here, each sample at its own index, as if nothing had been
  // measured (the bake is then the unguided one). regions() stay unmeasured.
  void abandon();
  bool abandoned() const { return abandoned_; }
  // With set_candidate_half_second: the share of the texel samples [begin, begin + samples) that run
  // the candidate. In the pilot, the measuring texels' samples in its second half; after the choice
  // (or abandon()), guided_share(). What a light-subpath pool serves, on both backends.
  double candidate_share(uint32_t begin, uint32_t samples) const;
  // After the choice: the share of texels guided from here (0 once abandoned).
  double guided_share() const { return double(texels_guided_) / double(std::max<size_t>(texel_region_.size(), 1)); }

  uint32_t pilot() const { return pilot_; }
  bool decided() const { return decided_; }
  // Whether sample `sample` of `texel` is guided: in the pilot, the half of it the texel's hashed
  // coin gave guiding; after it, the texel's leave-one-out choice.
  bool sample_guided(size_t texel, uint32_t sample) const;
  // sample_guided and strategy_sample_index of `texel` as one word (common/guiding_auto_strategy.h:
  // measuring, the pilot's coin, decided, the verdict), which both answer through that header's
  // functions, as the Vulkan kernels do.
  uint32_t strategy_word(size_t texel) const;
  // Whether `texel` measures both strategies in the pilot (a hash of seed and texel).
  bool measuring(size_t texel) const;
  // The index of texel sample `sample` (of strategy `guided`) within its strategy's own sequence:
  // `sample` less the samples of the other strategy before it.
  uint32_t strategy_sample_index(size_t texel, uint32_t sample, bool guided) const;
  // The random stream of a texel's guided samples (unguided ones use the texel's usual stream): a salt
  // far from the texel, probe and bounce-pass stream ranges.
  static uint64_t guided_stream(size_t texel) { return uint64_t(texel) ^ kAutoGuidedStreamSalt; }
  // Adds one finished pilot sample (ignored outside [statistics_from, pilot) or after the choice).
  // Texels are independent: concurrent calls for different texels are safe.
  void record(size_t texel, uint32_t sample, bool guided, double luminance, uint64_t rays, uint64_t guided_vertices);
  // Adds sums of samples recorded elsewhere (the Vulkan backend's device, which sums the pilot's
  // samples [statistics_from, pilot) itself) to a texel's strategy (ignored after the choice). From
  // one thread.
  void add_sums(size_t texel, bool guided, const StrategySums& sums);
  // Every region picks its strategy from the sums (deterministic given them). `floor`: the epsilon of
  // the relative variance, in luminance of E/pi (kErrorFloorFraction x the mean, as the EXR's error layer).
  void decide(double floor);
  // decide() with the floor computed from the pilot's own sums.
  void decide();

  const std::vector<RegionChoice>& regions() const { return regions_; }
  // The whole scene's evidence (every measured texel), which regions without their own follow.
  const EfficiencyEvidence& scene() const { return scene_; }
  size_t texels_guided() const { return texels_guided_; }
  size_t regions_guided() const;
  bool any_guided() const { return regions_guided() > 0; }
  const StrategySums& sums(size_t texel, bool guided) const;

 private:
  std::vector<uint32_t> texel_region_;
  std::vector<StrategySums> sums_;  // [texel][unguided, guided]; empty until add_sums without records_on_host
  std::vector<RegionChoice> regions_;
  std::vector<uint8_t> texel_guided_;  // after decide()
  size_t texels_guided_ = 0;           // their sum
  EfficiencyEvidence scene_;
  uint32_t pilot_;
  uint32_t statistics_from_;
  uint64_t seed_;
  uint64_t measuring_below_;  // hash threshold: measuring_share x 2^64
  double measuring_share_;
  double guided_vertex_cost_ = kGuidedVertexCostInRays;
  double guided_sample_cost_ = 0;
  double guided_cost_factor_ = 1;
  bool candidate_half_second_ = false;
  bool abandoned_ = false;
  bool decided_ = false;
};

// The decision rule alone: evidence of the region that is significant decides; else the scene's,
// when that is significant; else unguided (the cheaper code path, nothing to look up).
ChoiceBasis choose(const EfficiencyEvidence& region, const EfficiencyEvidence& scene, bool& guided);

}  // namespace exitance
