// The Vulkan backend's light interface: device descriptions, context options and the
// no-device error, without vulkan_raii.hpp (which costs seconds to parse per file).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pt {

// No Vulkan loader, no driver, or no device fit for the renderer: the command line maps this
// to its own exit status (kExitNoDevice).
class NoDeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DeviceInfo {
  uint32_t index = 0;
  std::string name;
  std::string type;    // "discrete", "integrated", "virtual", "cpu", "other"
  std::string driver;  // driver name and version
  bool suitable = false;
  std::string whyNot;  // when not suitable
};

struct ContextOptions {
  std::string device;         // name substring or index; empty: discrete GPU, else the best
  bool validation = false;    // enable VK_LAYER_KHRONOS_validation, count its errors
  bool debugPrintf = false;   // route debugPrintfEXT through the validation layer to stderr
  bool int64Atomics = false;  // enable 64-bit integer buffer atomics (the sppm integrator's)
};

// Every physical device with whether the renderer can use it. Throws NoDeviceError when
// there is no Vulkan loader or driver.
std::vector<DeviceInfo> listVulkanDevices();

}  // namespace pt
