// The runtime's results on the device (exitance_runtime_vulkan.h), as an engine uses them: the test
// makes its own Vulkan instance (validation layer on, a messenger counting its errors) and device,
// the runtime adopts it, and the test copies the page images the runtime hands over to the host with
// its own commands on that device. They must equal read_page bit for bit (E/pi and the dilated
// gutter) and carry the coverage in A, at open (the baked lightmap) and after an edit and a refresh;
// the timeline semaphore reaches the value handed out. Bad calls are one-line errors. The bundle is
// baked at 16 samples per texel, so the runtime starts from its baked lightmap.
#include <gtest/gtest.h>
#include <unistd.h>
#include <vulkan/vulkan.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "exitance/runtime/exitance_runtime.h"
#include "exitance/runtime/exitance_runtime_vulkan.h"

namespace {

namespace fs = std::filesystem;

const fs::path& bundle() {
  static const fs::path path = [] {
    const fs::path dir = fs::temp_directory_path() / ("exitance-page-images-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string command = std::string(EXITANCE_BAKE) + " " + EXITANCE_SAMPLE_DIR + "/cornell_room.gltf -o " +
                                (dir / "cornell.bake").string() +
                                " --backend cpu --spp 16 --texel-density 4 --probes none --voxel-resolution none 2>/dev/null";
    if (std::system(command.c_str()) != 0) throw std::runtime_error("bake failed: " + command);
    return dir / "cornell.bake";
  }();
  return path;
}

VKAPI_ATTR VkBool32 VKAPI_CALL count_errors(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
                                            const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    ++*static_cast<int*>(user);
    ADD_FAILURE() << "validation: " << (data && data->pMessage ? data->pMessage : "");
  }
  return VK_FALSE;
}

// What an engine has: an instance with validation, a device with a graphics+compute queue, the
// features the runtime needs and timeline semaphores.
struct EngineDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkPhysicalDeviceFeatures features{};
  int validation_errors = 0;
  std::string skip;  // why there is none

