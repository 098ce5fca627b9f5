// libexitance_runtime.so: the runtime library's exported surface is relight.h and the headers it
// reaches (Integrator, LightingScene, VulkanIntegrator); this unit only anchors the shared object.
#include "exitance/runtime/relight/relight.h"
