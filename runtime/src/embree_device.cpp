#include "exitance/runtime/embree_device.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace exitance {

RTCDevice new_embree_device() {
  const char* config = std::getenv("EXITANCE_EMBREE_CONFIG");
  RTCDevice device = rtcNewDevice(config);
  if (!device)
    throw std::runtime_error("Embree: cannot create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) +
                             (config ? ", EXITANCE_EMBREE_CONFIG=\"" + std::string(config) + "\")" : ")"));
  return device;
}

}  // namespace exitance
