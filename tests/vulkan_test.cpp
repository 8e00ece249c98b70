// The Vulkan backend on whatever device the machine has (lavapipe in CI), always with the
// validation layers on: it must agree with the CPU reference sample for sample.
#include <gtest/gtest.h>

#include <string>

#include "cpu/integrator.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/pbrt/pbrt_scene.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vulkan/backend.h"
#include "vulkan/device_limits.h"

namespace pt {
namespace {

using test::kConfigs;

SceneData prepareConfigScene(const std::string& config, int size) {
  return prepareScene(loadScene(kConfigs / config), RenderSettings{.width = size, .height = size});
}

TEST(Vulkan, CornellBoxMatchesCpuReference) {
  expectAgreement(renderBoth(prepareConfigScene("cornell-box.json", 64), 8));
}

// Where the backends part: a last bit of difference in a normal or a direction grows, over
// glossy bounces and thin triangles (tessellated spheres of a rough metal and glass in a room
// of a coated diffuse), into other paths. The shader rounds normalize as the CPU does
// (shared_types.h); with lavapipe's own normalize this scene's largest difference was 3.2e-5,
// with the CPU's rounding 4.8e-7 (what the transcendental functions still leave).
TEST(Vulkan, GlossyChainsAgreeToRoundingOnBothBackends) {
  const std::string text = R"(LookAt 0 1 -4  0 1 0  0 1 0
Camera "perspective" "float fov" 40
Sampler "independent" "integer pixelsamples" 16
Integrator "path" "integer maxdepth" 12
Film "rgb" "integer xresolution" 48 "integer yresolution" 48
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [20 20 20]
  Shape "trianglemesh" "point3 P" [-0.3 1.99 -0.3  0.3 1.99 -0.3  0.3 1.99 0.3  -0.3 1.99 0.3]
    "integer indices" [0 2 1 0 3 2]
AttributeEnd
Material "coateddiffuse" "rgb reflectance" [0.5 0.5 0.5] "float roughness" 0.05
Shape "trianglemesh" "point3 P" [-2 0 -5  2 0 -5  2 0 2  -2 0 2   -2 2 -5  2 2 -5  2 2 2  -2 2 2]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 3 7 0 7 4  1 5 6 1 6 2  3 2 6 3 6 7]
Material "conductor" "float roughness" 0.02 "spectrum eta" "metal-Ag-eta" "spectrum k" "metal-Ag-k"
AttributeBegin
  Translate -0.5 0.6 0.5
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  Translate 0.6 0.5 0.2
  Shape "sphere" "float radius" 0.4
AttributeEnd
Material "dielectric" "float eta" 1.5
AttributeBegin
  Translate 0 1.3 -0.5
  Shape "sphere" "float radius" 0.3
AttributeEnd
)";
  const SceneData data = prepareScene(loadPbrtSceneText(text, "glossy.pbrt"),
                                      RenderSettings{.width = 48, .height = 48});
  const Comparison cmp = renderBoth(data, 16);
  expectAgreement(cmp);
  EXPECT_LT(cmp.diff.maxAbsError, 1e-5);
}

TEST(Vulkan, MirrorVariantMatchesCpuReference) {
  const SceneData data = prepareConfigScene("cornell-mirror.json", 64);
  EXPECT_TRUE(data.effects.mirror);
  expectAgreement(renderBoth(data, 8));
}

TEST(Vulkan, BunnyMeshMatchesCpuReference) {
  // 69,666 triangles: deep BVH traversals on every bounce.
  expectAgreement(renderBoth(prepareConfigScene("bunny-box.json", 40), 4));
}

TEST(Vulkan, FastIntersectionMatchesCpuReference) {
  // The Moller-Trumbore knob (--intersection fast) on both backends, specialised and not.
  RenderSettings settings{.width = 48, .height = 48};
  settings.fastIntersection = true;
  const SceneData data = prepareScene(loadScene(kConfigs / "cornell-box.json"), settings);
  EXPECT_FALSE(data.effects.watertight);
  expectAgreement(renderBoth(data, 4));
  expectAgreement(renderBoth(data, 4, /*specialize=*/false));
}

TEST(Vulkan, BothSamplersMatchCpuReference) {
  // Independent and Owen-scrambled Sobol numbers are the same on both backends, with the
  // sampler specialised and (independent numbers; UnspecializedShaderGivesTheSameImage renders
  // the same scene's Sobol numbers so) decided at run time. The shader with every effect
  // compiled in takes lavapipe 5-15 s per pipeline, each render a pipeline of its own.
  for (uint sampler : {kSamplerIndependent, kSamplerSobol}) {
    SCOPED_TRACE("sampler " + std::to_string(sampler));
    RenderSettings settings{.width = 48, .height = 48};
    settings.sampler = int(sampler);
    const SceneData data = prepareScene(loadScene(kConfigs / "cornell-mirror.json"), settings);
    EXPECT_EQ(data.effects.sobol, sampler == kSamplerSobol);
    expectAgreement(renderBoth(data, 4));
    if (sampler == kSamplerIndependent) {
      expectAgreement(renderBoth(data, 4, /*specialize=*/false));
    }
  }
}

