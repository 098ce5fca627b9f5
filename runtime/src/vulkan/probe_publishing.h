// The refreshed probes as they show, written by shaders/wavefront/publish_probes.comp into a device
// buffer an engine reads (DeviceProbeBuffer): per refreshed probe the publishing rule's choice
// between its refreshed sums (ProbeAccumulators) and what it showed before the last edit (`kept`,
// uploaded when it changes), or during a change estimate of light edits between that, the change's
// base and base + change, in its slot of the grid. No read-back; the values equal
// RefreshSession::published_probes().
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "compute_kernel.h"
#include "exitance/runtime/vulkan/device_probe_buffer.h"
#include "shared_device_buffer.h"
#include "vulkan_context.h"
#include "wavefront_buffers.h"

namespace exitance::vulkan {

class ProbePublisher {
 public:
  // Per probe: what it showed before the last edit (27 SH values, samples, variance; < 0: unknown),
  // then a change estimate's base (27 SH values, samples; ignored without one).
  static constexpr size_t kKeptWords = 57;
  // A buffer for `grid_probes` probes; `grid_index`: per refreshed probe its slot in the grid.
  ProbePublisher(Context& context, size_t grid_probes, const std::vector<uint32_t>& grid_index);
  ProbePublisher(const ProbePublisher&) = delete;
  ProbePublisher& operator=(const ProbePublisher&) = delete;

  bool fits(size_t grid_probes, const std::vector<uint32_t>& grid_index) const;
  // What each refreshed probe showed before (kKeptWords per probe), uploaded.
  void set_kept(const std::vector<double>& kept);
  // Writes the buffer in one submission after everything submitted to the queue before it,
  // signals the semaphore and waits for it (bounded). `band_weight`: the dering window per band.
  // `change`: the sums estimate a change of the lights from the kept base (published_probes.h).
  const DeviceProbeBuffer& write(const ProbeAccumulators& sums, uint32_t switch_samples, const std::array<float, 3>& band_weight,
                                 bool change = false);
  std::vector<float> read_back() const { return out_buffer_.read_back(); }  // for tests and tools

 private:
  Context& context_;
  size_t probes_;  // refreshed probes
  std::vector<uint32_t> grid_index_;
  Buffer kept_, index_;
  SharedDeviceBuffer out_buffer_;
  DeviceProbeBuffer out_;
  ComputeKernel kernel_;
};

}  // namespace exitance::vulkan
