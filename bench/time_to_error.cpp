// Time against error for the CPU reference on one scene: a long converged run (cached by
// content hash outside the repository) is the reference; runs at doubling spp record seconds,
// relMSE, MAE, worst-texel error and rays/s as CSV, and the time to reach a target relMSE.
//
//   bench_time_to_error SCENE.gltf [--backends cpu,vulkan] [--integrators path,adaptive,bounces,guided,svo,guided_auto,auto_light,auto_nee,guided_auto_nee,nee,guided_nee,svo_nee,bounces_nee,light] [--guiding-mix M] [--name NAME]
//                       [--sky R,G,B] [--texel-density T] [--reference-spp N] [--max-spp N]
//                       [--max-seconds S] [--target 0.01] [--bounces N] [--min-spp N] [--cache DIR] [--csv FILE]
//                       [--texel-csv FILE] [--guiding-fields FILE] [--samplers sobol,independent]
//
// --samplers: each integrator runs with each listed sampler (path_sampler.h); an `independent` run's
// integrator column gets the suffix "_independent".
//
// The reference is always the CPU path tracer. For the per-bounce mode (integrator per_bounce) the
// CSV also has the bounces run, the fraction of gather hits without texels, and bias_rel_mse: at
// every rung a second run with another seed, and the mean over texels of w (x1 - r)(x2 - r) minus
// the reference's noise - the two runs' noises are independent, so this estimates the squared
// bias alone (relMSE units), whatever the noise (it can come out slightly negative). --bounces N
// forces N bounces in both modes (default: automatic), so the per-bounce mode's resolution bias can
// be told from its truncation; --min-spp starts the ladder higher. --texel-csv writes, for the last
// run of each integrator, every texel's instance, page position, world position, reference and
// estimate (luminance), to see where an error lives.
//
// relMSE = mean over live texels and channels of (x - r)^2 / (r^2 + 1e-3): the 1e-3 keeps
// black texels from dominating (the usual regulariser of relMSE in rendering papers).
// The reference's own noise adds its expected relMSE to every measurement; that amount,
// estimated from the reference's per-texel variances, is subtracted (column rel_mse) and
// reported (column reference_rel_mse) so a run is never credited with beating its reference.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "exitance/runtime/embree_scene.h"
#include "rel_mse_weight.h"
#include "exitance/runtime/core/grid_guiding_cache.h"
#include "exitance/runtime/core/svo_guiding_fields.h"
#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/common/path_sampler.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/bake/command/backend_choice.h"
#include "exitance/bake/cache/sha256_stream.h"
#include "exitance/bake/command/prepared_scene.h"

namespace fs = std::filesystem;
using namespace exitance;

