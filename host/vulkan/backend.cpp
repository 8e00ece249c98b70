// Vulkan backend; see backend.h. Host code kept small: device-local buffers filled through
// one staging buffer, one descriptor set, one compute pipeline specialised to the scene's
// effect set, one command buffer re-recorded per batch of passes.
#include "vulkan/backend.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "common/check.h"
#include "pathtrace_debug_spv.h"  // kPathtraceDebugSpv: the same shader with debugPrintfEXT
#include "pathtrace_spv.h"        // kPathtraceSpv: SPIR-V compiled at build time

namespace pt {
namespace {

struct Buffer {
  vk::raii::Buffer buffer{nullptr};
  vk::raii::DeviceMemory memory{nullptr};
  vk::DeviceSize size = 0;
  void* mapped = nullptr;  // host-visible buffers only
};

uint32_t findMemoryType(const VulkanContext& ctx, uint32_t typeBits, vk::MemoryPropertyFlags want) {
  const auto props = ctx.physicalDevice.getMemoryProperties();
  for (uint32_t i = 0; i < props.memoryTypeCount; ++i) {
    if ((typeBits & (1u << i)) && (props.memoryTypes[i].propertyFlags & want) == want) return i;
  }
  throw vk::SystemError(vk::make_error_code(vk::Result::eErrorOutOfDeviceMemory),
                        "no memory type with the required properties");
}

Buffer makeBuffer(const VulkanContext& ctx, vk::DeviceSize size, vk::BufferUsageFlags usage,
                  bool hostVisible) {
  Buffer b;
  b.size = size;
  b.buffer = vk::raii::Buffer(ctx.device, vk::BufferCreateInfo({}, size, usage));
  const vk::MemoryRequirements req = b.buffer.getMemoryRequirements();
  const auto props = hostVisible ? vk::MemoryPropertyFlagBits::eHostVisible |
                                       vk::MemoryPropertyFlagBits::eHostCoherent
                                 : vk::MemoryPropertyFlagBits::eDeviceLocal;
  b.memory = vk::raii::DeviceMemory(
      ctx.device, vk::MemoryAllocateInfo(req.size, findMemoryType(ctx, req.memoryTypeBits, props)));
  b.buffer.bindMemory(*b.memory, 0);
  if (hostVisible) b.mapped = b.memory.mapMemory(0, size);
  return b;
}

// Storage buffers larger than the device allows would be silently cut short (lavapipe's
// maxStorageBufferRange is 128 MiB): refuse them with the numbers instead.
void checkRange(const VulkanContext& ctx, const char* what, vk::DeviceSize size) {
  if (size > ctx.limits.maxStorageBufferRange) {
    throw InputError("scene too large for " + ctx.info().name + ": the " + what + " buffer is " +
                     std::to_string(size >> 20) + " MiB, the device's maxStorageBufferRange is " +
                     std::to_string(ctx.limits.maxStorageBufferRange >> 20) + " MiB");
  }
}

// The effect set as specialization constants, in PT_SPEC_* id order.
struct SpecData {
  vk::Bool32 values[6];
};

vk::raii::Pipeline makePipeline(const VulkanContext& ctx, const vk::raii::PipelineLayout& layout,
                                const vk::raii::ShaderModule& module, const EffectSet& fx,
                                bool specialize) {
  SpecData spec{};
  spec.values[PT_SPEC_DIFFUSE] = !specialize || fx.diffuse;
  spec.values[PT_SPEC_MIRROR] = !specialize || fx.mirror;
  spec.values[PT_SPEC_NEE] = !specialize || fx.lightSampling;
  spec.values[PT_SPEC_BSDF_EMISSION] = !specialize || fx.bsdfEmission;
  spec.values[PT_SPEC_MIS] = !specialize || fx.mis;
  spec.values[PT_SPEC_RR] = !specialize || fx.russianRoulette;
  std::vector<vk::SpecializationMapEntry> entries;
  for (uint32_t id = 0; id < 6; ++id)
    entries.emplace_back(id, uint32_t(id * sizeof(vk::Bool32)), sizeof(vk::Bool32));
  const vk::SpecializationInfo specInfo(entries, vk::ArrayProxyNoTemporaries<const SpecData>(spec));
  const vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *module,
                                                "main", &specInfo);
  return vk::raii::Pipeline(ctx.device, nullptr, vk::ComputePipelineCreateInfo({}, stage, *layout));
}

// Makes writes of one stage visible to the reads/writes of the next.
void barrier(const vk::raii::CommandBuffer& cmd, vk::PipelineStageFlags src,
             vk::AccessFlags srcAccess, vk::PipelineStageFlags dst, vk::AccessFlags dstAccess) {
  const vk::MemoryBarrier mb(srcAccess, dstAccess);
  cmd.pipelineBarrier(src, dst, {}, mb, {}, {});
}

}  // namespace

