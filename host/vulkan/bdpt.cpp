// Bidirectional path tracing on the Vulkan backend; see vulkan/bdpt.h. The outline of renderBdpt
// (cpu/bdpt.cpp), its passes on the device: each pass one dispatch of pathtrace.comp's PT_BDPT
// variant, one sample index for every pixel; now and then the device's exact sums are read
// back, folded into the film and cleared.
#include "vulkan/bdpt.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include "bdpt_splat.h"
#include "common/check.h"
#include "cpu/bdpt.h"
#include "image/exact_sum.h"
#include "vulkan/context.h"
#include "vulkan/glsl_compiler.h"
#include "vulkan/resources.h"
#include "vulkan/scene_buffers.h"

namespace pt {
namespace {

using S = vk::PipelineStageFlagBits;
using A = vk::AccessFlagBits;

// The film is read back and folded at most about this often (and at the end, and when
// stopped): a checkpoint needs it folded, and a fold costs a read-back of 128 bytes a pixel.
constexpr double kFoldSeconds = 1.0;

// The variant's definitions beyond the scene's effects (shaders/bdpt.glsl): the subpaths'
// array size, the splats' weight scale as its float's bits.
std::string bdptDefinitions(const SceneData& scene, const VulkanRenderOptions& options) {
  const Camera& cam = scene.params.camera;
  const float scale = bdptSplatScale(cam, bdptInverseFilterIntegral(cam));
  uint32_t bits;
  std::memcpy(&bits, &scale, sizeof(bits));
  return pathtraceDefinitions(scene, options) + "#define PT_BDPT\n" +
         "#define PT_BDPT_MAX_VERTICES " + std::to_string(bdptMaxDepth(scene) + 2u) + "u\n" +
         "#define PT_BDPT_SPLAT_SCALE uintBitsToFloat(" + std::to_string(bits) + "u)\n";
}

// PassConstants::reserved for bdpt.glsl: ~0u for every strategy weighed, else s << 16 | t.
uint32_t strategyConstant(const BdptStrategy& strategy) {
  return strategy.all() ? ~0u : uint32_t(strategy.s) << 16 | uint32_t(strategy.t);
}

// The read-back film's sums and counts into the film (exactly: the device's limbs are
// ExactSum's), and the counters into the statistics. Throws where a sample was cut short.
void foldBdptFilm(const VulkanContext& ctx, const uint64_t* words, const DeviceCounters& c,
                  Film& film, VulkanRenderStats& stats) {
  if (c.truncated != 0) {
    throw InputError("bdpt on " + ctx.info().name + ": " + std::to_string(c.truncated) +
                     " pixel samples ran into the device's loop-iteration cap (the most "
                     "iterations one counted: " +
                     std::to_string(c.maxLoopIterations) +
                     "); render with a smaller maxdepth, or with --backend cpu");
  }
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    const uint64_t* pixel = words + PT_BDPT_FILM_WORDS * i;
    std::array<ExactSum, 3> sums;
    for (int ch = 0; ch < 3; ++ch) {
      std::memcpy(sums[ch].limb, pixel + ExactSum::kLimbs * ch, sizeof(sums[ch].limb));
    }
    const uint64_t count = pixel[PT_BDPT_COUNT_WORD];
    film.addExactSums(i, sums, count & ((uint64_t(1) << PT_BDPT_INVALID_SHIFT) - 1u),
                      count >> PT_BDPT_INVALID_SHIFT);
  }
  stats.rays += uint64_t(c.raysHigh) << 32 | c.raysLow;
  stats.maxLoopIterations = std::max(stats.maxLoopIterations, c.maxLoopIterations);
}

}  // namespace