namespace {

struct ErrorFigures {
  double rel_mse = 0, mae = 0, worst = 0;
};

ErrorFigures compare(const std::vector<float>& x, const std::vector<float>& reference) {
  ErrorFigures e;
  for (size_t i = 0; i < x.size(); ++i) {
    const double d = double(x[i]) - reference[i];
    e.rel_mse += d * d * rel_mse_weight(reference[i]);
    e.mae += std::fabs(d);
    e.worst = std::max(e.worst, std::fabs(d) / (std::fabs(double(reference[i])) + 1e-2));
  }
  e.rel_mse /= double(x.size());
  e.mae /= double(x.size());
  return e;
}

// Means then variances of the mean, per texel and channel: [0, 3n) means, [3n, 6n) variances.
std::vector<float> flatten(const LightmapEstimate& estimate) {
  const size_t n = estimate.texels.size();
  std::vector<float> values(n * 6);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 mean = estimate.mean_total(i), variance = estimate.variance_of_mean(i);
    for (int c = 0; c < 3; ++c) values[i * 3 + size_t(c)] = mean[c], values[3 * n + i * 3 + size_t(c)] = variance[c];
  }
  return values;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_path, scene_name, sky, csv_path, cache_dir, texel_csv_path, backends = "cpu", integrators = "path";
  double max_seconds = 120;
  float density = 8;
  uint32_t reference_spp = 8192, max_spp = 1024, min_spp = 1;
  int bounces = -1;
  double target = 0.01;
  CLI::App app{"time against error of the CPU reference"};
  app.add_option("scene", scene_path)->required();
  app.add_option("--backends", backends, "comma-separated: cpu, vulkan (the reference is always cpu)");
  app.add_option("--integrators", integrators,
                 "comma-separated: path, adaptive (path with adaptive sampling; spp = mean), bounces, bounces_cached "
                 "(bounces with --first-bounce cached), guided (path with --guiding grid), svo (path with --guiding svo), "
                 "guided_auto (path with --guiding auto measuring grid guiding), auto_light (--guiding auto measuring light "
                 "subpaths), auto_nee (bake --integrator path's CPU default: --guiding auto, its candidate from the scene, "
                 "--emitter-guiding on), guided_auto_nee (the same measuring grid guiding), nee / guided_nee / svo_nee / bounces_nee (path, guided, "
                 "svo and bounces with --emitter-guiding on), light / light_nee (path with --light-paths on, without and with --emitter-guiding on)");
  float guiding_mix = 0.5f;
  app.add_option("--guiding-mix", guiding_mix, "guided component's probability (guided runs)");
  float emitter_guiding_mix = 0.5f;
  uint32_t emitter_guiding_patches = 512;
  app.add_option("--emitter-guiding-mix", emitter_guiding_mix, "learned next-event component's probability (*nee runs)");
  app.add_option("--emitter-guiding-patches", emitter_guiding_patches, "about this many emitter patches (*nee runs)");
  double light_subpaths_per_sample = 0.0625;
  app.add_option("--light-subpaths-per-sample", light_subpaths_per_sample, "light subpaths per texel sample (light runs)");
  std::string guiding_fields;
  app.add_option("--guiding-fields", guiding_fields,
                 "CSV of the learned grid guiding tables of the last guided run (record, cell, class, bins); svo "
                 "runs: their last run's fields (record, bin node level, class, capture origin, bins)");
  uint32_t svo_depth = 0;
  app.add_option("--svo-depth", svo_depth,
                 "svo runs: octree depth (default: the bake's for --texel-density, at least 6: the bench's coarse "
                 "atlases would otherwise get a few leaves per axis)");
  double svo_c_ray = 512;
  app.add_option("--svo-c-ray", svo_c_ray, "svo runs: PARTITION-S c_ray (vertices per sample per texel per bin)");
  uint32_t svo_rays_per_bin = 1;
  app.add_option("--svo-rays-per-bin", svo_rays_per_bin, "svo runs: rays per hemisphere bin of a field (k x k)");
  bool svo_reflected_only = false;
  app.add_flag("--svo-reflected-only", svo_reflected_only, "svo runs: fields without emitted radiance");
  bool svo_skip_texels = false;
  app.add_flag("--svo-skip-texels", svo_skip_texels, "svo runs: texel vertices sample cosine (guiding from bounce 1)");
  app.add_option("--name", scene_name, "scene name in the CSV (default: file stem)");
  app.add_option("--max-seconds", max_seconds, "stop the ladder after a run longer than this");
  app.add_option("--sky", sky);
  app.add_option("--texel-density", density);
  app.add_option("--reference-spp", reference_spp);
  app.add_option("--max-spp", max_spp);
  app.add_option("--target", target, "relMSE target (0.01 = 1 %)");
  app.add_option("--bounces", bounces, "forced bounces of the measured runs (default: automatic)");
  app.add_option("--min-spp", min_spp, "first spp of the ladder");
  app.add_option("--texel-csv", texel_csv_path, "per-texel reference and estimate of each integrator's last run");
  app.add_option("--cache", cache_dir, "reference cache folder (default ~/.cache/exitance)");
  app.add_option("--csv", csv_path);
  std::string samplers = "sobol";
  app.add_option("--samplers", samplers, "sobol,independent: the samplers each integrator runs with");
  CLI11_PARSE(app, argc, argv);
  if (scene_name.empty()) scene_name = fs::path(scene_path).stem().string();
  if (cache_dir.empty()) cache_dir = std::string(std::getenv("HOME") ? std::getenv("HOME") : "/tmp") + "/.cache/exitance";

