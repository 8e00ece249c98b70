// Ray queries on the device; see raycast.h.
#include "vulkan/raycast.h"

#include <cstring>

#include "common/check.h"
#include "raycast_spv.h"  // kRaycastSpv: shaders/raycast.comp
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
  const vk::DeviceSize sizes[] = {
      traversal.size() * sizeof(uint32_t), bvh.triangles.size() * sizeof(Triangle),
      queries.size() * sizeof(RayQuery), queries.size() * sizeof(RayResult)};
  const char* names[] = {"BVH node and triangle", "triangle", "ray query", "ray result"};
  const void* data[] = {traversal.data(), bvh.triangles.data(), queries.data()};
  // The nodes and the triangles are read as texels, as in the path tracer (shared_types.h).
  const bool texels[] = {true, true, false, false};
  for (int i = 0; i < 4; ++i) {
    checkRange(ctx, names[i], sizes[i]);
    if (texels[i]) checkTexelRange(ctx, names[i], sizes[i]);
  }
  // Host-visible buffers throughout: this is a test tool, not a hot path.
  std::vector<Buffer> buffers;
  std::vector<Binding> bound;
  for (int i = 0; i < 4; ++i) {
    const auto usage = texels[i] ? U::eUniformTexelBuffer : U::eStorageBuffer;
    buffers.push_back(makeBuffer(ctx, sizes[i], usage, /*hostVisible=*/true));
    if (texels[i]) makeTexelView(ctx, buffers[i]);
    if (i < 3) std::memcpy(buffers[i].mapped, data[i], sizes[i]);
  }
  for (int i = 0; i < 4; ++i) bound.push_back(Binding{&buffers[i], texels[i]});
  // The traversal stack sized for this tree, as in the path tracer.
  const uint32_t stackRows = gpuStackRows(gpu);
  const vk::SpecializationMapEntry stackEntry(PT_SPEC_STACK_ROWS, 0, sizeof(uint32_t));
  const vk::SpecializationInfo spec(1, &stackEntry, sizeof(stackRows), &stackRows);
  const ComputeProgram program =
      makeComputeProgram(ctx, kRaycastSpv, bound, sizeof(uint32_t), &spec);

  const uint64_t groups = (queries.size() + kRaycastWorkgroupSize - 1) / kRaycastWorkgroupSize;
  PT_CHECK(groups <= ctx.limits.maxComputeWorkGroupCount[0], "too many rays for one dispatch");
  const Commands commands(ctx);
  commands.begin();
  program.bind(commands.cmd);
  const uint32_t count = uint32_t(queries.size());
  commands.cmd.pushConstants<uint32_t>(*program.layout, vk::ShaderStageFlagBits::eCompute, 0,
                                       count);
  commands.cmd.dispatch(uint32_t(groups), 1, 1);
  barrier(commands.cmd, vk::PipelineStageFlagBits::eComputeShader, vk::AccessFlagBits::eShaderWrite,
          vk::PipelineStageFlagBits::eHost, vk::AccessFlagBits::eHostRead);
  commands.submitAndWait(ctx);

  std::memcpy(results.data(), buffers[3].mapped, sizes[3]);
  if (stats) {
    stats->validationErrors = ctx.validationErrors();
    stats->truncated = 0;
    for (const RayResult& r : results) stats->truncated += r.truncated;
  }
  return results;
}

}  // namespace pt
