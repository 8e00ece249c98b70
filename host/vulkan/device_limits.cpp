// The device's limits without the rest of the backend; see device_limits.h.
#include "vulkan/device_limits.h"

#include "common/check.h"
#include "vulkan/context.h"

namespace pt {

DeviceLimits queryDeviceLimits(const ContextOptions& options) {
  const VulkanContext ctx(options);
  return {ctx.limits.maxStorageBufferRange, ctx.limits.maxTexelBufferElements};
}

void checkEnvironmentTexels(const std::string& device, uint32_t limit, const std::string& file,
                            size_t texels) {
  if (texels <= limit) return;
  throw InputError(file + ": the environment image needs " + std::to_string(texels) +
                   " texels (its pixels and sampling tables), more than " + device +
                   "'s maxTexelBufferElements, " + std::to_string(limit));
}

}  // namespace pt
