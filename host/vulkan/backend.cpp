// Vulkan backend; see backend.h. Host code kept small: device-local buffers filled through
// one staging buffer, one descriptor set, one compute pipeline specialised to the scene's
// effect set, one command buffer re-recorded per batch of passes.
#include "vulkan/backend.h"
#include "vulkan/resources.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "common/check.h"
#include "pathtrace_debug_spv.h"  // kPathtraceDebugSpv: the same shader with debugPrintfEXT
#include "pathtrace_spv.h"        // kPathtraceSpv: SPIR-V compiled at build time

namespace pt {
namespace {

// The effect set as specialization constants, in PT_SPEC_* id order: booleans (VkBool32)
// for the effects, the chosen value (or kSpecAtRunTime) for the two choices.
struct SpecData {
  uint32_t values[PT_SPEC_COUNT];
};

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

  // ---- Pipeline, specialised to the scene's effect set --------------------------------------
  const EffectSet& fx = scene.effects;
  const bool all = !options.specialize;
  const RenderParams& params = scene.params;
  const SpecData spec{{all || fx.diffuse, all || fx.mirror, all || fx.lightSampling,
                       all || fx.bsdfEmission, all || fx.mis, all || fx.russianRoulette,
                       all ? kSpecAtRunTime : params.fastIntersection,
                       all ? kSpecAtRunTime : params.samplerType}};
  static_assert(PT_SPEC_DIFFUSE == 0 && PT_SPEC_MIRROR == 1 && PT_SPEC_NEE == 2 &&
                PT_SPEC_BSDF_EMISSION == 3 && PT_SPEC_MIS == 4 && PT_SPEC_RR == 5 &&
                PT_SPEC_INTERSECTION == 6 && PT_SPEC_SAMPLER == 7 && PT_SPEC_COUNT == 8);
  std::vector<vk::SpecializationMapEntry> entries;
  for (uint32_t id = 0; id < PT_SPEC_COUNT; ++id) {
    entries.emplace_back(id, uint32_t(id * sizeof(uint32_t)), sizeof(uint32_t));
  }
  const vk::SpecializationInfo specInfo(entries, vk::ArrayProxyNoTemporaries<const SpecData>(spec));
  std::vector<const Buffer*> bound;
  for (const Buffer& b : buffers) bound.push_back(&b);
  const std::span<const uint32_t> spirv = debugPrintf
                                              ? std::span<const uint32_t>(kPathtraceDebugSpv)
                                              : std::span<const uint32_t>(kPathtraceSpv);
  const ComputeProgram program =
      makeComputeProgram(ctx, spirv, bound, sizeof(PassConstants), &specInfo);

  // ---- Commands ---------------------------------------------------------------------------
  const Commands commands(ctx);
  const vk::raii::CommandBuffer& cmd = commands.cmd;
  const vk::raii::QueryPool queries(ctx.device,
                                    vk::QueryPoolCreateInfo({}, vk::QueryType::eTimestamp, 2));
  auto submitAndWait = [&]() { commands.submitAndWait(ctx); };
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
  auto dispatch = [&](uint32_t sampleIndex, uint32_t sampleCount, uint32_t gx, uint32_t gy) {
    const PassConstants pc{sampleIndex, sampleCount, debugPixel, 0u};
    cmd.pushConstants<PassConstants>(*program.layout, vk::ShaderStageFlagBits::eCompute, 0, pc);
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
  commands.begin();
  offset = 0;
  for (size_t i = 0; i < std::size(uploads); ++i) {
    cmd.copyBuffer(*staging.buffer, *buffers[i].buffer, vk::BufferCopy(offset, 0, uploads[i].size));
    offset += uploads[i].size;
  }
  clearAccumulators();
  program.bind(cmd);
  dispatch(0u, 1u, 1u, 1u);
  barrier(cmd, S::eComputeShader, A::eShaderWrite, S::eTransfer, A::eTransferWrite);
  clearAccumulators();
  submitAndWait();

  // ---- Passes: samplesPerPass samples per pixel per dispatch, folded into the film after
  // every passesPerFlush dispatches -----------------------------------------------------------
  VulkanRenderStats stats;
  stats.device = ctx.info().name;
  stats.threads = 0;
  const double tickSeconds = double(ctx.limits.timestampPeriod) * 1e-9;
  const int perFlush = std::max(1, options.passesPerFlush);
  const int perPass = std::max(1, options.samplesPerPass);
  for (int done = 0; done < options.spp;) {
    commands.begin();
    cmd.resetQueryPool(*queries, 0, 2);
    program.bind(cmd);
    cmd.writeTimestamp(S::eTopOfPipe, *queries, 0);
    int samples = 0;  // per pixel, in this batch of passes
    for (int p = 0; p < perFlush && done + samples < options.spp; ++p) {
      const int count = std::min(perPass, options.spp - done - samples);
      dispatch(options.firstSample + uint32_t(done + samples), uint32_t(count), groupsX, groupsY);
      samples += count;
    }
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
      film.sampleCount[i] += uint64_t(samples) - px[i].invalid;
      film.invalidCount[i] += px[i].invalid;
    }
    DeviceCounters c;
    std::memcpy(&c, static_cast<const char*>(readback.mapped) + accumSize, sizeof(c));
    stats.rays += uint64_t(c.raysHigh) << 32 | c.raysLow;
    stats.truncatedSamples += c.truncated;
    stats.maxLoopIterations = std::max(stats.maxLoopIterations, c.maxLoopIterations);
    done += samples;
    if (options.progress) options.progress(double(done) / double(options.spp));
  }
  stats.invalidSamples = film.totalInvalid();
  stats.validationErrors = ctx.validationErrors();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace pt
