#include "kernel_launches.h"

#include <algorithm>

#include "exitance/runtime/vulkan/vulkan_device_failure.h"

namespace exitance::vulkan {

VulkanStageStatistics& StageStatistics::operator[](const std::string& name) {
  for (VulkanStageStatistics& s : stages_)
    if (s.stage == name) return s;
  stages_.push_back({});
  stages_.back().stage = name;
  return stages_.back();
}

KernelLaunches::KernelLaunches(Context& context, const WavefrontKernels& kernels, StageStatistics& statistics, bool timed)
    : context_(context),
      kernels_(kernels),
      statistics_(statistics),
      timed_(timed && kernels.timestamp_queries() != VK_NULL_HANDLE),
      cmd_(context.begin()) {
  const VkDescriptorSet set = kernels.descriptor_set();
  vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, kernels.layout(), 0, 1, &set, 0, nullptr);
  if (timed_) {
    vkCmdResetQueryPool(cmd_, kernels.timestamp_queries(), 0, WavefrontKernels::kMaxTimestamps);
    stamp(nullptr);
  }
}

void KernelLaunches::barrier() const {
  VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT |
                    VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       0, 1, &b, 0, nullptr, 0, nullptr);
}

void KernelLaunches::bind(Kernel kernel, PushConstants push) {
  vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, kernels_.pipeline(kernel));
  vkCmdPushConstants(cmd_, kernels_.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
}

void KernelLaunches::note_launch(const std::string& name) {
  if (std::find(launched_.begin(), launched_.end(), name) == launched_.end()) launched_.push_back(name);
}

void KernelLaunches::launch_to_compile(Kernel kernel) {
  note_launch(std::string("compiling ") + kernel_file(kernel));
  bind(kernel, {});
  vkCmdDispatch(cmd_, 1, 1, 1);
  barrier();
}

void KernelLaunches::launch(const char* name, Kernel kernel, uint32_t groups, PushConstants push) {
  note_launch(name);
  statistics_[name];  // the stage is listed in launch order, timed or not
  bind(kernel, push);
  vkCmdDispatch(cmd_, groups, 1, 1);
  barrier();
  stamp(name);
}

void KernelLaunches::launch_queued(const char* name, Kernel kernel, IndirectDispatch dispatch, PushConstants push) {
  note_launch(name);
  statistics_[name];
  bind(kernel, push);
  vkCmdDispatchIndirect(cmd_, dispatch.buffer, dispatch.offset);
  barrier();
  stamp(name);
}

void KernelLaunches::leave_untimed() { stamp(nullptr); }

void KernelLaunches::stamp(const char* name) {
  if (!timed_ || stamped_.size() >= WavefrontKernels::kMaxTimestamps) return;
  vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, kernels_.timestamp_queries(), uint32_t(stamped_.size()));
  stamped_.push_back(name);
}

void KernelLaunches::submit_and_wait(double timeout_seconds) {
  try {
    context_.submit_and_wait(cmd_, timeout_seconds);
  } catch (const VulkanDeviceFailure& e) {
    std::string names;
    for (const std::string& n : launched_) names += (names.empty() ? "" : "; ") + n;
    throw VulkanDeviceFailure(std::string(e.what()) + " [submission: " + (names.empty() ? "copies" : names) + "]");
  }
  if (stamped_.size() < 2) return;
  std::vector<uint64_t> ts(stamped_.size());
  check(vkGetQueryPoolResults(context_.device(), kernels_.timestamp_queries(), 0, uint32_t(ts.size()), ts.size() * 8,
                              ts.data(), 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  const double period = double(context_.properties().limits.timestampPeriod) * 1e-9;
  for (size_t i = 1; i < ts.size(); ++i)
    if (stamped_[i]) statistics_[stamped_[i]].seconds += double(ts[i] - ts[i - 1]) * period;
}

}  // namespace exitance::vulkan
