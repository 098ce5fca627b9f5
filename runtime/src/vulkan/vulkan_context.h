// Thin RAII layer over the Vulkan objects the wavefront needs: its own instance (+ validation
// messenger) and device, or an engine's adopted ones; one compute queue, buffers, one-shot
// submissions with fence timeouts.
#pragma once
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance::vulkan {

std::string result_name(VkResult result);
// Throws std::runtime_error naming the call; device loss and out-of-memory get their own wording.
void check(VkResult result, const char* what);

class Context;

// A buffer and its memory, freed when the Buffer goes (the context outlives every buffer).
class Buffer {
 public:
  Buffer() = default;
  Buffer(Buffer&& other) noexcept { *this = std::move(other); }
  Buffer& operator=(Buffer&& other) noexcept;
  ~Buffer() { release(); }

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  void* mapped() const { return mapped_; }  // host-visible buffers only

 private:
  friend class Context;
  void release();
  Context* owner_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

// Bytes [offset, offset + size) of a buffer and of the host array that mirrors it.
struct ByteRange {
  VkDeviceSize offset = 0, size = 0;
};

// Runs [first, end) of records covering sorted, unique `indices`, two joined where at most
// kJoinedGapBytes of records lie between them: a copy command pays per region (on the H200 an edit's
// ~30 000 scattered records waited ~50 ms), so a short gap is cheaper copied along than cut out
// (written with its current, unchanged values).
constexpr size_t kJoinedGapBytes = 8192;
inline std::vector<std::pair<uint32_t, uint32_t>> record_runs(const std::vector<uint32_t>& indices, size_t record_bytes) {
  const uint32_t max_gap = uint32_t(std::max<size_t>(1, kJoinedGapBytes / record_bytes));
  std::vector<std::pair<uint32_t, uint32_t>> runs;
  for (uint32_t i : indices) {
    if (!runs.empty() && i <= runs.back().second + max_gap) runs.back().second = i + 1;
    else runs.push_back({i, i + 1});
  }
  return runs;
}
inline std::vector<ByteRange> byte_ranges(const std::vector<std::pair<uint32_t, uint32_t>>& runs, size_t record_bytes) {
  std::vector<ByteRange> ranges;
  for (const auto& [first, end] : runs) ranges.push_back({VkDeviceSize(first) * record_bytes, VkDeviceSize(end - first) * record_bytes});
  return ranges;
}

class Context {
 public:
  // Transfers up to this size go through one staging buffer the context keeps; larger ones allocate
  // their own (or use a caller's).
  static constexpr VkDeviceSize kReusedStagingLimit = 16 * 1024 * 1024;
  // Creates an instance and a device, or adopts options.external_device (checked, never destroyed).
  explicit Context(const VulkanDeviceOptions& options);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkDevice device() const { return device_; }
  const VulkanDeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memory_properties() const { return memory_properties_; }
  bool timestamps() const { return timestamp_valid_bits_ > 0; }
  bool adopted() const { return !owns_device_; }
  // The handles an engine sharing the device needs (exitance_runtime_vulkan.h).
  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  VkPhysicalDeviceFeatures enabled_features() const { return enabled_features_; }
  // Whether timeline semaphores were enabled (own device: when supported; adopted: as the engine says).
  bool timeline_semaphores() const { return timeline_semaphores_; }
  // Device-local memory for `requirements` (an image's), freed by the caller with vkFreeMemory.
  VkDeviceMemory allocate_device_local(const VkMemoryRequirements& requirements, const char* what);

  Buffer create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible);
  // A device-local storage buffer; throws when `size` exceeds the device's maxStorageBufferRange.
  Buffer create_storage_buffer(VkDeviceSize size, VkBufferUsageFlags extra_usage = 0);
  // Copies host data into a device buffer (through a staging buffer) and waits.
  void upload(const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset = 0);
  // Copies the ranges of `data`, a host mirror of `dst`, to the same ranges of `dst`, and waits.
  void upload_ranges(const Buffer& dst, const void* data, const std::vector<ByteRange>& ranges);
  // Hands `write` a host-visible staging mapping to fill with the `ranges`' bytes, packed in order,
  // then copies them to those ranges of `dst` and waits: for uploads made on the way, without a host
  // copy in between (`write` is not called when the ranges hold no bytes).
  // `staging`: as read_back_ranges's.
  void write_ranges(const Buffer& dst, const std::vector<ByteRange>& ranges, const std::function<void(char*)>& write,
                    const Buffer* staging = nullptr);
  // Several write_ranges to different buffers, staged together and copied in one submission waited
  // for once: an edit's few small uploads cost one round trip instead of one each.
  struct RangeWrite {
    const Buffer* dst = nullptr;
    std::vector<ByteRange> ranges;
    std::function<void(char*)> write;  // fills the ranges' bytes, packed in order
    // The first `bytes` of `dst` from `data` (which must outlive the write).
    static RangeWrite whole(const Buffer& dst, const void* data, size_t bytes);
    // The `ranges` of `dst` from the same ranges of `mirror`, a host copy of it (which must outlive the write).
    static RangeWrite mirrored(const Buffer& dst, const void* mirror, std::vector<ByteRange> ranges);
  };
  void write_ranges(const std::vector<RangeWrite>& writes, const Buffer* staging = nullptr);
  void download(const Buffer& src, void* data, VkDeviceSize size, VkDeviceSize offset = 0);
  // Copies the `ranges` of `src`, packed in order, into a host-visible staging buffer, waits, and
  // hands `read` its mapping: for read-backs converted on the way, without a host copy in between
  // (`read` is not called when the ranges hold no bytes).
  // `staging`: a host-visible buffer to copy through when it is large enough (made ahead of time:
  // allocating pinned memory is part of a read-back's cost), else one is made here.
  void read_back_ranges(const Buffer& src, const std::vector<ByteRange>& ranges, const std::function<void(const char*)>& read,
                        const Buffer* staging = nullptr);
  // Grows `kept`, a caller's host-visible staging buffer for the `staging` arguments above, to at
  // least `bytes` (made once for the largest of a run's transfers, then reused).
  void keep_staging(Buffer& kept, VkDeviceSize bytes);

  // Work recorded at the start of the next submission (in begin(), before the caller's commands,
  // then a barrier that makes its writes visible to all that follows): an edit's small clears and
  // uploads then cost no submission and no wait of their own. A recorder reads its buffers'
  // handles when it runs, so it must outlive nothing it names. Kept until a submission that
  // recorded it has been waited for (a command buffer begun and never submitted leaves it pending).
  void record_at_next_submission(std::function<void(VkCommandBuffer)> record);
  // `size` bytes of `data` copied now into staging the context keeps, and from there to `dst` at
  // `offset` at the start of the next submission (record_at_next_submission).
  void upload_at_next_submission(const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset = 0);
  // write_ranges(writes) the same way: each write fills its bytes in the kept staging now, and the
  // copies are recorded at the start of the next submission.
  void write_ranges_at_next_submission(const std::vector<RangeWrite>& writes);
  // Both kept staging buffers (the reused one and the next submission's) at least `bytes`, and
  // their pages written once: a runtime session's first edit then neither allocates host-visible
  // memory nor faults its pages in (the first edit's uploads were 0.6-0.8 ms slower than later ones).
  void reserve_staging(VkDeviceSize bytes);

  VkCommandBuffer begin();  // the context's single command buffer, reset; records what is pending (above)
  // Submits the command buffer and waits for its fence (bounded by fence_timeout_seconds); throws
  // VulkanDeviceFailure on timeout or device loss.
  // `timeout_seconds` > 0 replaces the fence timeout for this submission (kernel compilation).
  void submit_and_wait(VkCommandBuffer cmd, double timeout_seconds = 0);
  // The same, also signalling timeline semaphore `signal` to `value`, and waiting (bounded alike)
  // until the semaphore shows it too (lavapipe was seen to signal the fence first).
  void submit_and_wait(VkCommandBuffer cmd, VkSemaphore signal, uint64_t value);
  bool lost() const { return lost_; }
  // Submissions waited for so far and the host time spent waiting (what an edit's few small
  // uploads cost is mostly these round trips: exitance-relight --json edits.device).
  struct Waits {
    uint64_t submissions = 0;
    double seconds = 0;
  };
  const Waits& waits() const { return waits_; }
  // A submission may still be running (its fence timed out): from here on nothing is destroyed on
  // this device and nothing waits for it; its objects are leaked on purpose.
  bool hung() const { return hung_; }
  // Marks the device unusable after a fault the kernels counted, and throws VulkanDeviceFailure
  // with `message`; the device is idle, so teardown proceeds as usual.
  [[noreturn]] void fail(const std::string& message);

 private:
  friend class Buffer;
  void create_own_device(const VulkanDeviceOptions& options);
  void adopt(const VulkanExternalDevice& external);
  void create_submission_objects();
  void cleanup();
  void destroy(Buffer& buffer);
  void submit_and_wait(VkCommandBuffer cmd, double timeout_seconds, VkSemaphore signal, uint64_t value);
  uint32_t find_memory_type(uint32_t bits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const;

  VulkanDeviceOptions options_;
  struct Messages;
  std::unique_ptr<Messages> messages_;
  bool owns_device_ = true;  // false: instance and device are an engine's (never destroyed here)
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkPhysicalDeviceFeatures enabled_features_{};
  bool timeline_semaphores_ = false;
  uint32_t timestamp_valid_bits_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VulkanDeviceInfo info_;
  // Host-visible staging reused by uploads and read-backs (each waits for its copy, so one buffer
  // serves them in turn): 4 MiB at first (a city block's move uploads ~3.6 MB: its triangles, leaf
  // slots, nodes and every emitter's record), grown to the largest transfer up to 16 MiB, so an
  // edit allocates nothing (a new pinned buffer cost the first edit its allocation); larger
  // transfers get their own.
  Buffer small_staging_;
  bool small_staging_busy_ = false;
  static constexpr VkDeviceSize kSmallStagingBytes = 4 * 1024 * 1024;
  // `given` when it is a mapped buffer of at least `size` bytes (a caller's kept staging), else the
  // reused staging when `size` fits and it is free (marked busy until `own` is released by the
  // caller's scope: see StagingLease in the .cpp), else a new buffer in `own`.
  const Buffer& staging_for(VkDeviceSize size, Buffer& own, bool& leased, const Buffer* given = nullptr);
  bool lost_ = false;
  bool hung_ = false;
  Waits waits_;
  // record_at_next_submission's recorders; the first `pending_recorded_` are in the command buffer
  // begun last. upload_at_next_submission's bytes, packed in `deferred_staging_` up to `deferred_bytes_`.
  std::vector<std::function<void(VkCommandBuffer)>> pending_;
  size_t pending_recorded_ = 0;
  Buffer deferred_staging_;
  VkDeviceSize deferred_bytes_ = 0;
};

}  // namespace exitance::vulkan
