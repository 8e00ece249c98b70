// Stochastic progressive photon mapping on the Vulkan backend; see vulkan/sppm.h. The outline
// of renderSppm (cpu/sppm.cpp), its passes on the device: each iteration a camera pass
// (pathtrace.comp's PT_SPPM_CAMERA variant), the visible points read back and gridded on the
// host (SppmGrid, the CPU reference's), the grid uploaded, a photon pass (PT_SPPM_PHOTONS),
// the exact flux sums read back and every pixel updated on the host (sppmUpdatePixel).
#include "vulkan/sppm.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "common/check.h"
#include "cpu/sppm.h"
#include "cpu/sppm_grid.h"
#include "image/exact_sum.h"
#include "sppm_grid_cell.h"
#include "sppm_vertex.h"
#include "vulkan/context.h"
#include "vulkan/glsl_compiler.h"
#include "vulkan/resources.h"
#include "vulkan/scene_buffers.h"

namespace pt {
namespace {

// Photons per dispatch: a dispatch of 512 x (at most 8192) invocations.
constexpr uint32_t kSppmPhotonsPerDispatch = 1u << 22;
constexpr uint32_t kSppmPhotonRowInvocations = 512u;

// A visible point's record as the shaders lay it out (std430): the largest array stride the
// SPIR-V declares, sppmPoints' (every other array's element has 16 bytes at most).
uint32_t visiblePointStride(std::span<const uint32_t> spirv) {
  constexpr uint32_t kOpDecorate = 71, kArrayStride = 6;
  uint32_t stride = 0;
  for (size_t i = 5; i < spirv.size();) {
    const uint32_t words = spirv[i] >> 16;
    if (words == 0) break;
    if ((spirv[i] & 0xFFFFu) == kOpDecorate && words == 4 && spirv[i + 2] == kArrayStride) {
      stride = std::max(stride, spirv[i + 3]);
    }
    i += words;
  }
  PT_CHECK(stride >= 64, "the SPPM shader declares the visible points' array");
  return stride;
}

// One device buffer of SPPM's, checked against the storage-buffer limit.
Buffer sppmBuffer(const VulkanContext& ctx, const char* what, vk::DeviceSize size) {
  checkRange(ctx, what, size);
  return makeBuffer(ctx, std::max<vk::DeviceSize>(size, 16),
                    vk::BufferUsageFlagBits::eStorageBuffer |
                        vk::BufferUsageFlagBits::eTransferSrc |
                        vk::BufferUsageFlagBits::eTransferDst,
                    false);
}

void computeToTransfer(const vk::raii::CommandBuffer& cmd) {
  barrier(cmd, vk::PipelineStageFlagBits::eComputeShader, vk::AccessFlagBits::eShaderWrite,
          vk::PipelineStageFlagBits::eTransfer, vk::AccessFlagBits::eTransferRead);
}
void transferToCompute(const vk::raii::CommandBuffer& cmd) {
  barrier(cmd, vk::PipelineStageFlagBits::eTransfer, vk::AccessFlagBits::eTransferWrite,
          vk::PipelineStageFlagBits::eComputeShader,
          vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
}

// A camera path or photon cut short at lavapipe's loop cap leaves sums incomplete, of pixels no
// one can tell: the render is given up, in one line, as soon as an iteration has one.
void checkNotTruncated(const VulkanContext& ctx, const void* countersBack) {
  DeviceCounters c;
  std::memcpy(&c, countersBack, sizeof(c));
  if (c.truncated == 0) return;
  throw InputError("sppm on " + ctx.info().name + ": " + std::to_string(c.truncated) +
                   " camera paths or photons ran into the device's loop-iteration cap (the most "
                   "iterations one counted: " +
                   std::to_string(c.maxLoopIterations) +
                   "); render with a smaller --sppm-radius or image, or with --backend cpu");
}

void pushPass(const vk::raii::CommandBuffer& cmd, const ComputeProgram& program,
              const PassConstants& pc) {
  cmd.pushConstants<PassConstants>(*program.layout, vk::ShaderStageFlagBits::eCompute, 0, pc);
}

}  // namespace

VulkanRenderStats renderSppmVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                                   Film& film) {
  const auto callStart = std::chrono::steady_clock::now();
  const Camera& cam = scene.params.camera;
  PT_CHECK(film.width == int(cam.width) && film.height == int(cam.height));
  PT_CHECK(scene.params.mediaPresent == 0u, "SPPM renders no media (checkBdptScene)");
  // The scene (its upload recorded), SPPM's buffers and the two passes' pipelines.
  const ExactSumDeviceScene device(options.context, scene);  // the photons' exact sums
  const VulkanContext& ctx = device.ctx;
  const Commands& commands = device.commands;
  const vk::raii::CommandBuffer& cmd = commands.cmd;
  const RenderBuffers& buffers = device.buffers;
  const std::string definitions = pathtraceDefinitions(scene, options) + "#define PT_SPPM\n";
  const std::string cameraDefinitions = definitions + "#define PT_SPPM_CAMERA\n";
  const std::string photonDefinitions = definitions + "#define PT_SPPM_PHOTONS\n";
  const size_t pixels = film.pixelCount();
  const uint32_t stride = visiblePointStride(compileShader("pathtrace.comp", cameraDefinitions));
  // The grid's table has a prime number of buckets near the point count (below twice it), and
  // each point is listed in at most 27 buckets (its box, two radii wide, overlaps at most three
  // cells along an axis: a cell is at least the largest radius wide).
  const uint64_t gridWords = uint64_t(nextPrime(uint32_t(pixels))) + 1u + 27u * uint64_t(pixels);
  const vk::DeviceSize gridSize = sizeof(SppmGridShape) + gridWords * sizeof(uint32_t);
  const vk::DeviceSize foundSize = pixels * sizeof(vec4);
  const vk::DeviceSize fluxSize = pixels * PT_SPPM_FLUX_WORDS * sizeof(uint64_t);
  const Buffer points = sppmBuffer(ctx, "sppm visible point", pixels * stride);
  const Buffer found = sppmBuffer(ctx, "sppm visible point position", foundSize);
  const Buffer grid = sppmBuffer(ctx, "sppm grid", gridSize);
  const Buffer gridPoints = sppmBuffer(ctx, "sppm grid point", foundSize);
  const Buffer flux = sppmBuffer(ctx, "sppm flux", fluxSize);
  const std::vector<Binding> extra = {{&points}, {&found}, {&grid}, {&gridPoints}, {&flux}};
  static_assert(PT_BINDING_SPPM_POINTS == PT_BINDING_COUNT && PT_BINDING_SPPM_FOUND == 19 &&
                PT_BINDING_SPPM_GRID == 20 && PT_BINDING_SPPM_GRID_POINTS == 21 &&
                PT_BINDING_SPPM_FLUX == 22);
  const ComputeProgram cameraPass = makePathtraceProgram(ctx, cameraDefinitions, buffers, extra);
  const ComputeProgram photonPass = makePathtraceProgram(ctx, photonDefinitions, buffers, extra);
  // What comes back each iteration (the camera pass's points and direct light, the photons'
  // sums, the counters), and what goes up (the grid and the points' radii).
  const vk::DeviceSize foundAt = 0, ldAt = foundSize, fluxAt = ldAt + buffers.accumSize;
  const vk::DeviceSize countersAt = fluxAt + fluxSize;
  const Buffer readback = makeBuffer(ctx, countersAt + sizeof(DeviceCounters),
                                     vk::BufferUsageFlagBits::eTransferDst, true);
  const Buffer upload =
      makeBuffer(ctx, gridSize + foundSize, vk::BufferUsageFlagBits::eTransferSrc, true);

  // Warm up: drivers compile a pipeline at its first dispatch, which must not count as render
  // time; a dispatch of no samples (no photons) does nothing else.
  cmd.fillBuffer(*buffers.counters().buffer, 0, VK_WHOLE_SIZE, 0);
  cmd.fillBuffer(*flux.buffer, 0, VK_WHOLE_SIZE, 0);
  transferToCompute(cmd);
  const uint32_t groupsX = (cam.width + kWorkgroupSize - 1) / kWorkgroupSize;
  const uint32_t groupsY = (cam.height + kWorkgroupSize - 1) / kWorkgroupSize;
  cameraPass.bind(cmd);
  pushPass(cmd, cameraPass, PassConstants{0u, 0u, ~0u, 0u});
  cmd.dispatch(1, 1, 1);
  photonPass.bind(cmd);
  pushPass(cmd, photonPass, PassConstants{0u, 0u, ~0u, 0u});
  cmd.dispatch(1, 1, 1);
  computeToTransfer(cmd);
  commands.submitAndWait(ctx);

  const uint32_t photons = sppmPhotonsPerIteration(scene);
  SppmPixels local;
  SppmPixels& records = sppmStartState(scene, options, pixels, local);
  std::vector<vec3> gridAt(pixels);
  std::vector<float> radii(pixels);
  std::vector<char> present(pixels);
  const auto* back = static_cast<const char*>(readback.mapped);
  const auto* foundBack = reinterpret_cast<const vec4*>(back + foundAt);
  const auto* ldBack = reinterpret_cast<const AccumPixel*>(back + ldAt);
  const auto* fluxBack = reinterpret_cast<const uint64_t*>(back + fluxAt);
  auto stopRequested = [&] {
    return options.stop && options.stop->load(std::memory_order_relaxed);
  };

  VulkanRenderStats stats;
  stats.device = ctx.info().name;
  const auto start = std::chrono::steady_clock::now();
  int done = 0;
  for (int k = 0; k < options.spp && !stopRequested(); ++k) {
    const uint32_t iteration = options.firstSample + uint32_t(k);
    // The camera pass: every pixel's path to its visible point, and its direct light.
    commands.begin();
    cmd.fillBuffer(*buffers.accum().buffer, 0, VK_WHOLE_SIZE, 0);
    cmd.fillBuffer(*found.buffer, 0, VK_WHOLE_SIZE, 0);
    transferToCompute(cmd);
    cameraPass.bind(cmd);
    pushPass(cmd, cameraPass, PassConstants{iteration, 1u, ~0u, 0u});
    cmd.dispatch(groupsX, groupsY, 1);
    computeToTransfer(cmd);
    cmd.copyBuffer(*found.buffer, *readback.buffer, vk::BufferCopy(0, foundAt, foundSize));
    cmd.copyBuffer(*buffers.accum().buffer, *readback.buffer,
                   vk::BufferCopy(0, ldAt, buffers.accumSize));
    cmd.copyBuffer(*buffers.counters().buffer, *readback.buffer,
                   vk::BufferCopy(0, countersAt, sizeof(DeviceCounters)));
    commands.submitAndWait(ctx);
    checkNotTruncated(ctx, back + countersAt);

    // The grid over the visible points that carry light to their pixel, uploaded with the
    // points' positions and radii.
    for (size_t i = 0; i < pixels; ++i) {
      present[i] = foundBack[i].w != 0.0f;
      gridAt[i] = vec3(foundBack[i]);
      radii[i] = records[i].radius;
    }
    const SppmGrid cells(gridAt, radii, present);
    auto* up = static_cast<char*>(upload.mapped);
    const SppmGridShape shape = cells.shape();
    const std::vector<uint32_t>& starts = cells.bucketStarts();
    const std::vector<uint32_t>& entries = cells.entries();
    PT_CHECK(starts.size() + entries.size() <= gridWords);
    std::memcpy(up, &shape, sizeof(shape));
    std::memcpy(up + sizeof(shape), starts.data(), starts.size() * sizeof(uint32_t));
    std::memcpy(up + sizeof(shape) + starts.size() * sizeof(uint32_t), entries.data(),
                entries.size() * sizeof(uint32_t));
    auto* pointsUp = reinterpret_cast<vec4*>(up + gridSize);
    for (size_t i = 0; i < pixels; ++i) pointsUp[i] = vec4(gridAt[i], radii[i]);

    // The photon pass, in dispatches of at most kSppmPhotonsPerDispatch photons, gathering at
    // every hit (hits == 0) or split by hits: a dispatch for each hit, every photon traced to
    // it and taking the visible points there alone. The sums are exact, so either way gives
    // the same bits; the split keeps each invocation's loop iterations to one hit's bucket,
    // where all of them together ran into lavapipe's loop cap.
    const auto photonPassBy = [&](uint32_t hits) {
      commands.begin();
      cmd.fillBuffer(*flux.buffer, 0, VK_WHOLE_SIZE, 0);
      cmd.fillBuffer(*buffers.counters().buffer, offsetof(DeviceCounters, truncated),
                     sizeof(uint32_t), 0);
      transferToCompute(cmd);
      photonPass.bind(cmd);
      for (uint32_t hit = hits == 0 ? ~0u : 1u; hits == 0 || hit < hits; ++hit) {
        for (uint32_t first = 0; first < photons;) {
          const uint32_t count = std::min(photons - first, kSppmPhotonsPerDispatch);
          const uint32_t perRow = kSppmPhotonRowInvocations;
          const uint32_t rows = (count + perRow - 1) / perRow;
          pushPass(cmd, photonPass, PassConstants{iteration, count, hit, first});
          cmd.dispatch(perRow / kWorkgroupSize, (rows + kWorkgroupSize - 1) / kWorkgroupSize, 1);
          first += count;
        }
        if (hits == 0) break;
      }
      computeToTransfer(cmd);
      cmd.copyBuffer(*flux.buffer, *readback.buffer, vk::BufferCopy(0, fluxAt, fluxSize));
      cmd.copyBuffer(*buffers.counters().buffer, *readback.buffer,
                     vk::BufferCopy(0, countersAt, sizeof(DeviceCounters)));
      commands.submitAndWait(ctx);
      DeviceCounters c;
      std::memcpy(&c, back + countersAt, sizeof(c));
      return c.truncated == 0;
    };
    commands.begin();
    cmd.copyBuffer(*upload.buffer, *grid.buffer, vk::BufferCopy(0, 0, gridSize));
    cmd.copyBuffer(*upload.buffer, *gridPoints.buffer, vk::BufferCopy(gridSize, 0, foundSize));
    commands.submitAndWait(ctx);
    if (!photonPassBy(0)) {
      ++stats.splitPhotonPasses;
      photonPassBy(scene.params.maxDepth);
      checkNotTruncated(ctx, back + countersAt);
    }

    // Every pixel's update from the photons it gathered: the exact sums rounded once, as the
    // CPU reference's.
    for (size_t i = 0; i < pixels; ++i) {
      const uint64_t* words = fluxBack + PT_SPPM_FLUX_WORDS * i;
      vec3 phi;
      for (int c = 0; c < 3; ++c) {
        ExactSum sum;
        std::memcpy(sum.limb, words + ExactSum::kLimbs * c, sizeof(sum.limb));
        phi[c] = float(sum.toDouble());
      }
      const uint64_t count = words[PT_SPPM_COUNT_WORD];
      const uint64_t m = count & ((uint64_t(1) << PT_SPPM_INVALID_SHIFT) - 1u);
      SppmPixelRecord& r = records[i];
      if ((count >> PT_SPPM_INVALID_SHIFT) != 0 || ldBack[i].invalid != 0) r.invalid = true;
      sppmUpdateRecord(r, phi, uint32_t(m), ldBack[i].sum);
    }
    done = k + 1;
    if (options.progress) options.progress(double(done) / double(options.spp));
    if (options.checkpoint) {
      sppmEstimateToFilm(records, options.firstSample + uint32_t(done), photons, film);
      options.checkpoint(done);
    }
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // The counters of every pass (read back with the last photon pass's sums).
  DeviceCounters counters;
  std::memcpy(&counters, back + countersAt, sizeof(counters));
  stats.rays = uint64_t(counters.raysHigh) << 32 | counters.raysLow;
  stats.maxLoopIterations = counters.maxLoopIterations;

  // Each pixel's estimate, as its one sample.
  if (options.firstSample + uint32_t(done) > 0u) {
    sppmEstimateToFilm(records, options.firstSample + uint32_t(done), photons, film);
  }
  stats.stopped = done < options.spp;
  if (options.progress && !stats.stopped) options.progress(1.0);
  finishExactSumStats(device, film, done, callStart, stats);
  return stats;
}

}  // namespace pt
