// The Vulkan integrator as the cross-check tests use it: validation layer on, every validation
// message (teardown leaks included) a test failure, and no Vulkan device a skip, not a failure.
#pragma once
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance::testing {

class VulkanBackend {
 public:
  // `skip_reason` is set (and the integrator left empty) when there is no usable Vulkan device.
  VulkanBackend(const Scene& scene, std::string& skip_reason, uint32_t max_paths = 0)
      : VulkanBackend(make_lighting_scene(scene), skip_reason, with_max_paths(max_paths)) {}
  // On a prepared (or edited) lighting scene, with `options` plus validation.
  VulkanBackend(std::shared_ptr<const LightingScene> scene, std::string& skip_reason, VulkanDeviceOptions options) {
    options.validation = true;
    options.on_validation_message = [messages = messages_](const std::string& m) { messages->push_back(m); };
    try {
      integrator_ = VulkanIntegrator::create(std::move(scene), options);
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      if (what.find("no Vulkan device") != std::string::npos || what.find("no usable Vulkan device") != std::string::npos)
        skip_reason = what;
      else
        throw;
    }
  }
  ~VulkanBackend() {
    integrator_.reset();  // teardown messages (leaks) are recorded too
    for (const std::string& m : *messages_) ADD_FAILURE() << m;
  }
  VulkanIntegrator* operator->() { return integrator_.get(); }

 private:
  static VulkanDeviceOptions with_max_paths(uint32_t max_paths) {
    VulkanDeviceOptions options;
    options.max_paths = max_paths;
    return options;
  }
  std::shared_ptr<std::vector<std::string>> messages_ = std::make_shared<std::vector<std::string>>();
  std::unique_ptr<VulkanIntegrator> integrator_;
};

}  // namespace exitance::testing

// Declares `name`, a VulkanBackend for `scene` (optional extra: max_paths), or skips the test.
#define CREATE_VULKAN_OR_SKIP(name, scene, ...)                                                     \
  std::string skip_reason_##name;                                                                   \
  ::exitance::testing::VulkanBackend name(scene, skip_reason_##name __VA_OPT__(, ) __VA_ARGS__);    \
  if (!skip_reason_##name.empty()) GTEST_SKIP() << skip_reason_##name
