#include "traversal_benchmark.h"

#include <algorithm>
#include <stdexcept>

namespace exitance::vulkan {

double measure_incoherent_traversal(WavefrontBatchRunner& runner, uint32_t ray_count, int repetitions) {
  StageStatistics& statistics = runner.statistics();
  statistics.clear();
  runner.bind_buffers();
  GpuParams params{};
  params.path_capacity = runner.sizes().paths;
  params.batch_work_total = ray_count;
  params.traversal_steps = runner.scene().traversal_step_bound();
  params.collect_stats = 1;
  params.seed_lo = 12345;
  params.bench_lo = Vec4(runner.scene().bounds_lo(), 0.0f);
  params.bench_hi = Vec4(runner.scene().bounds_hi(), 0.0f);
  if (!runner.context().timestamps()) throw std::runtime_error("Vulkan backend: this device has no timestamp queries");
  double best = 0;
  uint64_t busy = 0, launched = 0;
  for (int rep = 0; rep < std::max(1, repetitions); ++rep) {
    statistics[stage::kTraversalOnly].seconds = 0;
    KernelLaunches launches = runner.launches(true);
    runner.update_params(launches, params);
    vkCmdFillBuffer(launches.commands(), runner.buffers().control.counters.handle(), 0, VK_WHOLE_SIZE, 0);
    launches.barrier();
    launches.leave_untimed();
    launches.launch(stage::kTraversalOnly, Kernel::TraversalOnly, groups_for(ray_count));
    runner.copy_counters(launches);
    launches.submit_and_wait();
    const double seconds = statistics[stage::kTraversalOnly].seconds;
    if (seconds > 0) best = std::max(best, double(ray_count) / seconds);
    busy = runner.buffers().control.read_back64(kCounterStatExtendActive);
    launched = runner.buffers().control.read_back64(kCounterStatExtendLaunched);
  }
  VulkanStageStatistics& s = statistics[stage::kTraversalOnly];
  s.rays = ray_count;
  s.items = runner.buffers().control.read_back()[kCounterRaysPrimary];  // rays that hit something
  s.seconds = double(ray_count) / std::max(best, 1e-30);
  s.lane_efficiency = launched ? double(busy) / double(launched) : 0.0;
  return best;
}

}  // namespace exitance::vulkan