  EngineDevice() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_2;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkDebugUtilsMessengerCreateInfoEXT messenger_info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messenger_info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    messenger_info.pfnUserCallback = count_errors;
    messenger_info.pUserData = &validation_errors;
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pNext = &messenger_info;
    info.pApplicationInfo = &app;
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = &extension;
    if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) {
      skip = "no Vulkan instance with VK_LAYER_KHRONOS_validation";
      instance = VK_NULL_HANDLE;
      return;
    }
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create) create(instance, &messenger_info, nullptr, &messenger);
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance, &count, devices.data());
    for (VkPhysicalDevice candidate : devices) {
      uint32_t families = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(candidate, &families, nullptr);
      std::vector<VkQueueFamilyProperties> properties(families);
      vkGetPhysicalDeviceQueueFamilyProperties(candidate, &families, properties.data());
      for (uint32_t f = 0; f < families && !physical; ++f)
        if ((properties[f].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) == (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
          physical = candidate, family = f;
    }
    if (!physical) {
      skip = "no Vulkan device with a graphics and compute queue";
      return;
    }
    VkPhysicalDeviceFeatures supported{};
    vkGetPhysicalDeviceFeatures(physical, &supported);
    if (!supported.shaderInt64 || !supported.shaderFloat64) {
      skip = "the device lacks shaderInt64 or shaderFloat64";
      return;
    }
    features.shaderInt64 = features.shaderFloat64 = VK_TRUE;
    VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    features12.timelineSemaphore = VK_TRUE;
    const float priority = 1;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    device_info.pNext = &features12;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.pEnabledFeatures = &features;
    if (vkCreateDevice(physical, &device_info, nullptr, &device) != VK_SUCCESS) {
      skip = "vkCreateDevice failed";
      device = VK_NULL_HANDLE;
      return;
    }
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~EngineDevice() {
    if (device) vkDestroyDevice(device, nullptr);
    if (messenger) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy) destroy(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
  }
  ExitanceRuntimeVulkanDevice handed_over() const {
    return {instance, physical, device, queue, family, VK_API_VERSION_1_2, features, 1};
  }

  // The image's RGBA floats, copied with the engine's own commands after waiting on the runtime's
  // semaphore (as a frame that samples it would).
  std::vector<float> copy_to_host(const ExitanceRuntimePageImage& image, const ExitanceRuntimeImagesReady& ready) {
    const VkDeviceSize bytes = VkDeviceSize(image.width) * image.height * 16;
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = bytes;
    buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer buffer;
    EXPECT_EQ(vkCreateBuffer(device, &buffer_info, nullptr, &buffer), VK_SUCCESS);
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device, buffer, &requirements);
    VkPhysicalDeviceMemoryProperties memory_properties;
    vkGetPhysicalDeviceMemoryProperties(physical, &memory_properties);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = requirements.size;
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    for (uint32_t i = 0; i < memory_properties.memoryTypeCount; ++i)
      if ((requirements.memoryTypeBits & (1u << i)) && (memory_properties.memoryTypes[i].propertyFlags & host) == host) {
        alloc.memoryTypeIndex = i;
        break;
      }
    VkDeviceMemory memory;
    EXPECT_EQ(vkAllocateMemory(device, &alloc, nullptr, &memory), VK_SUCCESS);
    vkBindBufferMemory(device, buffer, memory, 0);
    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.queueFamilyIndex = family;
    VkCommandPool pool;
    vkCreateCommandPool(device, &pool_info, nullptr, &pool);
    VkCommandBufferAllocateInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cmd_info.commandPool = pool;
    cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cmd_info.commandBufferCount = 1;
    VkCommandBuffer cmd;
    vkAllocateCommandBuffers(device, &cmd_info, &cmd);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(cmd, &begin);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {image.width, image.height, 1};
    vkCmdCopyImageToBuffer(cmd, image.image, image.layout, buffer, 1, &region);
    VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr, 0, nullptr);
    vkEndCommandBuffer(cmd);
    VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    timeline.waitSemaphoreValueCount = 1;
    timeline.pWaitSemaphoreValues = &ready.value;
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.pNext = &timeline;
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &ready.semaphore;
    submit.pWaitDstStageMask = &stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    vkCreateFence(device, &fence_info, nullptr, &fence);
    EXPECT_EQ(vkQueueSubmit(queue, 1, &submit, fence), VK_SUCCESS);
    EXPECT_EQ(vkWaitForFences(device, 1, &fence, VK_TRUE, 20'000'000'000ull), VK_SUCCESS);  // bounded: 20 s
    std::vector<float> pixels(size_t(bytes / 4));
    void* mapped = nullptr;
    vkMapMemory(device, memory, 0, bytes, 0, &mapped);
    std::memcpy(pixels.data(), mapped, size_t(bytes));
    vkUnmapMemory(device, memory);
    vkDestroyFence(device, fence, nullptr);
    vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyBuffer(device, buffer, nullptr);
    vkFreeMemory(device, memory, nullptr);
    return pixels;
  }
};

// Every page's image equals read_page (RGB) and the coverage channel (A) bit for bit.
void expect_images_equal_read_page(ExitanceRuntime* rt, EngineDevice& engine, const char* when) {
  const uint32_t pages = exitance_runtime_page_count(rt);
  std::vector<ExitanceRuntimePageImage> images(pages);
  ExitanceRuntimeImagesReady ready{};
  ASSERT_EQ(exitance_runtime_publish_page_images(rt, images.data(), pages, &ready), EXITANCE_RUNTIME_OK)
      << exitance_runtime_last_error_message();
  ASSERT_NE(ready.semaphore, VkSemaphore(VK_NULL_HANDLE));
  EXPECT_EQ(ready.queue_family, engine.family);
  uint64_t reached = 0;
  ASSERT_EQ(vkGetSemaphoreCounterValue(engine.device, ready.semaphore, &reached), VK_SUCCESS);
  EXPECT_GE(reached, ready.value);
  size_t lit = 0;
  for (uint32_t p = 0; p < pages; ++p) {
    EXPECT_EQ(images[p].format, VK_FORMAT_R32G32B32A32_SFLOAT);
    EXPECT_EQ(images[p].layout, VK_IMAGE_LAYOUT_GENERAL);
    ExitanceRuntimePageInfo info{};
    ASSERT_EQ(exitance_runtime_page_info(rt, p, &info), EXITANCE_RUNTIME_OK);
    ASSERT_EQ(images[p].width, info.width);
    ASSERT_EQ(images[p].height, info.height);
    const size_t n = size_t(info.width) * info.height;
    std::vector<float> rgb(n * 3), coverage(n);
    ASSERT_EQ(exitance_runtime_read_page(rt, p, rgb.data(), info.width, info.height), EXITANCE_RUNTIME_OK);
    ASSERT_EQ(exitance_runtime_read_page_channel(rt, p, "A", coverage.data(), info.width, info.height), EXITANCE_RUNTIME_OK);
    const std::vector<float> pixels = engine.copy_to_host(images[p], ready);
    size_t differing = 0;
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) differing += pixels[i * 4 + size_t(c)] != rgb[i * 3 + size_t(c)];
      differing += pixels[i * 4 + 3] != coverage[i];
      lit += rgb[i * 3 + 1] > 0;
    }
    EXPECT_EQ(differing, 0u) << when << ": page " << p << " differs from read_page in " << differing << " values";
  }
  EXPECT_GT(lit, 0u) << when;
}

