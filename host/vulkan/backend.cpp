// Vulkan backend; see backend.h. Host code kept small: device-local buffers filled through
// one staging buffer, one descriptor set, one compute pipeline specialised to the scene's
// effect set, one command buffer re-recorded for every dispatch. renderVulkan reads as its
// four stages: upload, pipeline, batches of passes, fold into the film.
#include "vulkan/backend.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "common/check.h"
#include "sheen_albedo.h"
#include "vulkan/bdpt.h"
#include "vulkan/context.h"
#include "vulkan/device_limits.h"
#include "vulkan/glsl_compiler.h"
#include "vulkan/gpu_bvh.h"
#include "vulkan/resources.h"
#include "vulkan/scene_buffers.h"
#include "vulkan/sppm.h"

namespace pt {
namespace {

using S = vk::PipelineStageFlagBits;
using A = vk::AccessFlagBits;
using U = vk::BufferUsageFlagBits;

}  // namespace

// ---- Upload: the flat scene arrays into device-local buffers ---------------------------------

RenderBuffers uploadScene(const VulkanContext& ctx, const SceneData& scene,
                          const vk::raii::CommandBuffer& cmd, Buffer& staging) {
  const Camera& cam = scene.params.camera;
  // The environment image against the device's texel limit first, naming its file.
  checkEnvironmentTexels(ctx.info().name, ctx.limits.maxTexelBufferElements, scene.environmentFile,
                         scene.environmentTexels.size());
  const std::vector<vec4> environment =
      scene.environmentTexels.empty() ? std::vector<vec4>{vec4(0.0f)} : scene.environmentTexels;
  // An empty emitter table still needs a valid binding: one zeroed entry the shader never reads.
  const std::vector<Emitter> emitters =
      scene.emitters.empty() ? std::vector<Emitter>{Emitter{}} : scene.emitters;
  const std::vector<TriangleNormals> normals =
      scene.normals.empty() ? std::vector<TriangleNormals>{TriangleNormals{}} : scene.normals;
  const std::vector<Light> lights =
      scene.lights.empty() ? std::vector<Light>{Light{}} : scene.lights;
  // The texture arrays, one dummy entry each where the scene has no textures; the image
  // buffer padded to whole 16-byte texels.
  const auto orDummy = [](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    return v.empty() ? std::vector<T>{T{}} : v;
  };
  const std::vector<TriangleUVs> uvs = orDummy(scene.uvs);
  // The materials, and after them the sheen's albedo table where a material has a sheen
  // (sheenAlbedoNode in pathtrace.comp, from texel sheenAlbedoTexel(scene)).
  std::vector<uint32_t> materials(scene.materials.size() * sizeof(Material) / sizeof(uint32_t));
  if (!materials.empty())
    std::memcpy(materials.data(), scene.materials.data(), materials.size() * 4);
  if (scene.effects.gltfSheen) {
    for (float e : kSheenAlbedo) materials.push_back(std::bit_cast<uint32_t>(e));
  }
  const std::vector<TextureNode> textureNodes = orDummy(scene.textureNodes);
  std::vector<uint32_t> imageWords = orDummy(scene.imageWords);
  imageWords.resize((imageWords.size() + 3) / 4 * 4, 0u);
  const std::vector<MaterialTextures> materialTextures = orDummy(scene.materialTextures);
  const std::vector<Medium> media = orDummy(scene.media);
  std::vector<float> mediumGrids = orDummy(scene.mediumGrids);
  mediumGrids.resize((mediumGrids.size() + 3) / 4 * 4, 0.0f);
  std::vector<MediumInterface> mediumInterfaces = orDummy(scene.mediumInterfaces);
  mediumInterfaces.resize((mediumInterfaces.size() + 1) / 2 * 2, MediumInterface{});
  // The light BVH's nodes and then its words, in whole texels (one zeroed texel without it).
  std::vector<uint32_t> lightBvh(scene.lightBvh.size() * sizeof(LightBvhNode) / sizeof(uint32_t));
  if (!lightBvh.empty()) std::memcpy(lightBvh.data(), scene.lightBvh.data(), lightBvh.size() * 4);
  lightBvh.insert(lightBvh.end(), scene.lightBvhWords.begin(), scene.lightBvhWords.end());
  lightBvh.resize(std::max<size_t>(4, (lightBvh.size() + 3) / 4 * 4), 0u);
  const GpuBvh bvh = buildGpuBvh(scene.bvh);
  const std::vector<uint32_t> traversal = gpuTraversalTexels(bvh, scene.bvh.triangles);
  // In PT_BINDING_* order, followed by the accumulation and the counters.
  const Upload uploads[] = {
      {"parameter", &scene.params, sizeof(RenderParams), false},
      {"BVH node and triangle", traversal.data(), traversal.size() * sizeof(uint32_t), true},
      {"triangle", scene.bvh.triangles.data(), scene.bvh.triangles.size() * sizeof(Triangle), true},
      {"material", materials.data(), materials.size() * sizeof(uint32_t), true},
      {"emitter", emitters.data(), emitters.size() * sizeof(Emitter), true},
      {"vertex normal", normals.data(), normals.size() * sizeof(TriangleNormals), true},
      {"light", lights.data(), lights.size() * sizeof(Light), true},
      {"environment", environment.data(), environment.size() * sizeof(vec4), true},
      {"texture coordinate", uvs.data(), uvs.size() * sizeof(TriangleUVs), true},
      {"texture", textureNodes.data(), textureNodes.size() * sizeof(TextureNode), true},
      {"texture image", imageWords.data(), imageWords.size() * sizeof(uint32_t), true},
      {"material texture", materialTextures.data(),
       materialTextures.size() * sizeof(MaterialTextures), true},
      {"medium", media.data(), media.size() * sizeof(Medium), true},
      {"medium grid", mediumGrids.data(), mediumGrids.size() * sizeof(float), true},
      {"medium interface", mediumInterfaces.data(),
       mediumInterfaces.size() * sizeof(MediumInterface), true},
      {"light BVH", lightBvh.data(), lightBvh.size() * sizeof(uint32_t), true},
  };
  static_assert(PT_BINDING_PARAMS == 0 && PT_BINDING_NODES == 1 && PT_BINDING_TRIANGLES == 2 &&
                PT_BINDING_MATERIALS == 3 && PT_BINDING_EMITTERS == 4 && PT_BINDING_NORMALS == 5 &&
                PT_BINDING_LIGHTS == 6 && PT_BINDING_ACCUM == 7 && PT_BINDING_COUNTERS == 8 &&
                PT_BINDING_ENVIRONMENT == 9 && PT_BINDING_UVS == 10 && PT_BINDING_TEXTURES == 11 &&
                PT_BINDING_IMAGES == 12 && PT_BINDING_MATERIAL_TEXTURES == 13 &&
                PT_BINDING_MEDIA == 14 && PT_BINDING_MEDIUM_GRIDS == 15 &&
                PT_BINDING_MEDIUM_INTERFACES == 16 && PT_BINDING_LIGHT_BVH == 17);
  static_assert(std::size(uploads) + 2 == PT_BINDING_COUNT, "every binding is a buffer");

  // Every size is checked before anything is allocated: a scene too large for the device is
  // refused with the numbers. Every buffer is held to the storage-buffer limit (lavapipe
  // allows 128 MiB), the scene's arrays as well, as before they were read as texels, and
  // those to the texel-buffer limit besides.
  RenderBuffers buffers;
  buffers.stackRows = gpuStackRows(bvh);
  buffers.accumSize = vk::DeviceSize(cam.width) * cam.height * sizeof(AccumPixel);
  checkRange(ctx, "accumulation", buffers.accumSize);
  checkUploads(ctx, uploads);
  buffers.bound = recordUploads(ctx, cmd, uploads, staging);
  for (const Upload& u : uploads) buffers.texels.push_back(u.texels);
  // The accumulation and the counters take their bindings, between the uploads.
  const auto readWrite = U::eStorageBuffer | U::eTransferSrc | U::eTransferDst;
  const auto at = [&](int binding) { return buffers.bound.begin() + binding; };
  buffers.bound.insert(at(PT_BINDING_ACCUM), makeBuffer(ctx, buffers.accumSize, readWrite, false));
  buffers.bound.insert(at(PT_BINDING_COUNTERS),
                       makeBuffer(ctx, sizeof(DeviceCounters), readWrite, false));
  buffers.texels.insert(buffers.texels.begin() + PT_BINDING_ACCUM, 2, false);
  buffers.readback =
      makeBuffer(ctx, buffers.accumSize + sizeof(DeviceCounters), U::eTransferDst, true);
  return buffers;
}

namespace {

ContextOptions withInt64Atomics(ContextOptions options) {
  options.int64Atomics = true;
  return options;
}

}  // namespace

ExactSumDeviceScene::ExactSumDeviceScene(const ContextOptions& options, const SceneData& scene)
    : ctx(withInt64Atomics(options)), commands(ctx) {
  commands.begin();
  buffers = uploadScene(ctx, scene, commands.cmd, staging);
}

void finishExactSumStats(const ExactSumDeviceScene& device, const Film& film, int samplesDone,
                         std::chrono::steady_clock::time_point callStart,
                         VulkanRenderStats& stats) {
  stats.samplesDone = samplesDone;
  stats.invalidSamples = film.totalInvalid();
  stats.validationErrors = device.ctx.validationErrors();
  stats.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - callStart).count();
}