VulkanRenderStats renderBdptVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                                   Film& film) {
  const auto callStart = std::chrono::steady_clock::now();
  const Camera& cam = scene.params.camera;
  PT_CHECK(film.width == int(cam.width) && film.height == int(cam.height));
  PT_CHECK(scene.params.mediaPresent == 0u, "BDPT renders no media (checkBdptScene)");
  // The scene (its upload recorded), the device's film and the pipeline.
  const ExactSumDeviceScene device(options.context, scene);  // the film's exact sums
  const VulkanContext& ctx = device.ctx;
  const Commands& commands = device.commands;
  const vk::raii::CommandBuffer& cmd = commands.cmd;
  const RenderBuffers& buffers = device.buffers;
  const vk::DeviceSize filmSize = film.pixelCount() * PT_BDPT_FILM_WORDS * sizeof(uint64_t);
  checkRange(ctx, "bdpt film", filmSize);
  const auto readWrite = vk::BufferUsageFlagBits::eStorageBuffer |
                         vk::BufferUsageFlagBits::eTransferSrc |
                         vk::BufferUsageFlagBits::eTransferDst;
  const Buffer deviceFilm = makeBuffer(ctx, filmSize, readWrite, false);
  static_assert(PT_BINDING_BDPT_FILM == PT_BINDING_COUNT);
  const ComputeProgram program =
      makePathtraceProgram(ctx, bdptDefinitions(scene, options), buffers, {{&deviceFilm}});
  const Buffer readback = makeBuffer(ctx, filmSize + sizeof(DeviceCounters),
                                     vk::BufferUsageFlagBits::eTransferDst, true);
  const auto clear = [&] {
    cmd.fillBuffer(*deviceFilm.buffer, 0, VK_WHOLE_SIZE, 0);
    cmd.fillBuffer(*buffers.counters().buffer, 0, VK_WHOLE_SIZE, 0);
    barrier(cmd, S::eTransfer, A::eTransferWrite, S::eComputeShader,
            A::eShaderRead | A::eShaderWrite);
  };
  const auto dispatch = [&](uint32_t sampleIndex, uint32_t samples, uint32_t groupsX,
                            uint32_t groupsY) {
    program.bind(cmd);
    cmd.pushConstants<PassConstants>(
        *program.layout, vk::ShaderStageFlagBits::eCompute, 0,
        PassConstants{sampleIndex, samples, ~0u, strategyConstant(options.bdptStrategy)});
    cmd.dispatch(groupsX, groupsY, 1);
  };

  // Warm up: drivers compile a pipeline at its first dispatch, which must not count as render
  // time; a dispatch of no samples does nothing else.
  clear();
  dispatch(0u, 0u, 1u, 1u);
  commands.submitAndWait(ctx);

  VulkanRenderStats stats;
  stats.device = ctx.info().name;
  const DeviceTimer timer(ctx);
  const uint32_t groupsX = (cam.width + kWorkgroupSize - 1) / kWorkgroupSize;
  const uint32_t groupsY = (cam.height + kWorkgroupSize - 1) / kWorkgroupSize;
  const auto* back = static_cast<const char*>(readback.mapped);
  auto stopRequested = [&] {
    return options.stop && options.stop->load(std::memory_order_relaxed);
  };
  // Reads the device's film and counters back, clears them and folds them into the film.
  const auto fold = [&] {
    commands.begin();
    barrier(cmd, S::eComputeShader, A::eShaderWrite, S::eTransfer, A::eTransferRead);
    cmd.copyBuffer(*deviceFilm.buffer, *readback.buffer, vk::BufferCopy(0, 0, filmSize));
    cmd.copyBuffer(*buffers.counters().buffer, *readback.buffer,
                   vk::BufferCopy(0, filmSize, sizeof(DeviceCounters)));
    barrier(cmd, S::eTransfer, A::eTransferRead, S::eTransfer, A::eTransferWrite);
    clear();
    commands.submitAndWait(ctx);
    DeviceCounters c;
    std::memcpy(&c, back + filmSize, sizeof(c));
    foldBdptFilm(ctx, reinterpret_cast<const uint64_t*>(back), c, film, stats);
  };

  int done = 0;    // passes dispatched
  int folded = 0;  // passes in the film
  auto lastFold = std::chrono::steady_clock::now();
  const auto foldNow = [&] {
    fold();
    folded = done;
    lastFold = std::chrono::steady_clock::now();
    if (options.checkpoint) options.checkpoint(folded);
  };
  while (done < options.spp) {
    if (stopRequested()) {
      stats.stopped = true;
      break;
    }
    commands.begin();
    timer.start(cmd);
    dispatch(options.firstSample + uint32_t(done), 1u, groupsX, groupsY);
    timer.stop(cmd);
    commands.submitAndWait(ctx);
    stats.seconds += timer.seconds();
    ++done;
    if (options.progress) options.progress(double(done) / double(options.spp));
    const double sinceFold =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - lastFold).count();
    if (done == options.spp || sinceFold >= kFoldSeconds) foldNow();
  }
  if (folded < done) foldNow();
  finishExactSumStats(device, film, done, callStart, stats);
  return stats;
}

}  // namespace pt