TEST(RuntimePageImages, EqualReadPageOnTheEnginesDevice) {
  EngineDevice engine;
  if (!engine.skip.empty()) GTEST_SKIP() << engine.skip;
  const ExitanceRuntimeVulkanDevice device = engine.handed_over();
  ExitanceRuntime* rt = nullptr;
  ASSERT_EQ(exitance_runtime_open_on_device(bundle().c_str(), nullptr, &device, &rt), EXITANCE_RUNTIME_OK)
      << exitance_runtime_last_error_message();
  ExitanceRuntimeVulkanDevice used{};
  ASSERT_EQ(exitance_runtime_vulkan_device(rt, &used), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(used.device, engine.device);
  EXPECT_EQ(used.queue, engine.queue);
  EXPECT_EQ(used.timeline_semaphore, 1);

  expect_images_equal_read_page(rt, engine, "at open (the baked lightmap)");
  ASSERT_EQ(exitance_runtime_apply_edits(rt, "{\"edits\": [{\"node\": \"TallBox\", \"translation\": [-0.2, 0, 0.4]}]}"),
            EXITANCE_RUNTIME_OK)
      << exitance_runtime_last_error_message();
  ExitanceRefreshReport report{};
  ASSERT_EQ(exitance_runtime_refresh(rt, 0, 8, &report), EXITANCE_RUNTIME_OK);
  expect_images_equal_read_page(rt, engine, "after a moved box and 8 samples");

  // With the indirect light filtered on the device: the images still equal read_page (both show the
  // filtered estimate), which is no longer what was shown unfiltered.
  ExitanceRuntimePageInfo info{};
  ASSERT_EQ(exitance_runtime_page_info(rt, 0, &info), EXITANCE_RUNTIME_OK);
  std::vector<float> unfiltered(size_t(info.width) * info.height * 3), filtered(unfiltered.size());
  ASSERT_EQ(exitance_runtime_read_page(rt, 0, unfiltered.data(), info.width, info.height), EXITANCE_RUNTIME_OK);
  ASSERT_EQ(exitance_runtime_set_denoise_radius(rt, 3), EXITANCE_RUNTIME_OK) << exitance_runtime_last_error_message();
  expect_images_equal_read_page(rt, engine, "filtered, radius 3");
  ASSERT_EQ(exitance_runtime_read_page(rt, 0, filtered.data(), info.width, info.height), EXITANCE_RUNTIME_OK);
  size_t changed = 0;
  for (size_t i = 0; i < filtered.size(); ++i) changed += filtered[i] != unfiltered[i];
  EXPECT_GT(changed, filtered.size() / 4) << "the filter changed too few values of page 0";
  for (int32_t bad : {-1, 17}) {
    EXPECT_EQ(exitance_runtime_set_denoise_radius(rt, bad), EXITANCE_RUNTIME_INVALID_ARGUMENT);
    const std::string message = exitance_runtime_last_error_message();
    EXPECT_NE(message.find("exitance_runtime_set_denoise_radius"), std::string::npos) << message;
    EXPECT_NE(message.find("is not 0 (off) to 16"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  EXPECT_EQ(exitance_runtime_set_denoise_radius(nullptr, 3), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  // The bad calls changed nothing: still filtered with radius 3; 0 turns it off again.
  std::vector<float> again(filtered.size());
  ASSERT_EQ(exitance_runtime_read_page(rt, 0, again.data(), info.width, info.height), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(again, filtered);
  ASSERT_EQ(exitance_runtime_set_denoise_radius(rt, 0), EXITANCE_RUNTIME_OK);
  ASSERT_EQ(exitance_runtime_read_page(rt, 0, again.data(), info.width, info.height), EXITANCE_RUNTIME_OK);
  EXPECT_EQ(again, unfiltered);

  // Bad calls: one line naming the call and the problem; the images stay as they were.
  const uint32_t pages = exitance_runtime_page_count(rt);
  std::vector<ExitanceRuntimePageImage> images(pages + 1);
  if (pages > 0) {
    EXPECT_EQ(exitance_runtime_publish_page_images(rt, images.data(), pages - 1, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
    const std::string message = exitance_runtime_last_error_message();
    EXPECT_NE(message.find("exitance_runtime_publish_page_images: image_count is"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  EXPECT_EQ(exitance_runtime_publish_page_images(rt, nullptr, pages, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(exitance_runtime_publish_page_images(nullptr, images.data(), pages, nullptr), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  exitance_runtime_release(rt);
  EXPECT_EQ(engine.validation_errors, 0);
}

TEST(RuntimePageImages, BadDevicesAreRefusedWithOneLine) {
  ExitanceRuntime* rt = reinterpret_cast<ExitanceRuntime*>(0x1);
  EXPECT_EQ(exitance_runtime_open_on_device(bundle().c_str(), nullptr, nullptr, &rt), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(rt, nullptr);
  EXPECT_EQ(std::string(exitance_runtime_last_error_message()), "exitance_runtime_open_on_device: device is NULL");
  ExitanceRuntimeVulkanDevice empty{};
  EXPECT_EQ(exitance_runtime_open_on_device(bundle().c_str(), nullptr, &empty, &rt), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_NE(std::string(exitance_runtime_last_error_message()).find("needs its instance"), std::string::npos)
      << exitance_runtime_last_error_message();
  EngineDevice engine;
  if (!engine.skip.empty()) GTEST_SKIP() << engine.skip;
  ExitanceRuntimeVulkanDevice no_float64 = engine.handed_over();
  no_float64.enabled_features.shaderFloat64 = VK_FALSE;
  EXPECT_EQ(exitance_runtime_open_on_device(bundle().c_str(), nullptr, &no_float64, &rt), EXITANCE_RUNTIME_NO_DEVICE);
  EXPECT_NE(std::string(exitance_runtime_last_error_message()).find("shaderFloat64"), std::string::npos)
      << exitance_runtime_last_error_message();
  const ExitanceRuntimeOptions with_index{0, 0, 0, 0};
  const ExitanceRuntimeVulkanDevice device = engine.handed_over();
  EXPECT_EQ(exitance_runtime_open_on_device(bundle().c_str(), &with_index, &device, &rt), EXITANCE_RUNTIME_INVALID_ARGUMENT);
  EXPECT_EQ(rt, nullptr);
  EXPECT_EQ(engine.validation_errors, 0);
}

}  // namespace