TEST(Vulkan, UnspecializedShaderGivesTheSameImage) {
  // Every effect compiled in and decided at run time must not change the result.
  const SceneData data = prepareConfigScene("cornell-mirror.json", 32);
  EXPECT_TRUE(data.effects.sobol);  // BothSamplersMatchCpuReference leaves this case here
  Film a(32, 32), b(32, 32);
  VulkanRenderOptions options = validatedOptions(4);
  const VulkanRenderStats s1 = renderVulkan(data, options, a);
  options.specialize = false;
  const VulkanRenderStats s2 = renderVulkan(data, options, b);
  EXPECT_EQ(s1.validationErrors + s2.validationErrors, 0u);
  // Every sample of both renders is in its image: none NaN or Inf, none cut short.
  EXPECT_EQ(s1.invalidSamples, 0u);
  EXPECT_EQ(s2.invalidSamples, 0u);
  EXPECT_EQ(s1.truncatedSamples, 0u);
  EXPECT_EQ(s2.truncatedSamples, 0u);
  const DiffStats d = diffImages(a.resolve(), b.resolve(), 1e-5);
  EXPECT_EQ(d.pixelsOverThreshold, 0u) << "max " << d.maxAbsError;
}

TEST(Vulkan, SamplesPerPassGiveTheSameBits) {
  // One sample per dispatch, five (in batches of 8: 5 + 3, 2 + 2), and as many as the backend
  // chooses as it goes: the same samples, added to each batch's float sum in the same order.
  const SceneData data = prepareConfigScene("cornell-box.json", 32);
  Film a(32, 32), b(32, 32), c(32, 32);
  VulkanRenderOptions options = validatedOptions(12);
  options.samplesPerFold = 8;
  options.samplesPerPass = 1;
  const VulkanRenderStats s1 = renderVulkan(data, options, a);
  options.samplesPerPass = 5;
  const VulkanRenderStats s2 = renderVulkan(data, options, b);
  options.samplesPerPass = 0;
  const VulkanRenderStats s3 = renderVulkan(data, options, c);
  EXPECT_EQ(s1.validationErrors + s2.validationErrors + s3.validationErrors, 0u);
  EXPECT_EQ(s1.invalidSamples + s2.invalidSamples + s3.invalidSamples, 0u);
  EXPECT_EQ(s1.rays, s2.rays);
  EXPECT_EQ(s1.rays, s3.rays);
  for (size_t i = 0; i < a.pixelCount(); ++i) {
    ASSERT_EQ(a.sampleCount[i], 12u);
    ASSERT_EQ(b.sampleCount[i], 12u);
    ASSERT_EQ(c.sampleCount[i], 12u);
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(a.sum(i)[k], b.sum(i)[k]) << "pixel " << i;
      ASSERT_EQ(a.sum(i)[k], c.sum(i)[k]) << "pixel " << i;
    }
  }
}

// A closed cube of perfect mirrors (reflectance 1, so Russian roulette never ends a path)
// with a small emitter inside, itself a mirror: nothing absorbs, every path bounces until the depth
// limit, so the shader's loop count grows with maxDepth.
SceneData mirrorBox(int maxDepth) {
  Scene scene;
  scene.materials = {Material{vec3(1.0f), kMaterialMirror, vec3(0.0f), 0},
                     Material{vec3(1.0f), kMaterialMirror, vec3(1.0f), 0}};
  test::addInwardCube(scene, {0, 0, 0, 0, 0, 0});
  const vec3 x(1, 0, 0), y(0, 1, 0);
  // The emitter: emits towards -z, reflects.
  test::addQuad(scene, vec3(0.1f, 0.0f, 0.5f), 0.05f * y, 0.05f * x, 1);
  for (uint i = 0; i < scene.triangles.size(); ++i) scene.triangles[i].primitive = i;
  scene.camera = CameraDesc{vec3(0.3f, 0.2f, -0.5f), vec3(0.2f, 0.1f, 1), y, 60.0f, 8, 8};
  scene.integrator.maxDepth = maxDepth;
  return prepareScene(scene, RenderSettings{});
}

TEST(VulkanLoopCap, DeepPathsAreCompleteAndMatchCpu) {
  const SceneData data = mirrorBox(64);
  const Comparison c = renderBoth(data, 2);
  EXPECT_EQ(c.gpu.truncatedSamples, 0u);
  EXPECT_GT(c.gpu.maxLoopIterations, 64u * 3u);  // the paths really are 64 bounces deep
  EXPECT_EQ(c.gpu.validationErrors, 0u);
  EXPECT_LE(double(c.diff.pixelsOverThreshold), 0.005 * double(c.diff.pixelCount));
}

