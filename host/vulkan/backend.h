// The Vulkan backend: uploads the flat scene arrays and runs shaders/pathtrace.comp in
// passes (dispatches) of one or more samples per pixel, accumulating on the device in float
// and folding each batch of passes into the host film's exact sums. Light header: no
// Vulkan-Hpp.
#pragma once

#include <cstdint>
#include <string>

#include "image/film_state.h"
#include "image/image.h"
#include "render/prepare.h"
#include "render/render_options.h"
#include "vulkan/device_info.h"

namespace pt {

struct VulkanRenderOptions : RenderOptions {
  ContextOptions context;
  // Samples per pixel in one dispatch (see --samples-per-pass); 0: chosen as the render goes,
  // as many as keep a dispatch short (see renderVulkan). The image does not depend on it.
  int samplesPerPass = 0;
  int samplesPerFold = 16;  // samples summed in float on the device before a fold (a batch)
  bool specialize = true;   // false: every effect compiled in (to measure what it saves)
  int debugPixelX = -1, debugPixelY = -1;  // print this pixel's paths (needs debugPrintf)
  // A batch a previous render left open (from a film state): it must end at firstSample; its
  // float sums are uploaded and the batch continued, as if that render had not stopped.
  const OpenBatch* openBatch = nullptr;
  // Leave a last batch that ends before its full size open (VulkanRenderStats::open) rather
  // than fold it, so that a later render that continues to more samples sums it whole.
  bool keepOpenBatch = false;
};

// RenderStats::seconds is the device time of the passes (timestamp queries, after a warm-up
// dispatch that compiles the shader); wallSeconds counts set-up and upload too.
struct VulkanRenderStats : RenderStats {
  uint32_t maxLoopIterations = 0;  // most loop iterations one invocation ran (lavapipe's cap)
  uint32_t splitPhotonPasses = 0;  // sppm: photon passes run again split by hits (the cap)
  uint32_t validationErrors = 0;
  std::string device;
  // The samples of a batch not folded into the film: when stopped in the middle of a batch,
  // or with keepOpenBatch. The film holds [firstSample, open.first) then, open the rest.
  OpenBatch open;
};

VulkanRenderStats renderVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                               Film& film);

// What of `options` determines the image's bits beyond the scene's settings, for film state
// files: the batch size (samples per fold), specialisation, and a hash of the shader's SPIR-V.
KeyValues vulkanImageSettings(const VulkanRenderOptions& options);

// The preprocessor definitions pathtrace.comp is compiled with for the scene
// (vulkan/glsl_compiler.h): its effects (PT_FX_*, every one; all on without
// options.specialize) and the variant it takes (media, debug printing, or none of bsdf.h).
std::string pathtraceDefinitions(const SceneData& scene, const VulkanRenderOptions& options);

// Sample indices per batch (samplesPerFold): a render split where no batch is split sums to
// the bits of one render.
uint32_t vulkanBatchSize(const VulkanRenderOptions& options);

}  // namespace pt
