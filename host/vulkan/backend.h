// The Vulkan backend: uploads the flat scene arrays and runs shaders/pathtrace.comp in
// passes (dispatches) of one or more samples per pixel, accumulating on the device and folding
// into the host film's double-precision sums. Light header: no Vulkan-Hpp.
#pragma once

#include <cstdint>
#include <string>

#include "image/image.h"
#include "render/prepare.h"
#include "render/render_options.h"
#include "vulkan/device_info.h"

namespace pt {

struct VulkanRenderOptions : RenderOptions {
  ContextOptions context;
  int samplesPerPass = 1;   // samples per pixel in one dispatch (see --samples-per-pass)
  int passesPerFlush = 16;  // passes accumulated in float on the device before a fold
  bool specialize = true;   // false: every effect compiled in (to measure what it saves)
  int debugPixelX = -1, debugPixelY = -1;  // print this pixel's paths (needs debugPrintf)
};

// RenderStats::seconds is the device time of the passes (timestamp queries, after a warm-up
// dispatch that compiles the shader); wallSeconds counts set-up and upload too.
struct VulkanRenderStats : RenderStats {
  uint32_t maxLoopIterations = 0;  // most loop iterations one invocation ran (lavapipe's cap)
  uint32_t validationErrors = 0;
  std::string device;
};

VulkanRenderStats renderVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                               Film& film);

}  // namespace pt
