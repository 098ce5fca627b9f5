#include "vulkan_context.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "device_requirements.h"
#include "driver_allocation_scope.h"
#include "exitance/runtime/vulkan/vulkan_device_failure.h"

namespace exitance::vulkan {

std::string result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    default: return "VkResult " + std::to_string(int(r));
  }
}

void check(VkResult r, const char* what) {
  if (r == VK_SUCCESS) return;
  if (r == VK_ERROR_DEVICE_LOST)
    throw std::runtime_error(std::string("Vulkan device lost during ") + what +
                             " (driver reset or GPU fault; try a smaller --max-paths or the cpu backend)");
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
    throw std::runtime_error(std::string("Vulkan out of memory during ") + what + " (" + result_name(r) +
                             "; try fewer paths in flight or a lower texel density)");
  throw std::runtime_error(std::string("Vulkan error in ") + what + ": " + result_name(r));
}

struct Context::Messages {
  std::function<void(const std::string&)> sink;
  std::mutex mutex;
};

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT, const VkDebugUtilsMessengerCallbackDataEXT* data,
                                              void* user) {
  auto* messages = static_cast<std::function<void(const std::string&)>*>(user);
  const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  const std::string text = std::string("[vulkan ") + level + "] " + (data && data->pMessage ? data->pMessage : "");
  if (messages && *messages) (*messages)(text);
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messenger_info(void* user) {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = debug_callback;
  info.pUserData = user;
  return info;
}

VkInstance create_instance(bool validation, VkDebugUtilsMessengerCreateInfoEXT* messenger) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "exitance";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  if (validation) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    if (std::none_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, layer) == 0; }))
      throw std::runtime_error("Vulkan validation requested but VK_LAYER_KHRONOS_validation is not installed "
                               "(Debian: vulkan-validationlayers)");
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = &extension;
    info.pNext = messenger;
  }
  VkInstance instance = VK_NULL_HANDLE;
  VkResult r;
  {
    const DriverAllocationScope driver;
    r = vkCreateInstance(&info, nullptr, &instance);
  }
  if (r != VK_SUCCESS)
    throw std::runtime_error("no Vulkan device: cannot create a Vulkan instance (" + result_name(r) +
                             "; is a Vulkan driver such as mesa-vulkan-drivers installed?)");
  return instance;
}

// One copy region per range that holds bytes, its bytes packed after the ones before it in a
// staging buffer: staging -> buffer when `from_staging`, else buffer -> staging. `packed`: their total.
std::vector<VkBufferCopy> staging_regions(const std::vector<ByteRange>& ranges, bool from_staging, VkDeviceSize& packed) {
  std::vector<VkBufferCopy> regions;
  packed = 0;
  for (const ByteRange& r : ranges) {
    if (r.size == 0) continue;
    regions.push_back(from_staging ? VkBufferCopy{packed, r.offset, r.size} : VkBufferCopy{r.offset, packed, r.size});
    packed += r.size;
  }
  return regions;
}

// Each write's copy regions from a staging buffer holding the writes' bytes packed in order from
// `first`; `start[w]`: where write w's bytes begin. Returns where the packed bytes end.
VkDeviceSize packed_write_regions(const std::vector<Context::RangeWrite>& writes, VkDeviceSize first,
                                  std::vector<std::vector<VkBufferCopy>>& regions, std::vector<VkDeviceSize>& start) {
  regions.assign(writes.size(), {});
  start.assign(writes.size(), 0);
  VkDeviceSize end = first;
  for (size_t w = 0; w < writes.size(); ++w) {
    VkDeviceSize packed = 0;
    regions[w] = staging_regions(writes[w].ranges, /*from_staging=*/true, packed);
    for (VkBufferCopy& r : regions[w]) r.srcOffset += end;
    start[w] = end;
    end += packed;
  }
  return end;
}

}  // namespace