VulkanRenderStats renderVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                               Film& film) {
  const auto start = std::chrono::steady_clock::now();
  const Camera& cam = scene.params.camera;
  PT_CHECK(film.width == int(cam.width) && film.height == int(cam.height));
  VulkanContext ctx(options.context);
  const bool debugPrintf = options.context.debugPrintf;

  // ---- Buffers: the flat scene arrays, the accumulation and the counters -------------------
  using U = vk::BufferUsageFlagBits;
  const size_t pixels = size_t(cam.width) * cam.height;
  // An empty emitter table still needs a valid binding: one zeroed entry the shader never reads.
  const std::vector<Emitter> emitters =
      scene.emitters.empty() ? std::vector<Emitter>{Emitter{}} : scene.emitters;
  struct Upload {
    const char* what;
    const void* data;
    vk::DeviceSize size;
  };
  const Upload uploads[] = {
      {"parameter", &scene.params, sizeof(RenderParams)},
      {"BVH node", scene.bvh.nodes.data(), scene.bvh.nodes.size() * sizeof(BvhNode)},
      {"triangle", scene.bvh.triangles.data(), scene.bvh.triangles.size() * sizeof(Triangle)},
      {"material", scene.materials.data(), scene.materials.size() * sizeof(Material)},
      {"emitter", emitters.data(), emitters.size() * sizeof(Emitter)},
  };
  const vk::DeviceSize accumSize = pixels * sizeof(AccumPixel);
  checkRange(ctx, "accumulation", accumSize);
  std::vector<Buffer> buffers;  // indexed by PT_BINDING_*
  vk::DeviceSize stagingSize = 0;
  for (const Upload& u : uploads) {
    checkRange(ctx, u.what, u.size);
    buffers.push_back(makeBuffer(ctx, u.size, U::eStorageBuffer | U::eTransferDst, false));
    stagingSize += u.size;
  }
  buffers.push_back(
      makeBuffer(ctx, accumSize, U::eStorageBuffer | U::eTransferSrc | U::eTransferDst, false));
  buffers.push_back(makeBuffer(ctx, sizeof(DeviceCounters),
                               U::eStorageBuffer | U::eTransferSrc | U::eTransferDst, false));
  Buffer& accum = buffers[PT_BINDING_ACCUM];
  Buffer& counters = buffers[PT_BINDING_COUNTERS];
  Buffer staging = makeBuffer(ctx, stagingSize, U::eTransferSrc, true);
  Buffer readback = makeBuffer(ctx, accumSize + sizeof(DeviceCounters), U::eTransferDst, true);

  // ---- Pipeline ---------------------------------------------------------------------------
  std::vector<vk::DescriptorSetLayoutBinding> bindings;
  for (uint32_t b = 0; b < PT_BINDING_COUNT; ++b)
    bindings.emplace_back(b, vk::DescriptorType::eStorageBuffer, 1,
                          vk::ShaderStageFlagBits::eCompute);
  const vk::raii::DescriptorSetLayout setLayout(ctx.device,
                                                vk::DescriptorSetLayoutCreateInfo({}, bindings));
  const vk::PushConstantRange pushRange(vk::ShaderStageFlagBits::eCompute, 0,
                                        sizeof(PassConstants));
  const vk::raii::PipelineLayout pipelineLayout(
      ctx.device, vk::PipelineLayoutCreateInfo({}, *setLayout, pushRange));
  const vk::raii::ShaderModule module =
      debugPrintf
          ? vk::raii::ShaderModule(
                ctx.device,
                vk::ShaderModuleCreateInfo({}, sizeof(kPathtraceDebugSpv), kPathtraceDebugSpv))
          : vk::raii::ShaderModule(
                ctx.device, vk::ShaderModuleCreateInfo({}, sizeof(kPathtraceSpv), kPathtraceSpv));
  const vk::raii::Pipeline pipeline =
      makePipeline(ctx, pipelineLayout, module, scene.effects, options.specialize);

  const vk::DescriptorPoolSize poolSize(vk::DescriptorType::eStorageBuffer, PT_BINDING_COUNT);
  const vk::raii::DescriptorPool pool(
      ctx.device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet,
                                               1, poolSize));
  vk::raii::DescriptorSets sets(ctx.device, vk::DescriptorSetAllocateInfo(*pool, *setLayout));
  const vk::raii::DescriptorSet& set = sets[0];
  std::vector<vk::DescriptorBufferInfo> infos;
  for (const Buffer& b : buffers) infos.emplace_back(*b.buffer, 0, b.size);
  std::vector<vk::WriteDescriptorSet> writes;
  for (uint32_t b = 0; b < PT_BINDING_COUNT; ++b)
    writes.emplace_back(*set, b, 0, vk::DescriptorType::eStorageBuffer, nullptr, infos[b]);
  ctx.device.updateDescriptorSets(writes, {});

  // ---- Commands ---------------------------------------------------------------------------
  const vk::raii::CommandPool commandPool(
      ctx.device, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                            ctx.queueFamily));
  vk::raii::CommandBuffers commandBuffers(
      ctx.device, vk::CommandBufferAllocateInfo(*commandPool, vk::CommandBufferLevel::ePrimary, 1));
  const vk::raii::CommandBuffer& cmd = commandBuffers[0];
  const vk::raii::Fence fence(ctx.device, vk::FenceCreateInfo());
  const vk::raii::QueryPool queries(ctx.device,
                                    vk::QueryPoolCreateInfo({}, vk::QueryType::eTimestamp, 2));
  auto submitAndWait = [&]() {
    cmd.end();
    ctx.queue.submit(vk::SubmitInfo({}, {}, *cmd), *fence);
    const vk::Result r = ctx.device.waitForFences(*fence, VK_TRUE, UINT64_MAX);
    PT_CHECK(r == vk::Result::eSuccess);
    ctx.device.resetFences(*fence);
  };
  using S = vk::PipelineStageFlagBits;
  using A = vk::AccessFlagBits;
  auto clearAccumulators = [&]() {
    cmd.fillBuffer(*accum.buffer, 0, VK_WHOLE_SIZE, 0);
    cmd.fillBuffer(*counters.buffer, 0, VK_WHOLE_SIZE, 0);
    barrier(cmd, S::eTransfer, A::eTransferWrite, S::eComputeShader,
            A::eShaderRead | A::eShaderWrite);
  };
  const uint32_t groupsX = (cam.width + kWorkgroupSize - 1) / kWorkgroupSize;
  const uint32_t groupsY = (cam.height + kWorkgroupSize - 1) / kWorkgroupSize;
  const uint32_t debugPixel = options.debugPixelX >= 0 ? uint32_t(options.debugPixelY) * cam.width +
                                                             uint32_t(options.debugPixelX)
                                                       : ~0u;
  auto dispatch = [&](uint32_t sampleIndex, uint32_t gx, uint32_t gy) {
    const PassConstants pc{sampleIndex, debugPixel, 0u, 0u};
    cmd.pushConstants<PassConstants>(*pipelineLayout, vk::ShaderStageFlagBits::eCompute, 0, pc);
    cmd.dispatch(gx, gy, 1);
    barrier(cmd, S::eComputeShader, A::eShaderWrite, S::eComputeShader | S::eTransfer,
            A::eShaderRead | A::eShaderWrite | A::eTransferRead);
  };

  // Upload the scene, then warm up: drivers (lavapipe especially) compile the shader at its
  // first dispatch, which must not count as render time. The warm-up's output is cleared.
  vk::DeviceSize offset = 0;
  for (size_t i = 0; i < std::size(uploads); ++i) {
    std::memcpy(static_cast<char*>(staging.mapped) + offset, uploads[i].data, uploads[i].size);
    offset += uploads[i].size;
  }
  cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
  offset = 0;
  for (size_t i = 0; i < std::size(uploads); ++i) {
    cmd.copyBuffer(*staging.buffer, *buffers[i].buffer, vk::BufferCopy(offset, 0, uploads[i].size));
    offset += uploads[i].size;
  }
  clearAccumulators();
  cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline);
  cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipelineLayout, 0, *set, {});
  dispatch(0u, 1u, 1u);
  barrier(cmd, S::eComputeShader, A::eShaderWrite, S::eTransfer, A::eTransferWrite);
  clearAccumulators();
  submitAndWait();

  // ---- Passes: one sample per pixel per dispatch, folded into the film every few passes ----
  VulkanRenderStats stats;
  stats.device = ctx.info().name;
  stats.threads = 0;
  const double tickSeconds = double(ctx.limits.timestampPeriod) * 1e-9;
  const int perFlush = std::max(1, options.passesPerFlush);
  for (int done = 0; done < options.spp;) {
    const int passes = std::min(perFlush, options.spp - done);
    cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
    cmd.resetQueryPool(*queries, 0, 2);
    cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline);
    cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipelineLayout, 0, *set, {});
    cmd.writeTimestamp(S::eTopOfPipe, *queries, 0);
    for (int p = 0; p < passes; ++p)
      dispatch(options.firstSample + uint32_t(done + p), groupsX, groupsY);
    cmd.writeTimestamp(S::eBottomOfPipe, *queries, 1);
    cmd.copyBuffer(*accum.buffer, *readback.buffer, vk::BufferCopy(0, 0, accumSize));
    cmd.copyBuffer(*counters.buffer, *readback.buffer,
                   vk::BufferCopy(0, accumSize, sizeof(DeviceCounters)));
    barrier(cmd, S::eTransfer, A::eTransferRead, S::eTransfer, A::eTransferWrite);
    clearAccumulators();
    submitAndWait();

    const auto [result, ticks] =
        queries.getResults<uint64_t>(0, 2, 2 * sizeof(uint64_t), sizeof(uint64_t),
                                     vk::QueryResultFlagBits::e64 | vk::QueryResultFlagBits::eWait);
    PT_CHECK(result == vk::Result::eSuccess);
    stats.deviceSeconds += double(ticks[1] - ticks[0]) * tickSeconds;

    // Fold the float sums into the double-precision film.
    const auto* px = static_cast<const AccumPixel*>(readback.mapped);
    for (size_t i = 0; i < pixels; ++i) {
      film.sum[i] += glm::dvec3(px[i].sum);
      film.sampleCount[i] += uint64_t(passes) - px[i].invalid;
      film.invalidCount[i] += px[i].invalid;
    }
    DeviceCounters c;
    std::memcpy(&c, static_cast<const char*>(readback.mapped) + accumSize, sizeof(c));
    stats.rays += uint64_t(c.raysHigh) << 32 | c.raysLow;
    stats.truncatedSamples += c.truncated;
    stats.maxLoopIterations = std::max(stats.maxLoopIterations, c.maxLoopIterations);
    done += passes;
    if (options.progress) options.progress(double(done) / double(options.spp));
  }
  stats.invalidSamples = film.totalInvalid();
  stats.validationErrors = ctx.validationErrors();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace pt
