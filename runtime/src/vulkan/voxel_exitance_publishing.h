// The voxel exitance of a published estimate, computed on the device every call by
// shaders/wavefront/publish_voxel_exitance.comp into a buffer an engine reads (DeviceVoxelExitance):
// fill_svo_exitance's deposit, bottom-up means and top-down fill, in floats (no half-float
// encoding), from where voxel_deposits (bundle/texel_exitance.h) says each texel goes.
#pragma once
#include <cstdint>
#include <vector>

#include "compute_kernel.h"
#include "device_lightmaps.h"
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/vulkan/device_voxel_exitance.h"
#include "shared_device_buffer.h"
#include "vulkan_context.h"

namespace exitance::vulkan {

class VoxelExitancePublisher {
 public:
  VoxelExitancePublisher(Context& context, const formats::SparseVoxelOctree& svo);
  VoxelExitancePublisher(const VoxelExitancePublisher&) = delete;
  VoxelExitancePublisher& operator=(const VoxelExitancePublisher&) = delete;

  // Where the texels deposit (again after an edit moved texels or changed materials), uploaded.
  void set_deposits(const VoxelDeposits& deposits);
  // The voxel exitance of `lightmap` (a published estimate of the deposits' texels), in one
  // submission after everything submitted to the queue before it; waits (bounded).
  const DeviceVoxelExitance& write(const DeviceLightmap& lightmap);
  std::vector<float> read_back() const { return out_buffer_.read_back(); }  // for tests and tools

 private:
  Context& context_;
  std::vector<uint32_t> level_begin_;
  Buffer side_first_, entries_, nodes_, scratch_, state_;
  bool deposits_set_ = false;
  SharedDeviceBuffer out_buffer_;
  DeviceVoxelExitance out_;
  ComputeKernel kernel_;
};

}  // namespace exitance::vulkan