// ---- Pipeline: shaders/pathtrace.comp compiled for the scene's effect set -----------------

ComputeProgram makePathtraceProgram(const VulkanContext& ctx, const std::string& definitions,
                                    const RenderBuffers& buffers,
                                    const std::vector<Binding>& extra) {
  std::vector<Binding> bound;
  for (size_t i = 0; i < buffers.bound.size(); ++i) {
    bound.push_back(Binding{&buffers.bound[i], buffers.texels[i]});
  }
  bound.insert(bound.end(), extra.begin(), extra.end());
  const std::vector<uint32_t>& spirv = compileShader("pathtrace.comp", definitions);
  const vk::SpecializationMapEntry stackEntry(PT_SPEC_STACK_ROWS, 0, sizeof(uint32_t));
  const vk::SpecializationInfo specInfo(1, &stackEntry, sizeof(uint32_t), &buffers.stackRows);
  return makeComputeProgram(ctx, spirv, bound, sizeof(PassConstants), &specInfo);
}

namespace {

// ---- Passes: dispatches of the shader, recorded into one command buffer -----------------------

class PassRecorder {
 public:
  PassRecorder(const vk::raii::CommandBuffer& cmd, const ComputeProgram& program,
               const RenderBuffers& buffers, const Camera& cam, uint32_t debugPixel)
      : cmd_(cmd),
        program_(program),
        buffers_(buffers),
        groupsX_((cam.width + kWorkgroupSize - 1) / kWorkgroupSize),
        groupsY_((cam.height + kWorkgroupSize - 1) / kWorkgroupSize),
        debugPixel_(debugPixel) {}

