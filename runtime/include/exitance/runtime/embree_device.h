// Every Embree device in the project is made here.
#pragma once
#include <embree3/rtcore.h>

namespace exitance {

// A new Embree device (never null: throws std::runtime_error). Its config string is the
// environment variable EXITANCE_EMBREE_CONFIG when set (e.g. "isa=sse4.2", "verbose=1"), otherwise
// Embree's defaults, so tests can pin the kernels Embree would otherwise pick for the CPU.
RTCDevice new_embree_device();

}  // namespace exitance
