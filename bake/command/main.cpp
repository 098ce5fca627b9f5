// `bake SCENE.{gltf,glb} [-o OUT] [options]`: see docs/cli.md and DESIGN §3.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

#include <fcntl.h>
#include <unistd.h>

#include "exitance/bake/bundle/write_bundle.h"
#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/bake/distributed/mpi_work_share.h"
#include "exitance/bake/input_error.h"
#include "exitance/common/path_sampler.h"
#include "exitance/common/texture_space_filter.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "exitance/runtime/tools/command_line_errors.h"
#include "exitance/runtime/tools/progress_bar.h"

using exitance::one_line;

namespace {

void print_warnings(const exitance::Diagnostics& diagnostics) {
  for (const std::string& w : diagnostics.warnings) std::cerr << "bake: warning: " << one_line(w) << "\n";
}

// Under mpirun the ranks other than 0 keep quiet (rank 0 prints progress, warnings and errors every
// rank would give alike); their own failures go to the stderr kept here.
FILE* rank_stderr = stderr;

void quiet_unless_rank_zero(const exitance::MpiWorkShare* share) {
  if (!share || share->rank() == 0) return;
  const int kept = dup(STDERR_FILENO);
  const int null = open("/dev/null", O_WRONLY);
  if (kept < 0 || null < 0) return;
  rank_stderr = fdopen(kept, "w");
  dup2(null, STDERR_FILENO);
  close(null);
}

// What `bake` cannot split over ranks yet: a one-line reason, or empty.
std::string refused_under_mpirun(const exitance::BakeOptions& options, const std::string& adaptive,
                                 const std::string& guiding, const std::string& integrator) {
  if (adaptive == "on") return "--adaptive on: adaptive sampling runs in one process only, not under mpirun";
  if (guiding == "grid" || guiding == "svo")
    return "--guiding " + guiding + ": guiding runs in one process only, not under mpirun";
  if (options.lighting.emitter_guiding) return "--emitter-guiding on: guiding runs in one process only, not under mpirun";
  if (options.lighting.light_layers) return "--light-layers: light layers are kept in one process only, not under mpirun";
  if (integrator == "path" && options.lighting.target_relative_error > 0 && options.backend.name == "cpu")
    return "--target-error: on the CPU backend with --integrator path it plans each texel's samples in one process; "
           "under mpirun use --integrator bounces";
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  // Launched by mpirun: this process lights its share of the texels and probes (docs/cli.md).
  const std::unique_ptr<exitance::MpiWorkShare> mpi = exitance::MpiWorkShare::start_if_launched_by_mpirun(argc, argv);
  quiet_unless_rank_zero(mpi.get());
  const bool several_ranks = mpi && mpi->ranks() > 1;
  exitance::BakeOptions options;
  CLI::App app{"Exitance lightmap baker: bake SCENE.{gltf,glb} [-o OUT] [options]"};
  app.add_option("scene", options.input, "input glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("-o,--out", options.output, "output bundle folder (default: SCENE.bake next to the input)");
  app.add_option("--backend", options.backend.name,
                 "auto | vulkan | cpu (auto: a GPU if one exists, else the CPU reference)")
      ->check(CLI::IsMember({"auto", "vulkan", "cpu"}));
  app.add_option("--device", options.backend.device_index, "Vulkan device index (see --list-devices)")
      ->check(CLI::NonNegativeNumber);
  bool list_devices = false;
  app.add_flag("--list-devices", list_devices, "print the Vulkan devices and exit");
  app.add_option("--texel-density", options.atlas.texel_density,
                 "lightmap texels per scene unit (default: 64, lowered for large scenes)")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-page", options.atlas.max_page, "atlas page size limit in texels")->check(CLI::Range(16, 16384));
  app.add_option("--padding", options.atlas.padding, "gutter texels around each chart rectangle")->check(CLI::Range(1, 16));
  std::string uv = "1";
  app.add_option("--uv", uv,
                 "lightmap UV set: 1 = TEXCOORD_1 (default), 0 = TEXCOORD_0; generated (CGAL charts) for a mesh "
                 "without it; generate = generated for every mesh")
      ->check(CLI::IsMember({"0", "1", "generate"}));
  app.add_option("--write-gltf", options.write_gltf,
                 "also write the scene with its generated lightmap UVs (as the --uv set) to this .gltf");
  CLI::Option* spp_option = app.add_option(
      "--spp", options.lighting.spp,
      "samples per texel (default 128; 0 = until --time or --target-error ends the run, the default when either is given)");
  app.add_option("--time", options.lighting.time_budget_seconds, "stop the lighting stage after this many seconds")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--target-error", options.lighting.target_relative_error,
                 "plan each texel's samples so its relative standard error, SE / (E/pi + 1 % of the scene's "
                 "mean), reaches this (CPU: adaptive; Vulkan: a texel stops once it is below)")
      ->check(CLI::NonNegativeNumber);
  std::string adaptive = "auto";
  app.add_option("--adaptive", adaptive,
                 "adaptive sampling (samples where the relative error is; unbiased: a texel's samples follow its "
                 "neighbours' pilot samples, not its own): auto (= on with --time or --target-error on the CPU backend) | on (CPU backend; --spp is then the mean) | off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  app.add_option("--bounces", options.lighting.max_bounces,
                 "maximum diffuse bounces (default: path: until Russian roulette ends the path; bounces: until the "
                 "extrapolated tail is below the noise)")
      ->check(CLI::NonNegativeNumber);
  std::string integrator = "auto";
  app.add_option("--integrator", integrator,
                 "auto (default: bounces on the CPU backend unless --directional, --guiding grid or --adaptive on needs path "
                 "tracing; path on the Vulkan backend) | path (unbiased path tracing) | bounces (per-bounce gather "
                 "passes, both backends; biased by the lightmap resolution: bench/results/per-bounce-traced.md)")
      ->check(CLI::IsMember({"auto", "path", "bounces"}));
  app.add_option("--sky", options.sky, "sky radiance: R,G,B or an equirectangular image (EXR/HDR)");
  app.add_option("--seed", options.lighting.seed, "random seed; results are deterministic per seed and backend");
  app.add_flag("--bounce-layers", options.bounce_layers, "also write bounce<k>.R/G/B debug layers");
  bool no_skip = false;
  app.add_flag("--no-skip", no_skip,
               "trace the sealed texels too (those no light can reach; skipped and dilated by default), to measure "
               "what skipping them changes");
  std::string seams = "stitch";
  app.add_option("--seams", seams,
                 "stitch (default: least-squares stitching of the texels on both sides of lightmap UV seams) | off")
      ->check(CLI::IsMember({"stitch", "off"}));
  std::string probes = "auto", voxels = "auto", directional, guiding = "auto";
  app.add_option("--probes", probes, "light-probe grid spacing in scene units, auto (largest extent / 12) or none");
  app.add_option("--probe-spp", options.probe_spp, "rays per light probe")->check(CLI::Range(1u, 1u << 24));
  app.add_option("--probe-dering", options.probe_sh_window,
                 "Hanning window width for the probes' SH (e.g. 3; 0 = off, the default)")
      ->check(CLI::Range(0.0f, 16.0f));
  app.add_option("--voxel-resolution", voxels,
                 "SVO leaves per axis: a power of two 2..4096, auto (leaves about 4 texels wide) or none");
  app.add_option("--directional", directional,
                 "sh1: also write L1 SH directional layers sh1.x.R .. sh1.z.B (docs/bundle.md; path tracing)");
  app.add_flag("--light-layers", options.lighting.light_layers,
               "also write E/pi split by light (light-layers-<page>.exr, docs/bundle.md \"Light layers\"), so that the "
               "runtime scales a light's layer with no ray from the moment it opens the bundle; path tracing only");
  app.add_flag("--denoise", options.denoise,
               "filter the indirect light in texture space after lighting (an edge-stopping average over atlas "
               "neighbours on the same surface; biased, off by default: docs/cli.md, bench/results/denoise.md)");
  app.add_option("--denoise-radius", options.denoise_radius, "--denoise window radius in texels (default 3)")
      ->check(CLI::Range(1, exitance::kFilterMaxRadius));
  app.add_option("--guiding", guiding,
                 "auto (default: path tracing on the CPU backend measures a candidate against unguided samples "
                 "during a pilot and keeps it per region where it pays: light subpaths where a light starts them (emitters, "
                 "punctual lights, the sky; unless --light-paths off), else grid guiding; on Vulkan grid guiding, only "
                 "when given (its pilot costs); off per-bounce and under mpirun) "
                 "| off | svo (fields from exitance in the bake's voxel octree, seed 000) | grid (regular-grid SARSA "
                 "cache, seed 002)")
      ->check(CLI::IsMember({"auto", "off", "svo", "grid"}));
  app.add_option("--guiding-mix", options.lighting.guiding_mix,
                 "probability of the guided direction in the one-sample mixture with cosine sampling (default 0.5)")
      ->check(CLI::Range(0.0f, 1.0f));
  std::string emitter_guiding = "auto";
  app.add_option("--emitter-guiding", emitter_guiding,
                 "auto (default: on where the CPU backend bakes in one process) | on (CPU, or Vulkan path tracing) | off: next-event "
                 "estimation samples emitter patches and punctual lights from distributions learned per grid region, "
                 "mixed with the default choice by power (docs/lighting-core.md \"Emitter guiding\")")
      ->check(CLI::IsMember({"auto", "off", "on"}));
  app.add_option("--emitter-guiding-mix", options.lighting.emitter_guiding_mix,
                 "probability of the learned emitter distribution in the mixture with the default (default 0.5)")
      ->check(CLI::Range(0.0f, 1.0f));
  std::string light_paths = "auto";
  app.add_option("--light-paths", light_paths,
                 "auto (default: --guiding auto measures them against unguided samples where a light starts them, "
                 "and keeps them per region where they pay) | on | off: light subpaths from "
                 "emitters, punctual lights and the sky into a pool that path vertices connect to, weighted with the "
                 "path tracer's strategies by MIS (light entering through narrow openings: docs/lighting-core.md "
                 "\"Light subpaths\"); path tracing; on: every sample, without --guiding grid/svo (on the Vulkan backend: "
                 "texels, without --emitter-guiding; auto measures grid guiding there)")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  std::string sampler = "sobol";
  app.add_option("--sampler", sampler,
                 "sobol (Owen-scrambled Sobol points per texel, the default) | independent (independent random "
                 "numbers): bench/results/low-discrepancy.md")
      ->check(CLI::IsMember({"sobol", "independent"}));
  std::string first_bounce = "traced";
  app.add_option("--first-bounce", first_bounce,
                 "--integrator bounces: traced (B_1 traces one direct-light sample at each gather hit, the "
                 "default) | cached (B_1 reads the B_0 lightmap: cheaper, blurs direct light to the texel size)")
      ->check(CLI::IsMember({"traced", "cached"}));
  std::string cache_directory;
  bool no_cache = false;
  app.add_option("--cache", cache_directory,
                 "bundle cache folder: a bake of the same input with the same options reuses the stored bundle "
                 "(default: .exitance-cache beside the output)");
  app.add_flag("--no-cache", no_cache, "neither read nor fill the bundle cache");
  app.add_flag("--preview", options.preview,
               "also write tone-mapped PNGs of the lightmap pages and default views into OUT/preview/");
  std::string preview_size;  // parsed below, so any bad value gets the same one-line error
  CLI::Option* preview_size_option = app.add_option(
      "--preview-size", preview_size, "preview view width in pixels, 16..4096 (default 512; implies --preview)");
  bool json_report = false;
  app.add_flag("--json", json_report, "print the run report as JSON on stdout");
  // --list-devices needs no scene: parse it before the required positional is enforced.
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--list-devices") {
      for (const auto& d : exitance::enumerate_vulkan_devices())
        std::cout << d.index << ": " << d.name << " (" << exitance::to_string(d.type) << ")"
                  << (d.usable ? "" : " unusable: " + d.missing_feature) << "\n";
      return 0;
    }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exitance::exit_for_option_error(app, e, "bake");
  }
  // A time budget or a target error ends the run itself: no sample cap unless --spp asks for one.
  if (spp_option->count() == 0 && (options.lighting.time_budget_seconds > 0 || options.lighting.target_relative_error > 0))
    options.lighting.spp = 0;
  if (options.lighting.spp == 0 && options.lighting.time_budget_seconds <= 0 &&
      options.lighting.target_relative_error <= 0) {
    std::cerr << "bake: error: --spp 0 needs --time or --target-error to end the run\n";
    return 2;
  }

  exitance::Diagnostics diagnostics;
  const char* validation = std::getenv("EXITANCE_VULKAN_VALIDATION");
  options.backend.validation = validation && std::string(validation) == "1";
  if (probes == "none") {
    options.probes_enabled = false;
  } else if (probes != "auto") {
    size_t used = 0;
    float spacing = -1;
    try {
      spacing = std::stof(probes, &used);
    } catch (...) {
    }
    if (used != probes.size() || !(spacing > 0) || !std::isfinite(spacing)) {
      std::cerr << "bake: error: --probes " << probes << ": expected a positive spacing, auto or none\n";
      return 2;
    }
    options.probe_spacing = spacing;
  }
  if (voxels == "none") {
    options.svo_enabled = false;
  } else if (voxels != "auto") {
    size_t used = 0;
    unsigned long resolution = 0;
    try {
      resolution = std::stoul(voxels, &used);
    } catch (...) {
    }
    if (used != voxels.size() || resolution < 2 || resolution > 4096 || (resolution & (resolution - 1))) {
      std::cerr << "bake: error: --voxel-resolution " << voxels << ": expected a power of two 2..4096, auto or none\n";
      return 2;
    }
    options.voxel_resolution = uint32_t(resolution);
  }
  if (!options.write_gltf.empty() && std::filesystem::path(options.write_gltf).extension() != ".gltf") {
    std::cerr << "bake: error: --write-gltf " << options.write_gltf << ": the file name must end in .gltf\n";
    return 2;
  }
  if (preview_size_option->count() > 0) {
    size_t used = 0;
    long width = 0;
    try {
      width = std::stol(preview_size, &used);
    } catch (...) {
    }
    if (used == 0 || used != preview_size.size() || width < 16 || width > 4096) {
      std::cerr << "bake: error: --preview-size " << preview_size << ": expected 16..4096 pixels\n";
      return 2;
    }
    options.preview = true;
    options.preview_size = uint32_t(width);
  }
  if (uv == "generate") options.import.generate_lightmap_uvs = true;
  else options.import.lightmap_uv_set = uv == "0" ? 0 : 1;
  if (integrator == "bounces") options.lighting.integrator = exitance::IntegratorMode::Bounces;
  options.integrator_auto = integrator == "auto";
  if (adaptive == "on") {
    if (integrator == "bounces") {
      std::cerr << "bake: error: --adaptive on plans path-tracing samples: it needs --integrator path\n";
      return 2;
    }
    options.adaptive_request = exitance::AdaptiveRequest::On;
  } else if (adaptive == "off") {
    if (options.lighting.target_relative_error > 0 && integrator == "path" && options.backend.name == "cpu") {
      std::cerr << "bake: error: --adaptive off: on the CPU backend --target-error plans each texel's samples "
                   "(adaptive); drop one of them\n";
      return 2;
    }
    options.adaptive_request = exitance::AdaptiveRequest::Off;
  }
  options.skip_sealed_texels = !no_skip;
  options.lighting.sampler = sampler == "independent" ? exitance::kSamplerIndependent : exitance::kSamplerSobol;
  options.lighting.trace_first_bounce = first_bounce == "traced";
  options.stitch_seams = seams == "stitch";
  if (!directional.empty()) {
    if (directional != "sh1") {
      std::cerr << "bake: error: --directional " << directional << ": expected sh1\n";
      return 2;
    }
    if (integrator == "bounces") {
      std::cerr << "bake: error: --directional sh1 is estimated by path tracing: it needs --integrator path\n";
      return 2;
    }
    options.lighting.directional = exitance::DirectionalMode::Sh1;
  }
  if (options.denoise && (options.lighting.light_layers || options.lighting.directional != exitance::DirectionalMode::Off)) {
    std::cerr << "bake: error: --denoise filters the indirect light, which "
              << (options.lighting.light_layers ? "--light-layers do" : "--directional sh1 does")
              << " not keep apart from the direct: bake with one of them\n";
    return 2;
  }
  if (options.lighting.light_layers && integrator == "bounces") {
    std::cerr << "bake: error: --light-layers are kept by path tracing: they need --integrator path (or auto)\n";
    return 2;
  }
  if (guiding == "grid" || guiding == "svo") {
    if (integrator == "bounces") {
      std::cerr << "bake: error: --guiding " << guiding << " guides path tracing: it needs --integrator path\n";
      return 2;
    }
    options.lighting.guiding = guiding == "grid" ? exitance::GuidingMode::Grid : exitance::GuidingMode::Svo;
  }
  if (guiding == "svo" && voxels == "none") {
    std::cerr << "bake: error: --guiding svo builds its fields from the voxel octree: it contradicts --voxel-resolution none\n";
    return 2;
  }
  // Resolved once the backend and integrator are known (automatic_integrator.h).
  if (guiding == "auto") options.lighting.guiding = exitance::GuidingMode::Auto;
  if (emitter_guiding == "on") {
    if (options.backend.name == "vulkan" && guiding == "svo") {
      std::cerr << "bake: error: --emitter-guiding on with --backend vulkan: --guiding svo beside it runs on the CPU "
                   "backend only (use --guiding grid or --backend cpu)\n";
      return 2;
    }
    options.lighting.emitter_guiding = true;
  }
  options.emitter_guiding_auto = emitter_guiding == "auto";
  if (light_paths == "on") {
    const char* conflict = integrator == "bounces"                 ? "--integrator bounces (light subpaths are path-tracing strategies)"
                           : guiding == "grid" || guiding == "svo" ? "--guiding grid/svo (not combined yet)"
                                                                   : nullptr;
    if (conflict) {
      std::cerr << "bake: error: --light-paths on contradicts " << conflict << "\n";
      return 2;
    }
    options.lighting.light_subpaths = true;
  }
  // Off: --guiding auto measures grid guiding (its candidate before light subpaths) wherever it runs.
  if (light_paths == "off") options.lighting.guiding_auto_candidate = exitance::AutoGuidingCandidate::Grid;
  options.guiding_auto_given = guiding == "auto" && app.get_option("--guiding")->count() > 0;

  if (no_cache && !cache_directory.empty()) {
    std::cerr << "bake: error: --cache " << cache_directory << ": contradicts --no-cache\n";
    return 2;
  }
  if (!no_cache) {
    options.cache_directory = cache_directory.empty()
                                  ? (exitance::bundle_folder(options).parent_path() / ".exitance-cache").string()
                                  : cache_directory;
    std::error_code error;
    if (std::filesystem::exists(options.cache_directory, error) &&
        !std::filesystem::is_directory(options.cache_directory, error)) {
      std::cerr << "bake: error: --cache " << options.cache_directory << ": exists and is not a folder\n";
      return 2;
    }
  }

  if (mpi) {
    options.lighting.work_share = mpi.get();
    if (several_ranks) {
      const std::string refused = refused_under_mpirun(options, adaptive, guiding, integrator);
      if (!refused.empty()) {
        std::cerr << "bake: error: " << refused << "\n";
        return 2;
      }
      // One GPU per rank: without --device, the ranks on one host take its GPUs in turn.
      const char* local_rank = std::getenv("OMPI_COMM_WORLD_LOCAL_RANK");
      if (options.backend.name != "cpu" && options.backend.device_index < 0 && local_rank) {
        std::vector<uint32_t> gpus;
        for (const auto& d : exitance::enumerate_vulkan_devices())
          if (d.usable && (d.type == exitance::VulkanDeviceType::Discrete || d.type == exitance::VulkanDeviceType::Integrated ||
                           d.type == exitance::VulkanDeviceType::Virtual))
            gpus.push_back(d.index);
        if (!gpus.empty()) options.backend.device_index = int(gpus[size_t(std::atoi(local_rank)) % gpus.size()]);
      }
    }
    if (mpi->rank() != 0) options.cache_directory.clear();  // rank 0 alone reads and fills the caches
  }

  exitance::ProgressBar bar;
  options.progress = [&](const std::string& stage, double fraction, uint64_t rays) { bar.update(stage, fraction, rays); };
  try {
    const nlohmann::json report = exitance::run_bake(options, diagnostics);
    bar.finish();
    if (mpi && mpi->rank() != 0) return 0;  // rank 0 wrote the bundle and reports it
    print_warnings(diagnostics);
    if (json_report) {
      std::cout << report.dump(2) << "\n";
    } else {
      std::cerr << "bake: wrote " << report["output"].get<std::string>() << " (" << report["pages"].get<size_t>()
                << " pages, " << report["live_texels"].get<size_t>() << " texels, "
                << report["rays_per_second"].get<double>() * 1e-6 << " Mrays/s"
                << (report.contains("cache") && report["cache"].value("reused", false) ? "; reused from the cache" : "")
                << ")\n";
    }
    return 0;
  } catch (const exitance::InputError& e) {
    bar.finish();
    print_warnings(diagnostics);
    std::cerr << "bake: error: " << one_line(e.what()) << "\n";
    // Every rank meets the same bad input alike, but one that met it alone (rank 0's cache or
    // output folder) must not leave the others waiting in an exchange.
    if (several_ranks) mpi->abort(2);
    return 2;
  } catch (const exitance::VulkanDeviceFailure& e) {
    // Nothing was written (bundles are renamed into place at the end). The device may still run the
    // hung submission: leave without static destructors, which could wait for it.
    bar.finish();
    print_warnings(diagnostics);
    if (several_ranks) {
      std::fprintf(rank_stderr, "bake: error: rank %d: device failure during %s: %s\n", mpi->rank(), bar.stage().c_str(),
                   one_line(e.what()).c_str());
      std::fflush(rank_stderr);
      mpi->abort(exitance::kDeviceFailureExitCode);
    }
    std::cerr << "bake: error: device failure during " << bar.stage() << ": " << one_line(e.what()) << "\n";
    std::fflush(stderr);
    std::_Exit(exitance::kDeviceFailureExitCode);
  } catch (const std::exception& e) {
    bar.finish();
    print_warnings(diagnostics);
    if (!several_ranks) {
      std::cerr << "bake: error: " << one_line(e.what()) << "\n";
      return 1;
    }
    // The other ranks may be waiting for this one in an exchange: end the whole job, so the run fails
    // (the earlier bundle intact: rank 0 writes atomically) instead of hanging.
    std::fprintf(rank_stderr, "bake: error: rank %d: %s\n", mpi->rank(), one_line(e.what()).c_str());
    std::fflush(rank_stderr);
    mpi->abort(1);
  }
}