  // Zeroes the accumulation and the counters before the next dispatch reads them.
  void clearAccumulators() const {
    cmd_.fillBuffer(*buffers_.accum().buffer, 0, VK_WHOLE_SIZE, 0);
    cmd_.fillBuffer(*buffers_.counters().buffer, 0, VK_WHOLE_SIZE, 0);
    barrier(cmd_, S::eTransfer, A::eTransferWrite, S::eComputeShader,
            A::eShaderRead | A::eShaderWrite);
  }

  // One pass: sample indices [sampleIndex, sampleIndex + sampleCount) of every pixel (of the
  // first workgroup only, for the warm-up).
  void dispatch(uint32_t sampleIndex, uint32_t sampleCount, bool wholeImage = true) const {
    const PassConstants pc{sampleIndex, sampleCount, debugPixel_, 0u};
    cmd_.pushConstants<PassConstants>(*program_.layout, vk::ShaderStageFlagBits::eCompute, 0, pc);
    cmd_.dispatch(wholeImage ? groupsX_ : 1u, wholeImage ? groupsY_ : 1u, 1);
    barrier(cmd_, S::eComputeShader, A::eShaderWrite, S::eComputeShader | S::eTransfer,
            A::eShaderRead | A::eShaderWrite | A::eTransferRead);
  }

