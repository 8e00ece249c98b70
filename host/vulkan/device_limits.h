// The device limits that decide whether a scene fits (storage and texel buffer sizes), and the
// environment image's check against them, without vulkan_raii.hpp (which costs seconds to
// parse per file): for code that asks what fits without recording commands.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "vulkan/device_info.h"

namespace pt {

struct DeviceLimits {
  uint64_t maxStorageBufferRange = 0;  // bytes
  uint32_t maxTexelBufferElements = 0;
};

// The limits of the device that `options` choose (as a render would choose it). Throws
// NoDeviceError where there is none.
DeviceLimits queryDeviceLimits(const ContextOptions& options);

// An environment image whose texels and sampling tables (`texels` of them) exceed the device's
// maxTexelBufferElements (`limit`) is refused in one line naming its file (InputError), before
// anything is uploaded.
void checkEnvironmentTexels(const std::string& device, uint32_t limit, const std::string& file,
                            size_t texels);

}  // namespace pt
