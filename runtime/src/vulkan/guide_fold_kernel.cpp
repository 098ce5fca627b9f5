#include "guide_fold_kernel.h"

#include <algorithm>

#include "exitance_spirv/fold_guide.h"

namespace exitance::vulkan {
namespace {

struct FoldPush {
  float mix;
  uint32_t first;
};

}  // namespace

GuideFoldKernel::GuideFoldKernel(Context& context)
    : context_(context),
      kernel_(context, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, sizeof(FoldPush), spirv_fold_guide, sizeof(spirv_fold_guide), 1,
              "fold_guide.comp") {}

void GuideFoldKernel::fold(const Buffer& guide, uint32_t records, float mix) {
  if (records == 0) return;
  // The binding's buffer is the one the passes use now (it is replaced when a guide grows it).
  const VkDescriptorBufferInfo info{guide.handle(), 0, VK_WHOLE_SIZE};
  kernel_.write_buffers(0, &info, 1);
  VkCommandBuffer cmd = context_.begin();
  writes_visible_to_compute(cmd);  // the pass's atomic adds to the back sums
  kernel_.bind(cmd, 0);
  // Records past the device's largest dispatch in further dispatches (independent records).
  const uint32_t per_dispatch = std::min<uint32_t>(context_.properties().limits.maxComputeWorkGroupCount[0], 1u << 20) * 64u;
  for (uint32_t first = 0; first < records; first += per_dispatch) {
    const FoldPush push{mix, first};
    kernel_.push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, (std::min(records - first, per_dispatch) + 63) / 64, 1, 1);
  }
  compute_done_before_all(cmd);
  context_.submit_and_wait(cmd);
}

}  // namespace exitance::vulkan
