#include "exitance/runtime/view/view_render.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace exitance::view {

ViewImage render_view(const ViewScene& view, const PinholeCamera& camera, const ViewRenderOptions& options) {
  // The tool and the preview check their options first; the library refuses what it cannot draw.
  if (options.width < 1 || options.height < 1 || options.width > 16384 || options.height > 16384)
    throw std::invalid_argument("render_view: image size " + std::to_string(options.width) + " x " +
                                std::to_string(options.height) + " is outside 1..16384");
  if (options.samples_per_axis < 1 || options.samples_per_axis > 16)
    throw std::invalid_argument("render_view: " + std::to_string(options.samples_per_axis) +
                                " samples per axis is outside 1..16");
  ViewImage image;
  image.width = options.width;
  image.height = options.height;
  image.rgb.assign(size_t(options.width) * size_t(options.height) * 3, 0.0f);
  const int n = options.samples_per_axis;
  std::atomic<int> next_row{0};
  const auto render_rows_of = [&](RayScratch& scratch) {
    for (int y = next_row++; y < image.height; y = next_row++)
      for (int x = 0; x < image.width; ++x) {
        Vec3 sum(0);
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) {
            const PrimaryRay ray = primary_ray(camera, x + (i + 0.5) / n, y + (j + 0.5) / n, image.width, image.height);
            sum += shade_primary_ray(view, options.mode, ray.origin, ray.direction, scratch);
          }
        const Vec3 mean = sum / float(n * n);
        float* out = &image.rgb[(size_t(y) * size_t(image.width) + size_t(x)) * 3];
        out[0] = mean.x;
        out[1] = mean.y;
        out[2] = mean.z;
      }
  };
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto render_rows = [&] {
    RayScratch scratch;
    try {
      render_rows_of(scratch);
    } catch (...) {
      // A lookup refused its input: stop every thread and rethrow on the caller's.
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next_row = image.height;
    }
  };
  // No more threads than rows, and a sane cap on what a caller may ask for.
  constexpr unsigned kMaxThreads = 1024;
  const unsigned asked = options.threads ? options.threads : std::thread::hardware_concurrency();
  const unsigned threads = std::max(1u, std::min({asked, unsigned(image.height), kMaxThreads}));
  std::vector<std::thread> workers;
  for (unsigned t = 1; t < threads; ++t) workers.emplace_back(render_rows);
  render_rows();
  for (std::thread& w : workers) w.join();
  if (failure) std::rethrow_exception(failure);
  return image;
}

}  // namespace exitance::view