// EXITANCE_VULKAN_FENCE_TIMEOUT=SECONDS replaces VulkanDeviceOptions::fence_timeout_seconds (a very
// slow or shared machine; the tests use a tiny one to exercise the timeout path).
static VulkanDeviceOptions with_environment(VulkanDeviceOptions options) {
  const char* text = std::getenv("EXITANCE_VULKAN_FENCE_TIMEOUT");
  if (!text) return options;
  char* end = nullptr;
  const double seconds = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(seconds > 0) || !std::isfinite(seconds))
    throw std::invalid_argument(std::string("EXITANCE_VULKAN_FENCE_TIMEOUT: expected seconds > 0, got '") + text + "'");
  options.fence_timeout_seconds = seconds;
  return options;
}

Context::Context(const VulkanDeviceOptions& options) : options_(with_environment(options)), messages_(new Messages) {
  try {
    if (options.external_device) adopt(*options.external_device);
    else create_own_device(options);
    create_submission_objects();
  } catch (...) {
    cleanup();
    throw;
  }
}

void Context::create_own_device(const VulkanDeviceOptions& options) {
  messages_->sink = options.on_validation_message;
  VkDebugUtilsMessengerCreateInfoEXT messenger = messenger_info(&messages_->sink);
  instance_ = create_instance(options.validation, &messenger);
  if (options.validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (create) check(create(instance_, &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
  uint32_t count = 0;
  std::vector<VkPhysicalDevice> devices;
  {
    const DriverAllocationScope driver;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    devices.resize(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  }
  if (count == 0) throw std::runtime_error("no Vulkan device: the Vulkan loader found no physical device");
  int chosen = -1;
  std::string reasons;
  for (uint32_t i = 0; i < count; ++i) {
    const VulkanDeviceInfo d = describe_device(devices[i], i);
    if (!d.usable) reasons += " " + d.name + " lacks " + d.missing_feature + ";";
    if (options.device_index >= 0) {
      if (int(i) == options.device_index) {
        if (!d.usable) throw std::runtime_error("Vulkan device " + std::to_string(i) + " (" + d.name + ") lacks " + d.missing_feature);
        chosen = int(i);
      }
    } else if (d.usable && (chosen < 0 || preference_rank(d.type) < preference_rank(describe_device(devices[size_t(chosen)], 0).type))) {
      chosen = int(i);
    }
  }
  if (options.device_index >= 0 && chosen < 0)
    throw std::runtime_error("no Vulkan device with index " + std::to_string(options.device_index) + " (" +
                             std::to_string(count) + " present)");
  if (chosen < 0) throw std::runtime_error("no usable Vulkan device:" + reasons);
  physical_ = devices[size_t(chosen)];
  info_ = describe_device(physical_, uint32_t(chosen), &queue_family_);

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family_;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  const VkPhysicalDeviceFeatures features = vulkan_required_features();
  // Timeline semaphores where the device has them: an engine sampling the page images waits on one.
  VkPhysicalDeviceVulkan12Features supported12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 supported{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  supported.pNext = &supported12;
  vkGetPhysicalDeviceFeatures2(physical_, &supported);
  VkPhysicalDeviceVulkan12Features enabled12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  enabled12.timelineSemaphore = supported12.timelineSemaphore;
  VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  device_info.pNext = &enabled12;
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  device_info.pEnabledFeatures = &features;
  {
    const DriverAllocationScope driver;
    check(vkCreateDevice(physical_, &device_info, nullptr, &device_), "vkCreateDevice");
  }
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  enabled_features_ = features;
  timeline_semaphores_ = enabled12.timelineSemaphore == VK_TRUE;
}

void Context::adopt(const VulkanExternalDevice& external) {
  if (options_.validation || options_.on_validation_message || options_.device_index >= 0)
    throw std::invalid_argument("Vulkan backend: with an adopted device, validation and the device are the engine's "
                                "(leave validation, on_validation_message and device_index unset)");
  check_adopted_device(external);
  owns_device_ = false;
  instance_ = external.instance;
  physical_ = external.physical_device;
  device_ = external.device;
  queue_ = external.queue;
  queue_family_ = external.queue_family;
  enabled_features_ = external.enabled_features;
  timeline_semaphores_ = external.timeline_semaphore;
  uint32_t count = 0;
  std::vector<VkPhysicalDevice> devices;
  {
    const DriverAllocationScope driver;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    devices.resize(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  }
  const auto position = std::find(devices.begin(), devices.end(), physical_);
  info_ = describe_device(physical_, uint32_t(position - devices.begin()));  // its index on the engine's instance
}

// Properties, and what the context itself creates on either device: one command pool, buffer, fence.
void Context::create_submission_objects() {
  vkGetPhysicalDeviceProperties(physical_, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_properties_);
  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &family_count, families.data());
  timestamp_valid_bits_ = families[queue_family_].timestampValidBits;
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = queue_family_;
  check(vkCreateCommandPool(device_, &pool_info, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(device_, &alloc, &cmd_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkCreateFence(device_, &fence_info, nullptr, &fence_), "vkCreateFence");
}

Context::~Context() { cleanup(); }

// Every submission was waited for, so nothing of ours is in flight; an adopted device may run the
// engine's work, which vkDeviceWaitIdle would wait for (and which needs its queues synchronised).
void Context::cleanup() {
  // A submission that timed out may still run: destroying its device (or waiting for it) blocks
  // forever on a CPU driver and faults on a GPU, so a hung device and its instance are leaked, and
  // so is what the instance's debug messenger calls.
  if (hung_) {
    (void)messages_.release();
    return;
  }
  if (device_) {
    if (owns_device_ && !lost_) vkDeviceWaitIdle(device_);
    small_staging_ = Buffer{};
    deferred_staging_ = Buffer{};
    pending_.clear();
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    fence_ = VK_NULL_HANDLE, pool_ = VK_NULL_HANDLE;
    if (owns_device_) vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (!owns_device_) return;
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  instance_ = VK_NULL_HANDLE;
}

uint32_t Context::find_memory_type(uint32_t bits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const {
  for (int pass = 0; pass < 2; ++pass)
    for (uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
      const VkMemoryPropertyFlags flags = memory_properties_.memoryTypes[i].propertyFlags;
      const VkMemoryPropertyFlags want = pass == 0 ? (required | preferred) : required;
      if ((bits & (1u << i)) && (flags & want) == want) return i;
    }
  throw std::runtime_error("Vulkan: no suitable memory type");
}

VkDeviceMemory Context::allocate_device_local(const VkMemoryRequirements& requirements, const char* what) {
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = requirements.size;
  alloc.memoryTypeIndex = find_memory_type(requirements.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  check(vkAllocateMemory(device_, &alloc, nullptr, &memory), what);
  return memory;
}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this == &other) return *this;
  release();
  owner_ = std::exchange(other.owner_, nullptr);
  buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
  memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
  size_ = std::exchange(other.size_, 0);
  mapped_ = std::exchange(other.mapped_, nullptr);
  return *this;
}

void Buffer::release() {
  if (owner_) owner_->destroy(*this);
}

Buffer Context::create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible) {
  Buffer b;
  b.size_ = std::max<VkDeviceSize>(size, 16);
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = b.size_;
  info.usage = usage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(device_, &info, nullptr, &b.buffer_), "vkCreateBuffer");
  b.owner_ = this;  // from here on, the Buffer frees what it holds, also when a step below throws
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer_, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex =
      host_visible ? find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                      VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                   : find_memory_type(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(vkAllocateMemory(device_, &alloc, nullptr, &b.memory_), ("allocating a buffer of " + std::to_string(req.size) + " bytes").c_str());
  check(vkBindBufferMemory(device_, b.buffer_, b.memory_, 0), "vkBindBufferMemory");
  if (host_visible) check(vkMapMemory(device_, b.memory_, 0, VK_WHOLE_SIZE, 0, &b.mapped_), "vkMapMemory");
  return b;
}

Buffer Context::create_storage_buffer(VkDeviceSize size, VkBufferUsageFlags extra_usage) {
  const VkDeviceSize limit = properties_.limits.maxStorageBufferRange;
  if (size > limit)
    throw std::runtime_error("Vulkan backend: a buffer of " + std::to_string(size) + " bytes exceeds this device's " +
                             "maxStorageBufferRange (" + std::to_string(limit) + "); use fewer paths or texels per bake");
  return create_buffer(size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | extra_usage, false);
}

void Context::destroy(Buffer& b) {
  if (!hung_) {  // a running submission may still read it (cleanup)
    if (b.buffer_) vkDestroyBuffer(device_, b.buffer_, nullptr);
    if (b.memory_) vkFreeMemory(device_, b.memory_, nullptr);
  }
  b.owner_ = nullptr, b.buffer_ = VK_NULL_HANDLE, b.memory_ = VK_NULL_HANDLE, b.size_ = 0, b.mapped_ = nullptr;
}

VkCommandBuffer Context::begin() {
  if (lost_) throw VulkanDeviceFailure("Vulkan device failed earlier; create a new integrator");
  check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd_, &info), "vkBeginCommandBuffer");
  pending_recorded_ = 0;
  if (!pending_.empty()) {
    for (const auto& record : pending_) record(cmd_);
    pending_recorded_ = pending_.size();
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
  }
  return cmd_;
}

void Context::record_at_next_submission(std::function<void(VkCommandBuffer)> record) {
  if (lost_) throw VulkanDeviceFailure("Vulkan device failed earlier; create a new integrator");
  pending_.push_back(std::move(record));
}

void Context::upload_at_next_submission(const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset) {
  if (offset + size > dst.size()) throw std::logic_error("Context::upload_at_next_submission: past the end of the buffer");
  write_ranges_at_next_submission({RangeWrite{&dst, {{offset, size}}, [data, size](char* staging) { std::memcpy(staging, data, size_t(size)); }}});
}

void Context::write_ranges_at_next_submission(const std::vector<RangeWrite>& writes) {
  std::vector<std::vector<VkBufferCopy>> regions;
  std::vector<VkDeviceSize> start;
  const VkDeviceSize first = (deferred_bytes_ + 15) & ~VkDeviceSize(15);
  const VkDeviceSize end = packed_write_regions(writes, first, regions, start);
  if (end == first) return;
  if (!deferred_staging_.handle() || deferred_staging_.size() < end) {
    // Grown by doubling; the bytes already staged move along (nothing on the device reads them
    // yet: they are copied only at the next submission, and every submission is waited for).
    VkDeviceSize bytes = std::max<VkDeviceSize>(64 * 1024, deferred_staging_.size());
    while (bytes < end) bytes *= 2;
    Buffer larger = create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    if (deferred_bytes_ > 0) std::memcpy(larger.mapped(), deferred_staging_.mapped(), size_t(deferred_bytes_));
    deferred_staging_ = std::move(larger);
  }
  deferred_bytes_ = end;  // before the fills: a write that throws leaves the earlier ones' bytes in place
  for (size_t w = 0; w < writes.size(); ++w) {
    if (regions[w].empty()) continue;
    writes[w].write(static_cast<char*>(deferred_staging_.mapped()) + start[w]);
    record_at_next_submission([this, dst = writes[w].dst, copies = std::move(regions[w])](VkCommandBuffer cmd) {
      vkCmdCopyBuffer(cmd, deferred_staging_.handle(), dst->handle(), uint32_t(copies.size()), copies.data());
    });
  }
}

void Context::reserve_staging(VkDeviceSize bytes) {
  bytes = std::min(bytes, kReusedStagingLimit);
  if (!small_staging_busy_ && small_staging_.size() < bytes) {
    small_staging_ = Buffer{};
    small_staging_ = create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  }
  if (!small_staging_busy_ && small_staging_.mapped()) std::memset(small_staging_.mapped(), 0, size_t(small_staging_.size()));
  if (deferred_staging_.size() < bytes) {
    Buffer larger = create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    if (deferred_bytes_ > 0) std::memcpy(larger.mapped(), deferred_staging_.mapped(), size_t(deferred_bytes_));
    deferred_staging_ = std::move(larger);
  }
  // Past the bytes already staged for the next submission.
  std::memset(static_cast<char*>(deferred_staging_.mapped()) + deferred_bytes_, 0, size_t(deferred_staging_.size() - deferred_bytes_));
}

void Context::submit_and_wait(VkCommandBuffer cmd, double timeout_seconds) {
  submit_and_wait(cmd, timeout_seconds, VK_NULL_HANDLE, 0);
}

void Context::submit_and_wait(VkCommandBuffer cmd, VkSemaphore signal, uint64_t value) {
  submit_and_wait(cmd, 0, signal, value);
  VkSemaphoreWaitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wait.semaphoreCount = 1;
  wait.pSemaphores = &signal;
  wait.pValues = &value;
  const VkResult r = vkWaitSemaphores(device_, &wait, uint64_t(std::max(0.001, options_.fence_timeout_seconds) * 1e9));
  if (r == VK_TIMEOUT) {
    hung_ = true;
    fail("Vulkan timeline semaphore did not reach its value within the fence timeout");
  }
  if (r == VK_ERROR_DEVICE_LOST) fail("Vulkan device lost (vkWaitSemaphores)");
  check(r, "vkWaitSemaphores");
}

void Context::submit_and_wait(VkCommandBuffer cmd, double timeout_seconds, VkSemaphore signal, uint64_t value) {
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  if (signal) {
    timeline.signalSemaphoreValueCount = 1;
    timeline.pSignalSemaphoreValues = &value;
    submit.pNext = &timeline;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &signal;
  }
  check(vkResetFences(device_, 1, &fence_), "vkResetFences");
  VkResult r = vkQueueSubmit(queue_, 1, &submit, fence_);
  if (r == VK_ERROR_DEVICE_LOST) fail("Vulkan device lost (vkQueueSubmit)");
  check(r, "vkQueueSubmit");
  const double limit = timeout_seconds > 0 ? timeout_seconds : std::max(0.001, options_.fence_timeout_seconds);
  const auto waiting = std::chrono::steady_clock::now();
  r = vkWaitForFences(device_, 1, &fence_, VK_TRUE, uint64_t(limit * 1e9));
  ++waits_.submissions;
  waits_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - waiting).count();
  if (r == VK_TIMEOUT) {
    hung_ = true;  // the submission may still run: never reuse, wait for or destroy this device
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%g", limit);
    fail(std::string("Vulkan submission did not finish within ") + seconds +
         " s (GPU hang or dispatch too large; lower max_paths / iterations_per_submit)");
  }
  if (r == VK_ERROR_DEVICE_LOST) fail("Vulkan device lost (vkWaitForFences)");
  check(r, "vkWaitForFences");
  // What was recorded at the start of this submission has run.
  pending_.erase(pending_.begin(), pending_.begin() + std::ptrdiff_t(pending_recorded_));
  pending_recorded_ = 0;
  if (pending_.empty()) deferred_bytes_ = 0;
}

void Context::fail(const std::string& message) {
  lost_ = true;
  throw VulkanDeviceFailure(message);
}

// Marks the reused staging buffer busy for one transfer's scope.
struct StagingLease {
  bool& busy;
  bool leased;
  ~StagingLease() {
    if (leased) busy = false;
  }
};

const Buffer& Context::staging_for(VkDeviceSize size, Buffer& own, bool& leased, const Buffer* given) {
  leased = false;
  if (given && given->mapped() && given->size() >= size) return *given;
  if (size <= kReusedStagingLimit && !small_staging_busy_) {
    if (!small_staging_.handle() || small_staging_.size() < size) {
      // Grown to the next power of two: a moved instance's edit writes a few megabytes each time, and
      // a new host-visible buffer per edit costs its allocation and page faults (pinned on GPUs).
      VkDeviceSize bytes = kSmallStagingBytes;
      while (bytes < size) bytes *= 2;
      small_staging_ = Buffer{};
      small_staging_ = create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    }
    small_staging_busy_ = leased = true;
    return small_staging_;
  }
  own = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  return own;
}

void Context::keep_staging(Buffer& kept, VkDeviceSize bytes) {
  if (bytes > 0 && kept.size() < bytes)
    kept = create_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
}

void Context::upload(const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset) {
  if (size == 0) return;
  Buffer own;
  bool leased = false;
  const Buffer& staging = staging_for(size, own, leased);
  StagingLease lease{small_staging_busy_, leased};
  std::memcpy(staging.mapped(), data, size_t(size));
  VkCommandBuffer cmd = begin();
  VkBufferCopy region{0, offset, size};
  vkCmdCopyBuffer(cmd, staging.handle(), dst.handle(), 1, &region);
  submit_and_wait(cmd);
}

Context::RangeWrite Context::RangeWrite::whole(const Buffer& dst, const void* data, size_t bytes) {
  RangeWrite w;
  w.dst = &dst;
  if (bytes > 0) w.ranges.push_back({0, bytes});
  w.write = [data, bytes](char* staging) { std::memcpy(staging, data, bytes); };
  return w;
}

Context::RangeWrite Context::RangeWrite::mirrored(const Buffer& dst, const void* mirror, std::vector<ByteRange> ranges) {
  RangeWrite w;
  w.dst = &dst;
  w.ranges = std::move(ranges);
  w.write = [mirror, ranges = w.ranges](char* staging) {
    for (const ByteRange& r : ranges) {
      std::memcpy(staging, static_cast<const char*>(mirror) + r.offset, size_t(r.size));
      staging += r.size;
    }
  };
  return w;
}

void Context::upload_ranges(const Buffer& dst, const void* data, const std::vector<ByteRange>& ranges) {
  write_ranges({RangeWrite::mirrored(dst, data, ranges)});
}

void Context::write_ranges(const Buffer& dst, const std::vector<ByteRange>& ranges, const std::function<void(char*)>& write,
                           const Buffer* staging) {
  write_ranges({RangeWrite{&dst, ranges, write}}, staging);
}

void Context::write_ranges(const std::vector<RangeWrite>& writes, const Buffer* given_staging) {
  std::vector<std::vector<VkBufferCopy>> regions;
  std::vector<VkDeviceSize> start;
  const VkDeviceSize total = packed_write_regions(writes, 0, regions, start);
  if (total == 0) return;
  Buffer own;
  bool leased = false;
  const Buffer& staging = staging_for(total, own, leased, given_staging);
  StagingLease lease{small_staging_busy_, leased};
  VkCommandBuffer cmd = begin();
  for (size_t w = 0; w < writes.size(); ++w) {
    if (regions[w].empty()) continue;
    writes[w].write(static_cast<char*>(staging.mapped()) + start[w]);
    vkCmdCopyBuffer(cmd, staging.handle(), writes[w].dst->handle(), uint32_t(regions[w].size()), regions[w].data());
  }
  submit_and_wait(cmd);
}

void Context::download(const Buffer& src, void* data, VkDeviceSize size, VkDeviceSize offset) {
  read_back_ranges(src, {{offset, size}}, [&](const char* mapped) { std::memcpy(data, mapped, size_t(size)); });
}

void Context::read_back_ranges(const Buffer& src, const std::vector<ByteRange>& ranges, const std::function<void(const char*)>& read,
                               const Buffer* staging) {
  VkDeviceSize packed = 0;
  const std::vector<VkBufferCopy> regions = staging_regions(ranges, /*from_staging=*/false, packed);
  if (packed == 0) return;
  Buffer own;
  bool leased = false;
  const Buffer& through = staging_for(packed, own, leased, staging);
  StagingLease lease{small_staging_busy_, leased};
  VkCommandBuffer cmd = begin();
  vkCmdCopyBuffer(cmd, src.handle(), through.handle(), uint32_t(regions.size()), regions.data());
  submit_and_wait(cmd);
  read(static_cast<const char*>(through.mapped()));
}

}  // namespace exitance::vulkan

namespace exitance {

std::vector<VulkanDeviceInfo> enumerate_vulkan_devices() {
  std::vector<VulkanDeviceInfo> result;
  VkInstance instance = VK_NULL_HANDLE;
  try {
    instance = vulkan::create_instance(false, nullptr);
  } catch (const std::exception&) {
    return result;
  }
  uint32_t count = 0;
  std::vector<VkPhysicalDevice> devices;
  {
    const vulkan::DriverAllocationScope driver;
    vkEnumeratePhysicalDevices(instance, &count, nullptr);
    devices.resize(count);
    vkEnumeratePhysicalDevices(instance, &count, devices.data());
  }
  for (uint32_t i = 0; i < count; ++i) result.push_back(vulkan::describe_device(devices[i], i));
  vkDestroyInstance(instance, nullptr);
  return result;
}

const char* to_string(VulkanDeviceType type) {
  switch (type) {
    case VulkanDeviceType::Discrete: return "discrete";
    case VulkanDeviceType::Integrated: return "integrated";
    case VulkanDeviceType::Virtual: return "virtual";
    case VulkanDeviceType::Cpu: return "cpu";
    default: return "other";
  }
}

}  // namespace exitance
