// The device failed under a bake or refresh: a submission that did not finish within
// VulkanDeviceOptions::fence_timeout_seconds, a lost device, or a fault the kernels counted (a BVH
// traversal past its bounds, a work claim that did not advance, a wavefront that stopped making
// progress). The integrator that threw never touches that device again, and when a submission may
// still be running it destroys nothing on it and never waits for it (a wait could never return:
// CPU drivers have no watchdog). Tools exit with kDeviceFailureExitCode; the C API returns
// EXITANCE_RUNTIME_DEVICE_FAILED.
#pragma once
#include <stdexcept>
#include <string>

namespace exitance {

inline constexpr int kDeviceFailureExitCode = 3;

class VulkanDeviceFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace exitance