TEST(VulkanLoopCap, PathsCutShortAreReportedNeverAddedSilently) {
  // 100,000 bounces need far more loop iterations than lavapipe's cap of 65,535: there
  // every sample must come back flagged as cut short and counted invalid, none added to
  // the image. A device without the cap completes them. Either way every sample is
  // accounted for.
  const SceneData data = mirrorBox(100000);
  Film film(8, 8);
  const VulkanRenderStats stats = renderVulkan(data, validatedOptions(1), film);
  EXPECT_EQ(stats.validationErrors, 0u);
  EXPECT_EQ(stats.invalidSamples, stats.truncatedSamples);
  for (size_t i = 0; i < film.sampleCount.size(); ++i) {
    EXPECT_EQ(film.sampleCount[i] + film.invalidCount[i], 1u) << "pixel " << i;
  }
  if (stats.device.find("llvmpipe") != std::string::npos) {
    EXPECT_EQ(stats.truncatedSamples, 64u);  // the cap is real on lavapipe, and caught
  } else {
    EXPECT_EQ(stats.truncatedSamples, 0u);
  }
}

TEST(VulkanLoopCap, ManySamplesPerPassCutShortAreReported) {
  // Lavapipe's cap counts every loop iteration of an invocation, so a dispatch of many
  // samples runs into it even with short paths: 500 samples of 64 bounces each. The
  // samples it cuts short, inside a path or in the sample loop itself, are counted and
  // left out; the rest are added. A device without the cap completes them all.
  const SceneData data = mirrorBox(64);
  VulkanRenderOptions options = validatedOptions(500);
  options.samplesPerPass = 500;
  options.samplesPerFold = 500;
  Film film(8, 8);
  const VulkanRenderStats stats = renderVulkan(data, options, film);
  EXPECT_EQ(stats.validationErrors, 0u);
  EXPECT_EQ(stats.invalidSamples, stats.truncatedSamples);
  for (size_t i = 0; i < film.sampleCount.size(); ++i) {
    EXPECT_EQ(film.sampleCount[i] + film.invalidCount[i], 500u) << "pixel " << i;
  }
  if (stats.device.find("llvmpipe") != std::string::npos) {
    EXPECT_GT(stats.truncatedSamples, 0u);
    uint64_t kept = 0;
    for (uint64_t n : film.sampleCount) kept += n;
    EXPECT_GT(kept, 0u);  // the samples before the cap were kept
  } else {
    EXPECT_EQ(stats.truncatedSamples, 0u);
  }
}

TEST(VulkanLimits, BuffersBeyondMaxStorageBufferRangeFailClearly) {
  // A 4096 x 4096 film needs a 256 MiB accumulation buffer; lavapipe allows 128 MiB per
  // storage buffer. A device with a larger limit renders it instead (skip there).
  SceneData data = prepareConfigScene("cornell-box.json", 4096);
  const DeviceLimits limits = queryDeviceLimits(ContextOptions{});
  if (limits.maxStorageBufferRange >= 4096ull * 4096ull * sizeof(AccumPixel)) {
    GTEST_SKIP() << "device allows " << limits.maxStorageBufferRange << " bytes";
  }
  Film film(4096, 4096);
  try {
    renderVulkan(data, validatedOptions(1), film);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("maxStorageBufferRange"), std::string::npos) << e.what();
  }
}

// Textures larger than the device can hold are refused before anything is allocated, in one
// line naming the texture buffer and the limit. (The image buffer is filled here directly, as
// a scene of that many texels would fill it.)
TEST(VulkanLimits, TexturesBeyondTheBufferLimitFailClearly) {
  SceneData data = prepareConfigScene("cornell-box.json", 16);
  const DeviceLimits limits = queryDeviceLimits(ContextOptions{});
  const uint64_t limit =
      std::min<uint64_t>(limits.maxStorageBufferRange, 16ull * limits.maxTexelBufferElements);
  if (limit >= (1ull << 31)) GTEST_SKIP() << "device allows " << limit << " bytes";
  data.materialTextures.assign(data.materials.size(), MaterialTextures{});
  for (MaterialTextures& t : data.materialTextures) {
    t = MaterialTextures{kNoTexture, kNoTexture, kNoTexture, kNoTexture, kNoTexture, kNoTexture,
                         kNoTexture, kNoTexture, 0u,         1.0f,       kNoTexture, kNoTexture};
  }
  data.uvs.assign(data.bvh.triangles.size(), TriangleUVs{});
  data.textureNodes.assign(1, TextureNode{});
  data.imageWords.assign(limit / sizeof(uint32_t) + 4, 0u);
  data.params.texturesPresent = 1u;
  data.effects.textures = true;
  Film film(16, 16);
  try {
    renderVulkan(data, validatedOptions(1), film);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("texture image buffer"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace pt