  Diagnostics diagnostics;
  AtlasSettings atlas;
  atlas.texel_density = density;
  const PreparedScene prepared = prepare_scene_for_lighting(scene_path, sky, atlas, diagnostics);
  const Scene& scene = prepared.scene;
  const TexelGBuffer& gbuffer = prepared.gbuffer;
  const std::shared_ptr<const LightingScene> lighting = make_lighting_scene(scene);
  const auto embree = std::make_shared<const EmbreeScene>(*lighting->source);
  const CpuReferenceIntegrator integrator(lighting, embree);
  std::vector<std::shared_ptr<const Integrator>> measured;
  for (size_t start = 0; start < backends.size();) {
    const size_t comma = std::min(backends.find(',', start), backends.size());
    BackendRequest request;
    request.name = backends.substr(start, comma - start);
    try {
      measured.push_back(choose_lighting_backend(lighting, embree, request, diagnostics));
      std::cerr << "backend " << request.name << ": " << measured.back()->device_description() << "\n";
    } catch (const std::exception& e) {
      std::cerr << "backend " << request.name << " skipped: " << e.what() << "\n";
    }
    start = comma + 1;
  }

  // Reference: keyed by scene bytes + settings, so a changed scene or setting rebuilds it.
  const std::string key = "v3-independent-" + sha256_of_file(scene_path).substr(0, 16) + "-d" + std::to_string(density) + "-s" +
                          std::to_string(reference_spp) + "-sky" + sky;
  fs::create_directories(cache_dir);
  const fs::path cache_file = fs::path(cache_dir) / ("reference-" + key + ".f32");
  std::vector<float> reference(gbuffer.texels.size() * 6);
  if (std::ifstream in{cache_file, std::ios::binary}; in && fs::file_size(cache_file) == reference.size() * 4) {
    in.read(reinterpret_cast<char*>(reference.data()), std::streamsize(reference.size() * 4));
    std::cerr << "reference: cached " << cache_file << "\n";
  } else {
    IntegratorSettings settings;
    settings.spp = reference_spp;
    settings.seed = 0x5EED5EED;  // independent of the measured runs
    // Independent samples: the reference's noise below comes from its per-texel sample variances,
    // which would overstate a stratified (Sobol) reference's noise and so flatter every run.
    settings.sampler = kSamplerIndependent;
    const LightmapEstimate estimate = integrator.bake(gbuffer, settings);
    reference = flatten(estimate);
    std::ofstream out(cache_file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(reference.data()), std::streamsize(reference.size() * 4));
    std::cerr << "reference: " << reference_spp << " spp in " << estimate.seconds << " s -> " << cache_file << "\n";
  }

  const size_t values = gbuffer.texels.size() * 3;
  const std::vector<float> reference_mean(reference.begin(), reference.begin() + long(values));
  double reference_noise = 0;
  for (size_t i = 0; i < values; ++i) reference_noise += reference[values + i] * rel_mse_weight(reference_mean[i]);
  reference_noise /= double(values);
  std::cerr << "reference relMSE from its own noise: " << reference_noise << "\n";