  // Copies the most loop iterations an invocation of the last dispatch ran to the readback
  // buffer (for loopIterations), then clears it for the next dispatch.
  void copyLoopIterations() const {
    const vk::DeviceSize at = offsetof(DeviceCounters, maxLoopIterations);
    cmd_.copyBuffer(*buffers_.counters().buffer, *buffers_.readback.buffer,
                    vk::BufferCopy(at, buffers_.accumSize + at, sizeof(uint32_t)));
    barrier(cmd_, S::eTransfer, A::eTransferRead, S::eTransfer, A::eTransferWrite);
    cmd_.fillBuffer(*buffers_.counters().buffer, at, sizeof(uint32_t), 0);
    barrier(cmd_, S::eTransfer, A::eTransferWrite, S::eComputeShader,
            A::eShaderRead | A::eShaderWrite);
  }
  uint32_t loopIterations() const {
    DeviceCounters c;
    std::memcpy(&c, static_cast<const char*>(buffers_.readback.mapped) + buffers_.accumSize,
                sizeof(c));
    return c.maxLoopIterations;
  }

  // Copies the accumulation and the counters to the readback buffer, then clears them.
  void readBack() const {
    cmd_.copyBuffer(*buffers_.accum().buffer, *buffers_.readback.buffer,
                    vk::BufferCopy(0, 0, buffers_.accumSize));
    cmd_.copyBuffer(*buffers_.counters().buffer, *buffers_.readback.buffer,
                    vk::BufferCopy(0, buffers_.accumSize, sizeof(DeviceCounters)));
    barrier(cmd_, S::eTransfer, A::eTransferRead, S::eTransfer, A::eTransferWrite);
    clearAccumulators();
  }

 private:
  const vk::raii::CommandBuffer& cmd_;
  const ComputeProgram& program_;
  const RenderBuffers& buffers_;
  uint32_t groupsX_, groupsY_;
  uint32_t debugPixel_;
};

// ---- Fold: the batch's float sums into the film's exact sums --------------------------------

// The device counters in the readback buffer into the statistics.
void addCounters(const RenderBuffers& buffers, VulkanRenderStats& stats) {
  DeviceCounters c;
  std::memcpy(&c, static_cast<const char*>(buffers.readback.mapped) + buffers.accumSize, sizeof(c));
  stats.rays += uint64_t(c.raysHigh) << 32 | c.raysLow;
  stats.truncatedSamples += c.truncated;
  stats.maxLoopIterations = std::max(stats.maxLoopIterations, c.maxLoopIterations);
}

// `samples` samples per pixel were dispatched since the last fold. The float sums are added
// to the film exactly, so a batch contributes the same bits whenever it is folded.
void foldIntoFilm(const RenderBuffers& buffers, int samples, Film& film, VulkanRenderStats& stats) {
  const auto* px = static_cast<const AccumPixel*>(buffers.readback.mapped);
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    film.addSums(i, px[i].sum, uint64_t(samples) - px[i].invalid, px[i].invalid);
  }
  addCounters(buffers, stats);
}

// The read-back sums of the batch [first, first + count), kept open instead of folded.
OpenBatch readOpenBatch(const RenderBuffers& buffers, uint32_t first, uint32_t count, size_t pixels,
                        VulkanRenderStats& stats) {
  const auto* px = static_cast<const AccumPixel*>(buffers.readback.mapped);
  OpenBatch open;
  open.first = first;
  open.count = count;
  open.sum.resize(pixels);
  open.invalid.resize(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    open.sum[i] = px[i].sum;
    open.invalid[i] = px[i].invalid;
  }
  addCounters(buffers, stats);
  return open;
}

// Records the upload of an open batch's sums into the (cleared) accumulation, through
// `staging` (kept alive by the caller until the commands have run).
void uploadOpenBatch(const VulkanContext& ctx, const vk::raii::CommandBuffer& cmd,
                     const RenderBuffers& buffers, const OpenBatch& open, Buffer& staging) {
  staging = makeBuffer(ctx, buffers.accumSize, U::eTransferSrc, true);
  auto* px = static_cast<AccumPixel*>(staging.mapped);
  for (size_t i = 0; i < open.sum.size(); ++i) px[i] = AccumPixel{open.sum[i], open.invalid[i]};
  cmd.copyBuffer(*staging.buffer, *buffers.accum().buffer, vk::BufferCopy(0, 0, buffers.accumSize));
  barrier(cmd, S::eTransfer, A::eTransferWrite, S::eComputeShader,
          A::eShaderRead | A::eShaderWrite);
}

