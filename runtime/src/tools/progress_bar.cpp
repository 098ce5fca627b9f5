#include "exitance/runtime/tools/progress_bar.h"

#include <unistd.h>

#include <cstdio>

namespace exitance {

ProgressBar::ProgressBar() : enabled_(::isatty(STDERR_FILENO) != 0) {}

void ProgressBar::update(const std::string& stage, double fraction, uint64_t rays) {
  const auto now = std::chrono::steady_clock::now();
  if (stage != stage_) stage_ = stage, stage_start_ = now;
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
  constexpr int kWidth = 30;
  const int filled = int(fraction * kWidth + 0.5);
  std::string bar(size_t(filled), '#');
  bar.resize(kWidth, '.');
  char line[160];
  if (rays > 0 && elapsed > 0) {
    const double eta = fraction > 0.01 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    std::snprintf(line, sizeof line, "\r%-9s [%s] %3.0f%%  %.2f Mrays/s  eta %.0fs   ", stage.c_str(), bar.c_str(),
                  fraction * 100.0, double(rays) / elapsed * 1e-6, eta);
  } else {
    std::snprintf(line, sizeof line, "\r%-9s [%s] %3.0f%%                              ", stage.c_str(), bar.c_str(),
                  fraction * 100.0);
  }
  std::fputs(line, stderr);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (drawn_) std::fputs("\n", stderr);
  drawn_ = false;
}

}  // namespace exitance
