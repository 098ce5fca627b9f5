#include "device_requirements.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace exitance::vulkan {
namespace {

VulkanDeviceType device_type(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return VulkanDeviceType::Discrete;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return VulkanDeviceType::Integrated;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return VulkanDeviceType::Virtual;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return VulkanDeviceType::Cpu;
    default: return VulkanDeviceType::Other;
  }
}

bool at_least_1_2(uint32_t version) {
  return VK_API_VERSION_MAJOR(version) > 1 || (VK_API_VERSION_MAJOR(version) == 1 && VK_API_VERSION_MINOR(version) >= 2);
}

std::vector<VkQueueFamilyProperties> queue_families(VkPhysicalDevice physical) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, families.data());
  return families;
}

}  // namespace

VulkanDeviceInfo describe_device(VkPhysicalDevice physical, uint32_t index, uint32_t* queue_family, uint32_t* subgroup_size) {
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
  const std::vector<VkQueueFamilyProperties> families = queue_families(physical);
  int family = -1;
  for (uint32_t i = 0; i < families.size() && family < 0; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) family = int(i);
  const VkSubgroupFeatureFlags needed =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
  if (!at_least_1_2(info.api_version)) info.missing_feature = "Vulkan 1.2";
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

int preference_rank(VulkanDeviceType t) {
  switch (t) {
    case VulkanDeviceType::Discrete: return 0;
    case VulkanDeviceType::Integrated: return 1;
    case VulkanDeviceType::Virtual: return 2;
    case VulkanDeviceType::Cpu: return 3;
    default: return 4;
  }
}

void check_adopted_device(const VulkanExternalDevice& external) {
  const std::string prefix = "Vulkan backend: the adopted device ";
  if (!external.instance || !external.physical_device || !external.device || !external.queue)
    throw std::invalid_argument(prefix + "needs its VkInstance, VkPhysicalDevice, VkDevice and VkQueue");
  if (!at_least_1_2(external.api_version))
    throw std::runtime_error(prefix + "belongs to an instance created for Vulkan " +
                             std::to_string(VK_API_VERSION_MAJOR(external.api_version)) + "." +
                             std::to_string(VK_API_VERSION_MINOR(external.api_version)) +
                             " (VkApplicationInfo::apiVersion); the kernels need Vulkan 1.2");
  const VulkanDeviceInfo info = describe_device(external.physical_device, 0);
  if (!info.usable) throw std::runtime_error(prefix + "(" + info.name + ") lacks " + info.missing_feature);
  const std::vector<VkQueueFamilyProperties> families = queue_families(external.physical_device);
  if (external.queue_family >= families.size() || !(families[external.queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT))
    throw std::runtime_error(prefix + "queue family " + std::to_string(external.queue_family) + " has no compute support");
  if (!external.enabled_features.shaderInt64)
    throw std::runtime_error(prefix + "was created without shaderInt64 (enable vulkan_required_features())");
  if (!external.enabled_features.shaderFloat64)
    throw std::runtime_error(prefix + "was created without shaderFloat64 (enable vulkan_required_features())");
}

}  // namespace exitance::vulkan

namespace exitance {

VkPhysicalDeviceFeatures vulkan_required_features() {
  VkPhysicalDeviceFeatures features{};
  features.shaderInt64 = VK_TRUE;
  features.shaderFloat64 = VK_TRUE;
  return features;
}

}  // namespace exitance