// Samples per pass when the options leave it open: as many as keep a dispatch to about
// kDispatchSeconds (a stop waits for the dispatch under way) and an invocation's loop
// iterations to kLoopIterations, a quarter of lavapipe's cap, judged by the last dispatch
// (`count` samples, `seconds`, `loopIterations` in its busiest invocation); at most four times
// the last count and at most a batch. More samples per pass save dispatches and keep a SIMD
// group's lanes busy: each lane goes on with its next sample as soon as a path ends, where
// with one sample per pass the group waits for its longest path (lavapipe, Cornell box 256²:
// 0.70 of the speed at 16 samples per pass, 0.87 at 4).
constexpr double kDispatchSeconds = 0.5;
constexpr double kLoopIterations = 65535.0 / 4.0;

uint32_t nextSamplesPerPass(uint32_t count, double seconds, uint32_t loopIterations,
                            uint64_t batch) {
  const double byTime = kDispatchSeconds * count / std::max(seconds, 1e-6);
  const double byLoops = kLoopIterations * count / std::max(loopIterations, 1u);
  const double k = std::min({byTime, byLoops, 4.0 * count, double(batch)});
  return uint32_t(std::max(1.0, std::floor(k)));
}

// The first pass, which no dispatch has timed yet: four samples (what a first pass of one
// would grow to), fewer where that is more paths than one sample of a 512 x 512 image (what
// a pass of one sample would cost there) or where the warm-up's loop iterations
// (`warmUpLoopIterations`, one sample of the first workgroup's pixels) say the loop cap is
// near.
uint32_t firstSamplesPerPass(size_t pixels, uint32_t warmUpLoopIterations, uint64_t batch) {
  constexpr double kFirstPassPaths = 512.0 * 512.0;
  const double byPaths = kFirstPassPaths / double(std::max<size_t>(pixels, 1));
  const double byLoops = kLoopIterations / std::max(warmUpLoopIterations, 1u);
  const double k = std::min({byPaths, byLoops, 4.0, double(batch)});
  return uint32_t(std::max(1.0, std::floor(k)));
}

}  // namespace

std::string pathtraceDefinitions(const SceneData& scene, const VulkanRenderOptions& options) {
  const EffectSet& fx = scene.effects;
  const bool all = !options.specialize;
  const RenderParams& params = scene.params;
  std::string text = "#define PT_FX_SET\n";
  const auto define = [&text](const char* name, const std::string& value) {
    text += std::string("#define ") + name + " " + value + "\n";
  };
  const auto flag = [&](const char* name, bool on) { define(name, all || on ? "true" : "false"); };
  const auto choice = [&](const char* name, uint32_t value) {
    define(name, all ? "kSpecAtRunTime" : std::to_string(value) + "u");
  };
  flag("PT_FX_DIFFUSE", fx.diffuse);
  flag("PT_FX_MIRROR", fx.mirror);
  flag("PT_FX_NEE", fx.lightSampling);
  flag("PT_FX_BSDF_EMISSION", fx.bsdfEmission);
  flag("PT_FX_MIS", fx.mis);
  flag("PT_FX_RR", fx.russianRoulette);
  choice("PT_FX_INTERSECTION", params.fastIntersection);
  choice("PT_FX_SAMPLER", params.samplerType);
  flag("PT_FX_LIGHT_BVH", fx.lightBvh);
  flag("PT_FX_CONDUCTOR", fx.conductor);
  flag("PT_FX_DIELECTRIC", fx.dielectric);
  flag("PT_FX_THIN_DIELECTRIC", fx.thinDielectric);
  flag("PT_FX_DIFFUSE_TRANSMISSION", fx.diffuseTransmission);
  flag("PT_FX_COATED_DIFFUSE", fx.coatedDiffuse);
  flag("PT_FX_GLTF", fx.gltf);
  flag("PT_FX_GLTF_LAYERS", fx.gltfLayers);
  flag("PT_FX_GLTF_SHEEN", fx.gltfSheen);
  flag("PT_FX_SHADING_NORMALS", fx.shadingNormals);
  flag("PT_FX_DELTA_LIGHTS", fx.deltaLights);
  flag("PT_FX_ENVIRONMENT", fx.environment);
  flag("PT_FX_TWO_SIDED_EMITTERS", fx.twoSidedEmitters);
  flag("PT_FX_SPHERE_LIGHTS", fx.sphereLights);
  flag("PT_FX_TEXTURES", fx.textures);
  flag("PT_FX_ALPHA", fx.alphaCutouts);
  flag("PT_FX_BUMP", fx.bumpMaps);
  define("PT_FX_TEXTURE_FEATURES",
         all ? "kTextureUsesAll" : std::to_string(fx.textureFeatures) + "u");
  define("PT_FX_MEDIUM_KINDS", all ? "0xFFFFFFFFu" : std::to_string(fx.mediumKinds) + "u");
  if (fx.gltfSheen) {
    define("PT_SHEEN_ALBEDO_TEXEL", std::to_string(scene.materials.size() * kMaterialTexels));
  }
  flag("PT_FX_ENVIRONMENT_IMAGE", fx.environmentImage);
  // Scenes with media take the volume integrator (also under --debug-pixel, whose printing it
  // leaves out). Scenes of diffuse and mirror surfaces without any of bsdf.h's materials, the
  // analytic lights, the pixel filters other than the box and the thin lens take the variant
  // without those (PT_NO_BSDF_MATERIALS: the same image).
  const Camera& camera = scene.params.camera;
  // SPPM's passes call BDPT's light start, which reads the analytic lights, as BDPT does.
  const bool full = all || scene.integrator != kIntegratorPath || fx.hasBsdfMaterials() ||
                    fx.shadingNormals || fx.deltaLights || fx.environment || fx.twoSidedEmitters ||
                    fx.sphereLights || fx.textures || fx.alphaCutouts || fx.bumpMaps ||
                    camera.filterType != kFilterBox || camera.lensRadius > 0.0f;
  if (fx.media) {
    text += "#define PT_VOLPATH\n";
  } else if (options.context.debugPrintf) {
    text += "#define PT_DEBUG_PRINTF\n";
  } else if (!full) {
    text += "#define PT_NO_BSDF_MATERIALS\n";
  }
  return text;
}

