// Milliseconds of RefreshSession::apply_edits alone, per phase (EditTimings), on a bundle: the
// edits of `--edits A` and `--edits-back B` applied in turn (A moves something, B moves it back, so
// every round starts from the same scene), each followed by a refresh of `--samples` samples over
// the texels near the edit (as a frame would give them), `--repeat` rounds; prints the median and
// the range of each phase for each direction. Profiling target for issue 32's edit costs (the
// figures an engine sees come from exitance-relight --json's edits.milliseconds, which this matches).
//
// `--samples-before N`: the session refreshes N samples per texel first (a session that has been
// running; an edit that only scales lights is applied by scaling its light layers once it has 256).
//
//   bench_edit_cost BUNDLE --edits A.json --edits-back B.json [--repeat 9] [--samples 1] [--samples-before 0]
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "exitance/runtime/refresh/refresh_session.h"
#include "exitance/runtime/refresh/scene_edits.h"

#include "wall_clock.h"

using namespace exitance;

namespace {

std::vector<SceneEdit> read_edits(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_scene_edits(text, path);
}

struct Phases {
  std::vector<double> total, scene, texels, near_texels, uploads, publish, restart, wait, submissions;
  void add(double ms, const EditTimings& t) {
    total.push_back(ms), scene.push_back(t.scene), texels.push_back(t.texels), near_texels.push_back(t.near_texels);
    uploads.push_back(t.uploads);
    publish.push_back(t.publish), restart.push_back(t.restart), wait.push_back(t.device_wait);
    submissions.push_back(double(t.device_submissions));
  }
  void print(const char* name) const {
    auto row = [](const char* what, std::vector<double> v) {
      std::sort(v.begin(), v.end());
      std::printf("  %-12s median %8.3f  min %8.3f  max %8.3f\n", what, bench::median(v), v.front(), v.back());
    };
    std::printf("%s (%zu edits)\n", name, total.size());
    row("total ms", total), row("scene", scene), row("texels", texels), row("near_texels", near_texels);
    row("uploads", uploads), row("publish", publish);
    row("restart", restart), row("device_wait", wait), row("submissions", submissions);
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"apply_edits' cost per phase on a bundle (bench/results/refresh-gpu.md)"};
  std::string bundle, forth, back;
  int repeat = 9;
  uint32_t samples = 1, samples_before = 0;
  app.add_option("bundle", bundle, "baked bundle folder")->required();
  app.add_option("--edits", forth, "edits applied first in each round")->required();
  app.add_option("--edits-back", back, "edits applied second (undoing the first)")->required();
  app.add_option("--repeat", repeat, "rounds")->check(CLI::PositiveNumber);
  app.add_option("--samples", samples, "samples per texel refreshed after each edit (0: none)");
  app.add_option("--samples-before", samples_before, "samples per texel refreshed before the first edit");
  CLI11_PARSE(app, argc, argv);
  try {
    const std::vector<SceneEdit> a = read_edits(forth), b = read_edits(back);
    auto session = RefreshSession::open(bundle);
    if (samples_before > 0) session->refresh(RefreshBudget{0, samples_before, 0});
    Phases there, home;
    size_t scaled = 0;
    double first_ms = 0, first_uploads = 0;  // a session's first edit (allocations, first touches)
    for (int r = 0; r < repeat; ++r) {
      for (int k = 0; k < 2; ++k) {
        const auto start = std::chrono::steady_clock::now();
        session->apply_edits(k == 0 ? a : b);
        const double ms = bench::seconds_since(start) * 1e3;
        (k == 0 ? there : home).add(ms, session->last_edit_timings());
        if (r == 0 && k == 0) first_ms = ms, first_uploads = session->last_edit_timings().uploads;
        scaled += session->last_edit_timings().scaled_light_layers;
        if (samples > 0) session->refresh(RefreshBudget{0, samples, 0});
      }
    }
    std::printf("first edit %.3f ms (uploads %.3f)\n", first_ms, first_uploads);
    there.print(forth.c_str());
    home.print(back.c_str());
    std::printf("edits applied by scaling light layers: %zu of %d\n", scaled, 2 * repeat);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_edit_cost: %s\n", e.what());
    return 2;
  }
  return 0;
}
