// Ray queries on the device; see raycast.h.
#include "vulkan/raycast.h"

#include <cstring>

#include "common/check.h"
#include "vulkan/glsl_compiler.h"
#include "vulkan/gpu_bvh.h"
#include "vulkan/resources.h"

namespace pt {

std::vector<RayResult> traceRaysVulkan(const Bvh& bvh, const std::vector<RayQuery>& queries,
                                       const ContextOptions& options, RaycastStats* stats) {
  std::vector<RayResult> results(queries.size());
  if (queries.empty()) return results;
  VulkanContext ctx(options);
  const GpuBvh gpu = buildGpuBvh(bvh);
  const std::vector<uint32_t> traversal = gpuTraversalTexels(gpu, bvh.triangles);
  using U = vk::BufferUsageFlagBits;
  using S = vk::PipelineStageFlagBits;
  using A = vk::AccessFlagBits;
  // The nodes and the triangles are read as texels, as in the path tracer (shared_types.h);
  // device-local buffers as there, so that a discrete GPU reads them from its own memory.
  const Upload uploads[] = {
      {"BVH node and triangle", traversal.data(), traversal.size() * sizeof(uint32_t), true},
      {"triangle", bvh.triangles.data(), bvh.triangles.size() * sizeof(Triangle), true},
      {"ray query", queries.data(), queries.size() * sizeof(RayQuery), false},
  };
  const vk::DeviceSize resultSize = queries.size() * sizeof(RayResult);
  checkUploads(ctx, uploads);
  checkRange(ctx, "ray result", resultSize);

  const Commands commands(ctx);
  commands.begin();
  Buffer staging;
  std::vector<Buffer> buffers = recordUploads(ctx, commands.cmd, uploads, staging);
  buffers.push_back(makeBuffer(ctx, resultSize, U::eStorageBuffer | U::eTransferSrc, false));
  const Buffer readback = makeBuffer(ctx, resultSize, U::eTransferDst, true);
  std::vector<Binding> bound;
  for (size_t i = 0; i < buffers.size(); ++i) {
    bound.push_back(Binding{&buffers[i], i < std::size(uploads) && uploads[i].texels});
  }
  // The traversal stack sized for this tree, as in the path tracer.
  const uint32_t stackRows = gpuStackRows(gpu);
  const vk::SpecializationMapEntry stackEntry(PT_SPEC_STACK_ROWS, 0, sizeof(uint32_t));
  const vk::SpecializationInfo spec(1, &stackEntry, sizeof(stackRows), &stackRows);
  const ComputeProgram program =
      makeComputeProgram(ctx, compileShader("raycast.comp", ""), bound, sizeof(uint32_t), &spec);

  const uint64_t groups = (queries.size() + kRaycastWorkgroupSize - 1) / kRaycastWorkgroupSize;
  PT_CHECK(groups <= ctx.limits.maxComputeWorkGroupCount[0], "too many rays for one dispatch");
  barrier(commands.cmd, S::eTransfer, A::eTransferWrite, S::eComputeShader, A::eShaderRead);
  program.bind(commands.cmd);
  const uint32_t count = uint32_t(queries.size());
  commands.cmd.pushConstants<uint32_t>(*program.layout, vk::ShaderStageFlagBits::eCompute, 0,
                                       count);
  const DeviceTimer timer(ctx);
  timer.start(commands.cmd);
  commands.cmd.dispatch(uint32_t(groups), 1, 1);
  timer.stop(commands.cmd);
  barrier(commands.cmd, S::eComputeShader, A::eShaderWrite, S::eTransfer, A::eTransferRead);
  commands.cmd.copyBuffer(*buffers.back().buffer, *readback.buffer,
                          vk::BufferCopy(0, 0, resultSize));
  barrier(commands.cmd, S::eTransfer, A::eTransferWrite, S::eHost, A::eHostRead);
  commands.submitAndWait(ctx);

  std::memcpy(results.data(), readback.mapped, resultSize);
  if (stats) {
    stats->validationErrors = ctx.validationErrors();
    stats->deviceSeconds = timer.seconds();
    stats->truncated = 0;
    for (const RayResult& r : results) stats->truncated += r.truncated;
  }
  return results;
}

}  // namespace pt
