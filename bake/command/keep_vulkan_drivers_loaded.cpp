// Sanitizer builds only. LeakSanitizer reports allocations made by libraries that the Vulkan
// loader has already dlclose()d as "<unknown module>", which no suppression can match. Pinning
// the loader and Mesa's lavapipe for the life of the process lets their driver-internal leaks be
// attributed, and suppressed by name in tests/lsan.supp, while our own leaks still fail the run.
#include "exitance/runtime/address_sanitizer.h"

#if defined(EXITANCE_ADDRESS_SANITIZER)
#include <dlfcn.h>

#include <initializer_list>

namespace {

struct KeepVulkanDriversLoaded {
  KeepVulkanDriversLoaded() {
    for (const char* library : {"libvulkan.so.1", "libvulkan_lvp.so"}) dlopen(library, RTLD_NOW | RTLD_NODELETE);
  }
};

const KeepVulkanDriversLoaded keep_vulkan_drivers_loaded;

}  // namespace
#endif
