// exitance-relight BUNDLE [-o OUT] [--edits EDITS.json] [--spp N] [--time S] [--budget-ms N] [--frames N] [--guiding off|grid|svo|auto] [--emitter-guiding off|on] [--seed N] [--device N] [--json] [--share R/N]
// Re-lights a baked bundle from its scene.bin on the GPU (runtime/src/relight). Links the runtime
// library and nothing of the offline stage; runs where only a Vulkan driver exists.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>

#include "exitance/common/texture_space_filter.h"
#include "exitance/runtime/relight/relight.h"
#include "exitance/runtime/tools/command_line_errors.h"
#include "exitance/runtime/tools/progress_bar.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"

using exitance::one_line;

int main(int argc, char** argv) {
  CLI::App app{"exitance-relight: re-light a baked bundle from its scene.bin on the GPU"};
  exitance::RelightOptions options;
  std::optional<uint32_t> spp;
  std::optional<uint64_t> seed;
  bool json_report = false, list_devices = false;
  app.add_option("bundle", options.bundle, "the bundle folder bake wrote (manifest.json, scene.bin, ...)")->required();
  app.add_option("-o,--out", options.output, "output bundle folder (default: the input bundle, replaced atomically)");
  app.add_option("--edits", options.edits_file, "apply these edits (docs/edits.md) to the scene before the refresh");
  app.add_option("--spp", spp, "samples per texel (default: the bake's; 0 = until --time ends the run)");
  app.add_option("--time", options.time_budget_seconds, "bound the whole lightmap refresh to this many seconds")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--budget-ms", options.frame_budget_ms, "bound each frame (refresh call) to this many milliseconds")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--frames", options.frames, "refresh at most this many frames; the report lists each frame's time and error");
  bool no_frame_errors = false, ignore_baked = false, no_light_layers = false;
  app.add_flag("--no-light-layers", no_light_layers,
               "keep no estimate per light layer (24 bytes per layer and texel); an edit that only scales lights "
               "(intensity, colour, emission, a constant sky) then restarts instead of scaling their layers with 0 rays");
  app.add_flag("--light-layers", options.whole_run_light_layers,
               "keep light layers in a whole run too (they are kept with --frames, --budget-ms or --spp-before-edits), "
               "so the bundle written holds them: a session opening it scales a light's layer from its first frame");
  bool denoise = false;
  int denoise_radius = 3;
  app.add_flag("--denoise", denoise,
               "filter the indirect light of what the session shows in texture space, on the device (as bake "
               "--denoise; biased, off by default): the written lightmap and each frame's page images; the bundle "
               "then holds no light layers");
  app.add_option("--denoise-radius", denoise_radius, "--denoise window radius in texels (default 3)")->check(CLI::Range(1, exitance::kFilterMaxRadius));
  app.add_flag("--ignore-baked", ignore_baked,
               "start every texel from nothing instead of from the bundle's baked lightmap (which is shown until refreshed samples are better, and which light edits are estimated as a change from)");
  app.add_option("--spp-before-edits", options.samples_before_edits,
                 "with --edits: refresh this many samples per texel before applying them (a session that has been "
                 "running when the edit comes; benchmarks)");
  app.add_option("--priority-samples", options.priority_samples,
                 "after a local edit, the samples per texel the texels near it get before the others get any "
                 "(default 32; 0: every pass takes every texel)");
  app.add_flag("--page-images", options.page_images,
               "with --frames: after each frame, write the lightmap pages into the device images an engine samples "
               "(exitance_runtime_publish_page_images), and the probes and voxel exitance into their device buffers "
               "where the bundle has them, and report each call's milliseconds per frame");
  app.add_flag("--no-frame-errors", no_frame_errors,
               "with --frames: no per-frame error (it reads the lightmap back between frames, which idles the GPU)");
  app.add_option("--integrator", options.integrator,
                 "path (default: progressive path tracing, frames) | bounces (the per-bounce mode, the whole lightmap "
                 "in one run; not with --frames or --budget-ms)")
      ->check(CLI::IsMember({"path", "bounces"}));
  app.add_option("--guiding", options.guiding,
                 "off (default) | grid | svo | auto (guided path tracing, as bake --backend vulkan --guiding grid|svo|auto; "
                 "svo reads the bundle's svo.bin; auto keeps grid guiding where its measured pilot says it pays and "
                 "reports the choice as guiding_auto: the whole lightmap in one run; not with --frames, --budget-ms or "
                 "--integrator bounces)")
      ->check(CLI::IsMember({"off", "grid", "svo", "auto"}));
  app.add_option("--bounce-caches", options.bounce_caches,
                 "device (default) | host: where --integrator bounces builds its layer caches (host: the earlier path, "
                 "built on the CPU and uploaded between layers, for A/B timing; the same results bit for bit)")
      ->check(CLI::IsMember({"device", "host"}));
  app.add_option("--emitter-guiding", options.emitter_guiding,
                 "off (default) | on (next-event estimation guided by emitter distributions learned during the run, as "
                 "bake --emitter-guiding on: the whole lightmap in one run; not with --frames, --budget-ms, --guiding or "
                 "--integrator bounces)")
      ->check(CLI::IsMember({"off", "on"}));
  app.add_option("--light-paths", options.light_paths,
                 "off (default) | on (light subpaths that the texels' paths connect to, as bake --light-paths on: with "
                 "--time, --frames or --budget-ms in the progressive refresh's passes, else the whole lightmap in one "
                 "run; not with --guiding, --emitter-guiding on or --integrator bounces)")
      ->check(CLI::IsMember({"off", "on"}));
  app.add_flag("--whole-run", options.whole_run,
               "path trace the whole lightmap in one run as bake --backend vulkan does (its passes, --time counted from "
               "the run's start, the read-back inside the lighting) instead of refresh calls: what --guiding and "
               "--emitter-guiding runs compare with; not with --frames, --budget-ms, --guiding or --integrator bounces");
  app.add_option("--seed", seed, "random seed (default: the bake's); results are deterministic per seed and device");
  app.add_option("--device", options.device_index, "Vulkan device index (see --list-devices)")->check(CLI::NonNegativeNumber);
  app.add_flag("--list-devices", list_devices, "print the Vulkan devices and exit");
  app.add_flag("--json", json_report, "print the run report as JSON on stdout");
  app.add_flag("--stage-statistics", options.stage_statistics,
               "time each wavefront stage on the GPU (timestamps, lane counters; slower, for benchmarks)");
  app.add_option("--traversal-rays", options.traversal_rays,
                 "also time N incoherent closest-hit rays (origins in the scene bounds, uniform directions) alone");
  std::string share;
  app.add_option("--share", share,
                 "R/N: time rank R's share of an N-rank bake (bake under mpirun) alone on this device, by path tracing "
                 "at --spp (benchmarks: the split's balance on one GPU); writes nothing");
  try {
    if (argc > 1 && std::string(argv[1]) == "--list-devices") {
      for (const auto& d : exitance::enumerate_vulkan_devices())
        std::cout << d.index << ": " << d.name << " (" << exitance::to_string(d.type) << ")"
                  << (d.usable ? "" : " unusable: " + d.missing_feature) << "\n";
      return 0;
    }
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exitance::exit_for_option_error(app, e, "exitance-relight");
  }
  if (!share.empty()) {
    int rank = -1, ranks = 0;
    char slash = 0, extra = 0;
    // The form here; relight_bundle checks the range, except N = 0, which it would read as no share.
    if (std::sscanf(share.c_str(), "%d%c%d%c", &rank, &slash, &ranks, &extra) != 3 || slash != '/' || ranks < 1) {
      std::cerr << "exitance-relight: error: --share " << share << ": expected R/N with 0 <= R < N\n";
      return 2;
    }
    options.share_rank = rank, options.share_ranks = ranks;
  }
  options.spp = spp;
  options.frame_errors = !no_frame_errors;
  options.from_baked = !ignore_baked;
  options.light_layers = !no_light_layers;
  options.denoise_radius = denoise ? denoise_radius : 0;
  options.seed = seed;
  const char* validation = std::getenv("EXITANCE_VULKAN_VALIDATION");
  options.validation = validation && std::string(validation) == "1";

  exitance::ProgressBar bar;
  options.progress = [&](const std::string& stage, double fraction, uint64_t rays) { bar.update(stage, fraction, rays); };
  try {
    const nlohmann::json report = exitance::relight_bundle(options);
    bar.finish();
    if (report.contains("warnings"))
      for (const auto& w : report["warnings"]) std::cerr << "exitance-relight: warning: " << w.get<std::string>() << "\n";
    if (json_report) {
      std::cout << report.dump(2) << "\n";
    } else if (options.share_ranks > 0) {
      std::cerr << "exitance-relight: share " << share << ": " << report["lighting_seconds"].get<double>() << " s, "
                << report["rays_per_second"].get<double>() * 1e-6 << " Mrays/s on " << report["device"].get<std::string>() << "\n";
    } else {
      std::cerr << "exitance-relight: wrote " << report["output"].get<std::string>() << " ("
                << report["rays_per_second"].get<double>() * 1e-6 << " Mrays/s on " << report["device"].get<std::string>()
                << ")\n";
    }
    return 0;
  } catch (const exitance::RelightInputError& e) {
    bar.finish();
    std::cerr << "exitance-relight: error: " << one_line(e.what()) << "\n";
    return 2;
  } catch (const exitance::VulkanDeviceFailure& e) {
    // Nothing was written (the bundle is renamed into place at the end). The device may still run
    // the hung submission: leave without static destructors, which could wait for it or unload
    // the code it runs.
    bar.finish();
    std::cerr << "exitance-relight: error: device failure during " << bar.stage() << ": " << one_line(e.what()) << "\n";
    std::fflush(stderr);
    std::_Exit(exitance::kDeviceFailureExitCode);
  } catch (const std::exception& e) {
    bar.finish();
    std::cerr << "exitance-relight: error: " << one_line(e.what()) << "\n";
    return 1;
  }
}
