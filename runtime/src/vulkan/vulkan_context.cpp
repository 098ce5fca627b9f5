#include "vulkan_context.h"

#include <algorithm>
#include <cstring>
#include <mutex>

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
  const VkResult r = vkCreateInstance(&info, nullptr, &instance);
  if (r != VK_SUCCESS)
    throw std::runtime_error("no Vulkan device: cannot create a Vulkan instance (" + result_name(r) +
                             "; is a Vulkan driver such as mesa-vulkan-drivers installed?)");
  return instance;
}

VulkanDeviceType device_type(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return VulkanDeviceType::Discrete;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return VulkanDeviceType::Integrated;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return VulkanDeviceType::Virtual;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return VulkanDeviceType::Cpu;
    default: return VulkanDeviceType::Other;
  }
}

int type_rank(VulkanDeviceType t) {
  switch (t) {
    case VulkanDeviceType::Discrete: return 0;
    case VulkanDeviceType::Integrated: return 1;
    case VulkanDeviceType::Virtual: return 2;
    case VulkanDeviceType::Cpu: return 3;
    default: return 4;
  }
}

// What the shaders need: int64, fp64, subgroup basic/ballot/arithmetic in compute, a compute queue.
VulkanDeviceInfo describe(VkPhysicalDevice physical, uint32_t index, uint32_t* queue_family, uint32_t* subgroup_size) {
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(physical, &props);
  VkPhysicalDeviceFeatures features{};
  vkGetPhysicalDeviceFeatures(physical, &features);
  VulkanDeviceInfo info;
  info.index = index;
  info.name = props.properties.deviceName;
  info.type = device_type(props.properties.deviceType);
  info.api_version = props.properties.apiVersion;
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, families.data());
  int family = -1;
  for (uint32_t i = 0; i < count; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      family = int(i);
      break;
    }
  const VkSubgroupFeatureFlags needed =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
  if (VK_API_VERSION_MINOR(info.api_version) < 2 && VK_API_VERSION_MAJOR(info.api_version) == 1)
    info.missing_feature = "Vulkan 1.2";
  else if (family < 0) info.missing_feature = "a compute queue";
  else if (!features.shaderInt64) info.missing_feature = "shaderInt64";
  else if (!features.shaderFloat64) info.missing_feature = "shaderFloat64";
  else if ((subgroup.supportedOperations & needed) != needed || !(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT))
    info.missing_feature = "subgroup basic/ballot/arithmetic operations in compute shaders";
  info.usable = info.missing_feature.empty();
  if (queue_family) *queue_family = uint32_t(std::max(family, 0));
  if (subgroup_size) *subgroup_size = subgroup.subgroupSize;
  return info;
}

}  // namespace

Context::Context(const VulkanDeviceOptions& options) : options_(options), messages_(new Messages) {
  messages_->sink = options.on_validation_message;
  VkDebugUtilsMessengerCreateInfoEXT messenger = messenger_info(&messages_->sink);
  instance_ = create_instance(options.validation, &messenger);
  try {
    if (options.validation) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      if (create) check(create(instance_, &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    }
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());
    if (count == 0) throw std::runtime_error("no Vulkan device: the Vulkan loader found no physical device");
    int chosen = -1;
    std::string reasons;
    for (uint32_t i = 0; i < count; ++i) {
      const VulkanDeviceInfo d = describe(devices[i], i, nullptr, nullptr);
      if (!d.usable) reasons += " " + d.name + " lacks " + d.missing_feature + ";";
      if (options.device_index >= 0) {
        if (int(i) == options.device_index) {
          if (!d.usable) throw std::runtime_error("Vulkan device " + std::to_string(i) + " (" + d.name + ") lacks " + d.missing_feature);
          chosen = int(i);
        }
      } else if (d.usable && (chosen < 0 || type_rank(d.type) < type_rank(describe(devices[size_t(chosen)], 0, nullptr, nullptr).type))) {
        chosen = int(i);
      }
    }
    if (options.device_index >= 0 && chosen < 0)
      throw std::runtime_error("no Vulkan device with index " + std::to_string(options.device_index) + " (" +
                               std::to_string(count) + " present)");
    if (chosen < 0) throw std::runtime_error("no usable Vulkan device:" + reasons);
    physical_ = devices[size_t(chosen)];
    info_ = describe(physical_, uint32_t(chosen), &queue_family_, &subgroup_size_);
    vkGetPhysicalDeviceProperties(physical_, &properties_);
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_properties_);
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &family_count, families.data());
    timestamp_valid_bits_ = families[queue_family_].timestampValidBits;

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = queue_family_;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkPhysicalDeviceFeatures features{};
    features.shaderInt64 = VK_TRUE;
    features.shaderFloat64 = VK_TRUE;
    VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.pEnabledFeatures = &features;
    check(vkCreateDevice(physical_, &device_info, nullptr, &device_), "vkCreateDevice");
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
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
  } catch (...) {
    cleanup();
    throw;
  }
}

