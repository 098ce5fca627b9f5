// libexitance_runtime.so: the runtime library's exported surface is the C API
// (exitance/runtime/exitance_runtime.h) and the C++ headers it reaches (RefreshSession, relight.h,
// Integrator, LightingScene, VulkanIntegrator); this unit only anchors the shared object.
#include "exitance/runtime/exitance_runtime.h"
#include "exitance/runtime/relight/relight.h"