VulkanRenderStats renderVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                               Film& film) {
  if (scene.integrator == kIntegratorSppm) return renderSppmVulkan(scene, options, film);
  if (scene.integrator == kIntegratorBdpt) return renderBdptVulkan(scene, options, film);
  const auto start = std::chrono::steady_clock::now();
  const Camera& cam = scene.params.camera;
  PT_CHECK(film.width == int(cam.width) && film.height == int(cam.height));
  VulkanContext ctx(options.context);
  const Commands commands(ctx);
  const vk::raii::CommandBuffer& cmd = commands.cmd;

  // Upload the scene and build the pipeline.
  commands.begin();
  Buffer staging;
  const RenderBuffers buffers = uploadScene(ctx, scene, cmd, staging);
  const ComputeProgram program =
      makePathtraceProgram(ctx, pathtraceDefinitions(scene, options), buffers);
  const uint32_t debugPixel = options.debugPixelX >= 0 ? uint32_t(options.debugPixelY) * cam.width +
                                                             uint32_t(options.debugPixelX)
                                                       : ~0u;
  const PassRecorder passes(cmd, program, buffers, cam, debugPixel);

  // Warm up: drivers (lavapipe especially) compile the shader at its first dispatch, which
  // must not count as render time. The warm-up's output is cleared.
  passes.clearAccumulators();
  program.bind(cmd);
  passes.dispatch(0u, 1u, /*wholeImage=*/false);
  passes.copyLoopIterations();
  barrier(cmd, S::eComputeShader, A::eShaderWrite, S::eTransfer, A::eTransferWrite);
  passes.clearAccumulators();
  commands.submitAndWait(ctx);
  const uint32_t warmUpLoopIterations = passes.loopIterations();

  // Batches of samplesPerFold samples per pixel, summed in float on the device in the order of
  // their sample indices, then folded into the film. Batches cover the sample indices
  // [k * batch, (k + 1) * batch), aligned to absolute sample indices rather than to this
  // call's first sample: a render that is stopped and continued, or split into slices at
  // batch boundaries, sums every batch in float exactly as one uninterrupted render does, and
  // the film's exact sums do the rest. A batch goes to the device in passes (dispatches) of
  // samplesPerPass samples, or of as many as nextSamplesPerPass finds; the split does not
  // change the sums.
  VulkanRenderStats stats;
  stats.device = ctx.info().name;
  const DeviceTimer timer(ctx);
  const uint64_t batch = vulkanBatchSize(options);
  uint32_t perPass = options.samplesPerPass > 0
                         ? uint32_t(options.samplesPerPass)
                         : firstSamplesPerPass(film.pixelCount(), warmUpLoopIterations, batch);
  const uint32_t first = options.firstSample;
  const uint32_t end = first + uint32_t(options.spp);
  const size_t pixels = film.pixelCount();
  auto stopRequested = [&] {
    return options.stop && options.stop->load(std::memory_order_relaxed);
  };

  uint32_t next = first;               // the next sample index to dispatch
  uint32_t batchFirst = first;         // the first sample index of the batch under way
  const OpenBatch* carried = nullptr;  // an open batch handed in, until it is uploaded
  Buffer openStaging;
  if (options.openBatch && !options.openBatch->empty()) {
    carried = options.openBatch;
    PT_CHECK(carried->first + carried->count == first && carried->sum.size() == pixels &&
                 carried->invalid.size() == pixels,
             "an open batch must end where the render starts and match the film");
    batchFirst = carried->first;
  }
  for (;;) {
    const uint32_t batchEnd = uint32_t(std::min<uint64_t>(end, (batchFirst / batch + 1) * batch));
    // Dispatch by dispatch, each submitted on its own, so that a stop waits for one dispatch.
    bool stopped = false;
    while (next < batchEnd) {
      if (stopRequested()) {
        stopped = true;
        break;
      }
      commands.begin();
      if (carried) {
        uploadOpenBatch(ctx, cmd, buffers, *carried, openStaging);
        carried = nullptr;
      }
      program.bind(cmd);
      timer.start(cmd);
      const uint32_t count = std::min(perPass, batchEnd - next);
      passes.dispatch(next, count);
      timer.stop(cmd);
      passes.copyLoopIterations();
      commands.submitAndWait(ctx);
      const double seconds = timer.seconds();
      stats.seconds += seconds;
      const uint32_t loopIterations = passes.loopIterations();
      stats.maxLoopIterations = std::max(stats.maxLoopIterations, loopIterations);
      if (options.samplesPerPass <= 0) {
        perPass = nextSamplesPerPass(count, seconds, loopIterations, batch);
      }
      next += count;
      if (options.progress) options.progress(double(next - first) / double(options.spp));
    }
    const uint32_t batchSamples = next - batchFirst;
    const bool whole = next == (batchFirst / batch + 1) * batch;
    const bool keepOpen = stopped || (!whole && options.keepOpenBatch);
    if (batchSamples > 0) {
      if (carried) {  // nothing dispatched since it was handed in: it is still on the host
        if (keepOpen) {
          stats.open = *carried;
        } else {
          carried->foldInto(film);
        }
        carried = nullptr;
      } else {
        commands.begin();
        passes.readBack();
        commands.submitAndWait(ctx);
        if (keepOpen) {
          stats.open = readOpenBatch(buffers, batchFirst, batchSamples, pixels, stats);
        } else {
          foldIntoFilm(buffers, int(batchSamples), film, stats);
        }
      }
    }
    if (keepOpen) {
      stats.stopped = stopped;
      break;
    }
    batchFirst = next;
    if (options.checkpoint && batchSamples > 0) options.checkpoint(int(next - first));
    if (next >= end) break;
    if (stopRequested()) {
      stats.stopped = true;
      break;
    }
  }
  stats.samplesDone = int(next - first);
  stats.invalidSamples = film.totalInvalid() + stats.open.invalidTotal();
  stats.validationErrors = ctx.validationErrors();
  stats.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

KeyValues vulkanImageSettings(const VulkanRenderOptions& options) {
  // The shaders this build may run: their sources (which variant a scene compiles follows
  // from the scene), and whether they print (--debug-pixel).
  const uint64_t sources = shaderSourcesHash();
  const uint64_t shader = options.context.debugPrintf ? hashBytes("printf", 6, sources) : sources;
  return {{"samples_per_fold", std::to_string(vulkanBatchSize(options))},
          {"specialize", options.specialize ? "on" : "off"},
          {"shader", hexHash(shader)}};
}

uint32_t vulkanBatchSize(const VulkanRenderOptions& options) {
  return uint32_t(std::max(1, options.samplesPerFold));
}

}  // namespace pt
