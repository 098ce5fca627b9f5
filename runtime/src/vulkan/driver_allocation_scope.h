// Around the Vulkan calls that initialise drivers (instance creation, device enumeration, device
// creation): in sanitizer builds, allocations made there are not reported as leaks. Mesa's lavapipe
// keeps a one-time allocation from its first enumeration (a pthread_once in libvulkan_lvp.so) that
// LeakSanitizer reports from "<unknown module>", which no suppression file can name. Our own code
// allocates nothing inside these calls; everywhere else leaks still fail the sanitizer run.
#pragma once

#include "exitance/runtime/address_sanitizer.h"

#if defined(EXITANCE_ADDRESS_SANITIZER)
#include <sanitizer/lsan_interface.h>
#endif

namespace exitance::vulkan {

struct DriverAllocationScope {
#if defined(EXITANCE_ADDRESS_SANITIZER)
  DriverAllocationScope() { __lsan_disable(); }
  ~DriverAllocationScope() { __lsan_enable(); }
  DriverAllocationScope(const DriverAllocationScope&) = delete;
  DriverAllocationScope& operator=(const DriverAllocationScope&) = delete;
#endif
};

}  // namespace exitance::vulkan
