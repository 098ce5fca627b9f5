#include "guide_fold_kernel.h"

#include <algorithm>
#include <cstring>

#include "exitance/common/gpu_layout.h"
#include "exitance_spirv/fold_emitter_guide.h"
#include "exitance_spirv/fold_guide.h"

namespace exitance::vulkan {
namespace {

struct FoldPush {
  uint32_t first;
  uint32_t argument;  // grid: the mix's float bits; emitter: the section's first word
};

}  // namespace

GuideFoldKernel::GuideFoldKernel(Context& context, GuideFold which)
    : context_(context),
      kernel_(context, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, sizeof(FoldPush),
              which == GuideFold::Grid ? spirv_fold_guide : spirv_fold_emitter_guide,
              which == GuideFold::Grid ? sizeof(spirv_fold_guide) : sizeof(spirv_fold_emitter_guide), 1,
              which == GuideFold::Grid ? "fold_guide.comp" : "fold_emitter_guide.comp") {}

void GuideFoldKernel::record(VkCommandBuffer cmd, const Buffer& guide, uint32_t records, uint32_t argument) {
  // The binding's buffer is the one the passes use now (it is replaced when a guide grows it).
  const VkDescriptorBufferInfo info{guide.handle(), 0, VK_WHOLE_SIZE};
  kernel_.write_buffers(0, &info, 1);
  writes_visible_to_compute(cmd);  // the pass's atomic adds to the back sums
  kernel_.bind(cmd, 0);
  // Records past the device's largest dispatch in further dispatches (independent records).
  const uint32_t per_dispatch = std::min<uint32_t>(context_.properties().limits.maxComputeWorkGroupCount[0], 1u << 20) * 64u;
  for (uint32_t first = 0; first < records; first += per_dispatch) {
    const FoldPush push{first, argument};
    kernel_.push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, (std::min(records - first, per_dispatch) + 63) / 64, 1, 1);
  }
  compute_done_before_all(cmd);
}

void GuideFoldKernel::fold_grid(const Buffer& guide, uint32_t records, float mix) {
  if (records == 0) return;
  uint32_t mix_bits = 0;
  std::memcpy(&mix_bits, &mix, 4);
  VkCommandBuffer cmd = context_.begin();
  record(cmd, guide, records, mix_bits);
  context_.submit_and_wait(cmd);
}

uint32_t GuideFoldKernel::fold_emitters(const Buffer& guide, uint32_t records, uint32_t section) {
  if (records == 0) return 0;
  const VkDeviceSize counter = (VkDeviceSize(section) + kEmitterGuideSampling) * 4;
  VkCommandBuffer cmd = context_.begin();
  vkCmdFillBuffer(cmd, guide.handle(), counter, 4, 0);
  record(cmd, guide, records, section);
  context_.submit_and_wait(cmd);
  uint32_t sampling = 0;
  context_.download(guide, &sampling, 4, counter);
  return sampling;
}

}  // namespace exitance::vulkan