Context::~Context() { cleanup(); }

void Context::cleanup() {
  if (device_) {
    if (!lost_) vkDeviceWaitIdle(device_);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
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

Buffer Context::create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible) {
  Buffer b;
  b.size = std::max<VkDeviceSize>(size, 16);
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = b.size;
  info.usage = usage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(device_, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex =
      host_visible ? find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                      VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                   : find_memory_type(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &b.memory);
  if (r != VK_SUCCESS) {
    vkDestroyBuffer(device_, b.buffer, nullptr);
    check(r, ("allocating a buffer of " + std::to_string(req.size) + " bytes").c_str());
  }
  check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
  if (host_visible) check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  return b;
}

void Context::destroy(Buffer& b) {
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
  b = Buffer{};
}

VkCommandBuffer Context::begin() {
  if (lost_) throw std::runtime_error("Vulkan device was lost earlier; create a new integrator");
  check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd_, &info), "vkBeginCommandBuffer");
  return cmd_;
}

void Context::submit_and_wait(VkCommandBuffer cmd) {
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  check(vkResetFences(device_, 1, &fence_), "vkResetFences");
  VkResult r = vkQueueSubmit(queue_, 1, &submit, fence_);
  if (r == VK_ERROR_DEVICE_LOST) lost_ = true;
  check(r, "vkQueueSubmit");
  const uint64_t timeout_ns = uint64_t(std::max(0.001, options_.fence_timeout_seconds) * 1e9);
  r = vkWaitForFences(device_, 1, &fence_, VK_TRUE, timeout_ns);
  if (r == VK_TIMEOUT) {
    lost_ = true;  // the submission may still run: never reuse this device
    throw std::runtime_error("Vulkan submission did not finish within " + std::to_string(options_.fence_timeout_seconds) +
                             " s (GPU hang or dispatch too large; lower max_paths / iterations_per_submit)");
  }
  if (r == VK_ERROR_DEVICE_LOST) lost_ = true;
  check(r, "vkWaitForFences");
}

void Context::upload(const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset) {
  if (size == 0) return;
  Buffer staging = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  std::memcpy(staging.mapped, data, size_t(size));
  VkCommandBuffer cmd = begin();
  VkBufferCopy region{0, offset, size};
  vkCmdCopyBuffer(cmd, staging.buffer, dst.buffer, 1, &region);
  try {
    submit_and_wait(cmd);
  } catch (...) {
    destroy(staging);
    throw;
  }
  destroy(staging);
}

void Context::download(const Buffer& src, void* data, VkDeviceSize size, VkDeviceSize offset) {
  if (size == 0) return;
  Buffer staging = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  VkCommandBuffer cmd = begin();
  VkBufferCopy region{offset, 0, size};
  vkCmdCopyBuffer(cmd, src.buffer, staging.buffer, 1, &region);
  try {
    submit_and_wait(cmd);
  } catch (...) {
    destroy(staging);
    throw;
  }
  std::memcpy(data, staging.mapped, size_t(size));
  destroy(staging);
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
  vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance, &count, devices.data());
  for (uint32_t i = 0; i < count; ++i) result.push_back(vulkan::describe(devices[i], i, nullptr, nullptr));
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
