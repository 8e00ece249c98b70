// The device buffers of one render of shaders/pathtrace.comp and its pipeline, for the Vulkan
// backend's integrators (vulkan/backend.cpp's path tracer, vulkan/sppm.cpp's photon mapping,
// vulkan/bdpt.cpp's bidirectional path tracing):
// the flat scene arrays uploaded, the accumulation and the counters.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/prepare.h"
#include "vulkan/backend.h"
#include "vulkan/context.h"
#include "vulkan/resources.h"

namespace pt {

// The device buffers of one render, indexed by PT_BINDING_*, and the host-visible buffer the
// accumulation and the counters are copied back through.
struct RenderBuffers {
  std::vector<Buffer> bound;
  uint32_t stackRows = 0;    // the traversal's stack for the uploaded tree (gpuStackRows)
  std::vector<bool> texels;  // by binding: read as texels (a uniform texel buffer)
  Buffer readback;
  vk::DeviceSize accumSize = 0;

  const Buffer& accum() const { return bound[PT_BINDING_ACCUM]; }
  const Buffer& counters() const { return bound[PT_BINDING_COUNTERS]; }
};

// Creates every buffer the shader binds and records the copies of the scene arrays from
// `staging` (filled here, kept alive by the caller until the commands have run).
RenderBuffers uploadScene(const VulkanContext& ctx, const SceneData& scene,
                          const vk::raii::CommandBuffer& cmd, Buffer& staging);

// What the integrators that sum exactly on the device (vulkan/sppm.cpp, vulkan/bdpt.cpp) start
// from: the device with 64-bit buffer atomics, a command buffer begun, and the scene's upload
// recorded into it (submitted with the caller's next commands).
struct ExactSumDeviceScene {
  ExactSumDeviceScene(const ContextOptions& options, const SceneData& scene);

  VulkanContext ctx;
  Commands commands;
  Buffer staging;
  RenderBuffers buffers;
};

// The statistics those integrators end with: samplesDone, the film's invalid samples, the
// validation errors and the wall time since callStart.
void finishExactSumStats(const ExactSumDeviceScene& device, const Film& film, int samplesDone,
                         std::chrono::steady_clock::time_point callStart, VulkanRenderStats& stats);

// shaders/pathtrace.comp compiled with `definitions` (pathtraceDefinitions and a variant's),
// binding the render's buffers as PT_BINDING_* and then `extra` from PT_BINDING_COUNT on.
ComputeProgram makePathtraceProgram(const VulkanContext& ctx, const std::string& definitions,
                                    const RenderBuffers& buffers,
                                    const std::vector<Binding>& extra = {});

}  // namespace pt
