// Named kernel launches, as pbrt-v4's wavefront names every ForAllQueued: each launch carries a
// name saying what it computes, and the per-stage statistics (GPU time, items, rays, lane
// efficiency) are keyed by those names, so a profile reads like the algorithm.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "vulkan_context.h"
#include "wavefront_buffers.h"
#include "wavefront_kernels.h"

namespace exitance::vulkan {

// Per-stage figures keyed by launch name, in the order of their first launch.
class StageStatistics {
 public:
  void clear() { stages_.clear(); }
  VulkanStageStatistics& operator[](const std::string& name);  // adds the stage when new
  const std::vector<VulkanStageStatistics>& all() const { return stages_; }

 private:
  std::vector<VulkanStageStatistics> stages_;
};

// One command buffer of launches: each binds its pipeline and push constants, dispatches a fixed
// grid, or over a queue the grid that prepare.comp wrote for it, and ends with a barrier. Timed,
// a timestamp after each launch charges the GPU time since the previous one to its name.
class KernelLaunches {
 public:
  KernelLaunches(Context& context, const WavefrontKernels& kernels, StageStatistics& statistics, bool timed);
  KernelLaunches(const KernelLaunches&) = delete;
  KernelLaunches& operator=(const KernelLaunches&) = delete;

  // `groups` workgroups of the kernel's size (64 threads; prepare: 1).
  void launch(const char* name, Kernel kernel, uint32_t groups, PushConstants push = {});
  // One thread per entry of a queue, the grid read from `dispatch`.
  void launch_queued(const char* name, Kernel kernel, IndirectDispatch dispatch, PushConstants push = {});

  VkCommandBuffer commands() const { return cmd_; }  // for fills, copies and parameter updates
  void barrier() const;  // every write so far is visible to what follows
  // Timed: the commands recorded since the last timestamp are charged to no launch.
  void leave_untimed();
  // One workgroup of `kernel` with the parameters as they are, outside the statistics: makes a
  // driver that compiles pipelines at their first dispatch (lavapipe) compile it now.
  void launch_to_compile(Kernel kernel);
  // Submits, waits (`timeout_seconds` > 0: instead of the fence timeout), and charges each timed
  // launch's GPU time to its name. A device failure's message names the submission's launches.
  void submit_and_wait(double timeout_seconds = 0);

 private:
  void note_launch(const std::string& name);
  void bind(Kernel kernel, PushConstants push);
  void stamp(const char* name);

  Context& context_;
  const WavefrontKernels& kernels_;
  StageStatistics& statistics_;
  bool timed_;
  VkCommandBuffer cmd_;
  std::vector<const char*> stamped_;  // per timestamp, the launch it ends (null: none)
  std::vector<std::string> launched_;  // distinct launch names, in order (device failure messages)
};

}  // namespace exitance::vulkan