  std::ofstream csv_file;
  if (!csv_path.empty()) csv_file.open(csv_path);
  std::ostream& csv = csv_path.empty() ? std::cout : csv_file;
  std::ofstream texel_csv;
  if (!texel_csv_path.empty()) {
    texel_csv.open(texel_csv_path);
    texel_csv << "integrator,texel,instance,page,x,y,px,py,pz,reference,estimate\n";
  }
  csv << "backend,integrator,scene,live_texels,spp,seconds,rel_mse,raw_rel_mse,reference_rel_mse,mae,worst_texel_error,"
         "rays_per_second,bounces,texelless_fraction,bias_rel_mse\n";
  struct Mode {
    IntegratorMode integrator;
    GuidingMode guiding;
    std::string name;
    bool adaptive = false;
    uint32_t sampler = kSamplerSobol;
    bool trace_first_bounce = true;  // bounces: B_1 traced (true) or read from the B_0 lightmap
    bool emitter_guiding = false;
    bool light_subpaths = false;
    AutoGuidingCandidate candidate = AutoGuidingCandidate::Grid;  // GuidingMode::Auto's
  };
  std::vector<Mode> modes;
  auto listed = [&](const std::string& name) {
    return ("," + integrators + ",").find("," + name + ",") != std::string::npos;
  };
  if (listed("path")) modes.push_back({IntegratorMode::Path, GuidingMode::Off, "path_tracing"});
  if (listed("adaptive")) modes.push_back({IntegratorMode::Path, GuidingMode::Off, "path_adaptive", true});
  if (listed("guided")) modes.push_back({IntegratorMode::Path, GuidingMode::Grid, "path_guided_grid"});
  if (listed("guided_auto")) modes.push_back({IntegratorMode::Path, GuidingMode::Auto, "path_guided_auto"});
  if (listed("svo")) modes.push_back({IntegratorMode::Path, GuidingMode::Svo, "path_guided_svo"});
  // Emitter guiding (--emitter-guiding on) with unguided, grid and SVO continuations.
  if (listed("nee")) modes.push_back({IntegratorMode::Path, GuidingMode::Off, "path_nee", false, kSamplerSobol, true, true});
  if (listed("guided_nee"))
    modes.push_back({IntegratorMode::Path, GuidingMode::Grid, "path_guided_grid_nee", false, kSamplerSobol, true, true});
  if (listed("svo_nee"))
    modes.push_back({IntegratorMode::Path, GuidingMode::Svo, "path_guided_svo_nee", false, kSamplerSobol, true, true});
  // The octree of svo runs: built once, as the bake's voxelize stage does before lighting (not timed:
  // every bake builds it, guided or not).
  formats::SparseVoxelOctree octree;
  if (listed("svo") || listed("svo_nee")) {
    SvoBuildSettings build;
    build.depth = svo_depth ? svo_depth : std::max(6u, default_svo_depth(scene, density));
    octree = build_sparse_voxel_octree(scene, build);
    std::cerr << "svo guiding octree: depth " << build.depth << ", " << octree.nodes.size() << " nodes\n";
  }
  // Light subpaths connected to every path vertex (--light-paths on).
  if (listed("light")) modes.push_back({IntegratorMode::Path, GuidingMode::Off, "path_light_subpaths", false, kSamplerSobol, true, false, true});
  if (listed("light_nee"))
    modes.push_back({IntegratorMode::Path, GuidingMode::Off, "path_light_subpaths_nee", false, kSamplerSobol, true, true, true});
  // --guiding auto measuring light subpaths (auto_light), and `bake --integrator path`'s default on the
  // CPU (auto_nee: auto's candidate from the scene, emitter guiding on) beside the default before it
  // (guided_auto_nee: auto measuring grid guiding).
  if (listed("auto_light"))
    modes.push_back({IntegratorMode::Path, GuidingMode::Auto, "path_auto_light_subpaths", false, kSamplerSobol, true, false, false,
                     AutoGuidingCandidate::LightSubpaths});
  if (listed("auto_nee"))
    modes.push_back({IntegratorMode::Path, GuidingMode::Auto, "path_auto_nee", false, kSamplerSobol, true, true, false,
                     AutoGuidingCandidate::Scene});
  if (listed("guided_auto_nee"))
    modes.push_back({IntegratorMode::Path, GuidingMode::Auto, "path_guided_auto_nee", false, kSamplerSobol, true, true});
  if (listed("bounces")) modes.push_back({IntegratorMode::Bounces, GuidingMode::Off, "per_bounce"});
  if (listed("bounces_nee"))
    modes.push_back({IntegratorMode::Bounces, GuidingMode::Off, "per_bounce_nee", false, kSamplerSobol, true, true});
  if (listed("bounces_cached"))
    modes.push_back({IntegratorMode::Bounces, GuidingMode::Off, "per_bounce_cached", false, kSamplerSobol, false});
  if (("," + samplers + ",").find(",independent,") != std::string::npos) {
    const size_t sobol_modes = modes.size();
    for (size_t k = 0; k < sobol_modes; ++k) {
      Mode m = modes[k];
      m.name += "_independent";
      m.sampler = kSamplerIndependent;
      modes.push_back(m);
    }
    if (("," + samplers + ",").find(",sobol,") == std::string::npos) modes.erase(modes.begin(), modes.begin() + long(sobol_modes));
  }
  for (const std::shared_ptr<const Integrator>& backend : measured)
    for (const Mode& m : modes) {
      const IntegratorMode mode = m.integrator;
      const char* mode_name = m.name.c_str();
      {  // Warm-up, not recorded: lavapipe and GPU drivers compile pipelines at the first dispatch.
        IntegratorSettings warm_up;
        warm_up.spp = 1;
        warm_up.integrator = mode;
        warm_up.guiding = m.guiding;
        warm_up.guiding_octree = &octree;
        try {
          backend->bake(gbuffer, warm_up);
        } catch (const std::exception& e) {
          std::cerr << backend->backend_name() << " " << mode_name << " skipped: " << e.what() << "\n";
          continue;
        }
      }
      double previous_seconds = 0, previous_error = 0, time_to_target = -1;
      std::vector<float> last_result;
      for (uint32_t spp = std::max(min_spp, 1u); spp <= max_spp; spp *= 2) {
        IntegratorSettings settings;
        settings.spp = spp;
        settings.seed = spp;
        settings.integrator = mode;
        settings.max_bounces = bounces;
        settings.guiding = m.guiding;
        settings.guiding_mix = guiding_mix;
        settings.emitter_guiding = m.emitter_guiding;
        settings.light_subpaths = m.light_subpaths;
        settings.guiding_auto_candidate = m.candidate;
        settings.light_subpaths_per_sample = light_subpaths_per_sample;
        settings.emitter_guiding_mix = emitter_guiding_mix;
        settings.emitter_guiding_patches = emitter_guiding_patches;
        settings.guiding_octree = &octree;
        settings.guiding_svo_c_ray = svo_c_ray;
        settings.guiding_svo_rays_per_bin = svo_rays_per_bin;
        settings.guiding_svo_emitted = !svo_reflected_only;
        settings.guiding_svo_texels = !svo_skip_texels;
        uint32_t svo_records = 0, svo_bins = 0;
        size_t svo_memory = 0;
        settings.inspect_svo_guiding = [&](const SvoGuidingFields& fields) {
          svo_records = fields.record_count(), svo_bins = fields.bin_count(), svo_memory = fields.memory_bytes();
          if (guiding_fields.empty()) return;
          std::ofstream out(guiding_fields);
          out << "record,level,normal_class,x,y,z,bytes_per_record,memory_bytes";
          for (uint b = 0; b < kGuideBins; ++b) out << ",bin" << b;
          out << "\n";
          for (uint32_t r = 0; r < fields.record_count(); ++r) {
            const Vec3 o = fields.capture_origin(r);
            out << r << "," << int(octree.nodes[fields.bin_node(fields.record_bin(r))].level) << ","
                << fields.record_class(r) << "," << o.x << "," << o.y << "," << o.z << ","
                << SvoGuidingFields::bytes_per_record() << "," << fields.memory_bytes();
            for (uint b = 0; b < kGuideBins; ++b) out << "," << fields.field(r)[b];
            out << "\n";
          }
        };
        settings.adaptive = m.adaptive;  // spp is then the mean samples per texel
        settings.sampler = m.sampler;
        settings.trace_first_bounce = m.trace_first_bounce;
        if (!guiding_fields.empty())
          settings.inspect_guiding = [&](const GridGuidingCache& cache) {
            std::ofstream out(guiding_fields);
            out << "cell_x,cell_y,cell_z,normal_class,cell_size,memory_bytes_per_record";
            for (uint b = 0; b < kGuideBins; ++b) out << ",bin" << b;
            out << "\n";
            for (int z = 0; z < cache.cells(2); ++z)
              for (int y = 0; y < cache.cells(1); ++y)
                for (int x = 0; x < cache.cells(0); ++x)
                  for (uint k = 0; k < kGuideNormalClasses; ++k) {
                    const uint32_t r = cache.record_of_cell(x, y, z, k);
                    if (r == GridGuidingCache::kNoRecord) continue;
                    out << x << "," << y << "," << z << "," << k << "," << cache.cell_size() << ","
                        << GridGuidingCache::bytes_per_record();
                    for (uint b = 0; b < kGuideBins; ++b) out << "," << cache.radiance(r)[b];
                    out << "\n";
                  }
          };
        const LightmapEstimate estimate = backend->bake(gbuffer, settings);
        if (m.guiding == GuidingMode::Svo)
          std::cerr << mode_name << " " << spp << " spp: " << svo_bins << " bins, " << svo_records << " records, "
                    << svo_memory << " bytes\n";
        if (mode == IntegratorMode::Path) {  // counts behind --guiding auto's cost model (bench/results/guiding-auto.md)
          uint64_t samples = 0;
          for (const TexelAccumulator& t : estimate.texels) samples += t.samples;
          std::cerr << scene_name << " " << mode_name << " " << spp << " spp: rays/sample "
                    << double(estimate.rays) / double(std::max<uint64_t>(samples, 1)) << ", guided vertices/sample "
                    << double(estimate.guided_vertices) / double(std::max<uint64_t>(samples, 1)) << ", seconds "
                    << estimate.seconds << "\n";
        }
        if (estimate.guiding_auto) {  // what --guiding auto kept (stderr: the CSV stays one row per run)
          size_t texels = 0, guided = 0, regions = 0;
          for (const RegionChoice& r : estimate.guiding_regions) texels += r.texels, guided += r.texels_guided, regions += r.guided;
          std::cerr << scene_name << " " << spp << " spp auto: " << (estimate.guiding_regions.empty() ? "undecided" : "decided")
                    << ", regions guided " << regions << "/" << estimate.guiding_regions.size() << ", texels guided "
                    << guided << "/" << texels << "\n";
        }
        std::vector<float> result = flatten(estimate);
        result.resize(values);
        ErrorFigures e = compare(result, reference_mean);
        const double raw = e.rel_mse;
        e.rel_mse = std::max(raw - reference_noise, 1e-12);
        double bias = 0, texelless = 0;
        if (mode == IntegratorMode::Bounces) {
          settings.seed = spp + 0x10000;
          std::vector<float> second = flatten(backend->bake(gbuffer, settings));
          for (size_t i = 0; i < values; ++i)
            bias += (double(result[i]) - reference_mean[i]) * (double(second[i]) - reference_mean[i]) *
                    rel_mse_weight(reference_mean[i]);
          bias = bias / double(values) - reference_noise;
          const BounceGatherStatistics& b = estimate.bounce_statistics;
          texelless = b.gathers ? double(b.texelless_hits) / double(b.gathers) : 0.0;
        }
        csv << backend->backend_name() << "," << mode_name << "," << scene_name << "," << gbuffer.texels.size() << ","
            << spp << "," << estimate.seconds << "," << e.rel_mse << "," << raw << "," << reference_noise << "," << e.mae
            << "," << e.worst << "," << double(estimate.rays) / estimate.seconds << ","
            << estimate.bounce_statistics.bounces << "," << texelless << "," << bias << std::endl;
        if (time_to_target < 0 && e.rel_mse <= target) {
          // Log-log interpolation between the two runs that bracket the target.
          time_to_target = previous_seconds > 0
                               ? std::exp(std::log(previous_seconds) + (std::log(target) - std::log(previous_error)) /
                                                                           (std::log(e.rel_mse) - std::log(previous_error)) *
                                                                           (std::log(estimate.seconds) - std::log(previous_seconds)))
                               : estimate.seconds;
        }
        previous_seconds = estimate.seconds;
        previous_error = e.rel_mse;
        last_result = result;
        if (estimate.seconds > max_seconds) break;
      }
      if (texel_csv.is_open())
        for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
          const LiveTexel& t = gbuffer.texels[i];
          auto lum = [&](const std::vector<float>& v) { return luminance({v[i * 3], v[i * 3 + 1], v[i * 3 + 2]}); };
          texel_csv << mode_name << "," << i << "," << t.instance << "," << t.page << "," << t.x << "," << t.y << ","
                    << t.position.x << "," << t.position.y << "," << t.position.z << "," << lum(reference_mean) << ","
                    << lum(last_result) << "\n";
        }
      std::cerr << backend->backend_name() << " " << mode_name << ": live texels " << gbuffer.texels.size()
                << "; time to relMSE " << target << ": "
                << (time_to_target < 0 ? std::string("not reached") : std::to_string(time_to_target) + " s") << "\n";
    }
  return 0;
}
