// The Vulkan backend: uploads the flat scene arrays and runs shaders/pathtrace.comp in
// passes (dispatches) of one or more samples per pixel, accumulating on the device and folding
// into the host film's double-precision sums.
#pragma once

#include <functional>
#include <string>

#include "cpu/integrator.h"
#include "vulkan/context.h"

namespace pt {

struct VulkanRenderOptions {
  ContextOptions context;
  uint32_t firstSample = 0;
  int spp = 1;
  int samplesPerPass = 1;   // samples per pixel in one dispatch (see --samples-per-pass)
  int passesPerFlush = 16;  // passes accumulated in float on the device before a fold
  bool specialize = true;   // false: every effect compiled in (to measure what it saves)
  int debugPixelX = -1, debugPixelY = -1;  // print this pixel's paths (needs debugPrintf)
  std::function<void(double)> progress;
};

struct VulkanRenderStats : RenderStats {
  double deviceSeconds = 0.0;     // timestamp queries around the dispatches, after a warm-up
  uint64_t truncatedSamples = 0;  // paths given up at the shader's loop budget
  uint32_t maxLoopIterations = 0;
  uint32_t validationErrors = 0;
  std::string device;
};

VulkanRenderStats renderVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                               Film& film);

}  // namespace pt
