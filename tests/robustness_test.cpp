// Hard cases on both backends: energy conservation against closed forms, and degenerate
// geometry and light that must never produce NaN, Inf or unbounded pixels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>

#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

using test::addInwardCube;
using test::addQuad;
using test::kConfigs;

SceneData finish(Scene& scene, CameraDesc camera, int maxDepth = 100000) {
  for (uint i = 0; i < scene.triangles.size(); ++i) scene.triangles[i].primitive = i;
  scene.camera = camera;
  scene.integrator.maxDepth = maxDepth;
  return prepareScene(scene, RenderSettings{});
}

// Mean pixel value and its standard error, for images whose pixels share one expectation.
void expectImageMean(const Image& image, vec3 expected, const char* backend) {
  glm::dvec3 mean(0.0), sq(0.0);
  const double n = double(image.pixels.size());
  for (const vec3& p : image.pixels) mean += glm::dvec3(p) / n;
  for (const vec3& p : image.pixels) sq += (glm::dvec3(p) - mean) * (glm::dvec3(p) - mean);
  const glm::dvec3 se = sqrt(sq / (n - 1.0) / n);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(se[c], 0.0) << backend;
    EXPECT_NEAR(mean[c], expected[c], 3.0 * se[c])
        << backend << " channel " << c << " (standard error " << se[c] << ")";
  }
}

// White furnace: a closed cube whose every face emits Le and reflects a fraction a has
// radiance Le / (1 - a) everywhere, whatever mix of diffuse and mirror faces it has.
TEST(RobustFurnace, ClosedFormOnBothBackendsUpToAlbedo099) {
  for (float a : {0.5f, 0.9f, 0.99f}) {
    for (bool mirrors : {false, true}) {
      SCOPED_TRACE("albedo " + std::to_string(a) + (mirrors ? " with mirrors" : " diffuse"));
      const vec3 Le(1.0f, 0.5f, 0.25f);
      Scene scene;
      scene.materials = {Material{vec3(a), kMaterialDiffuse, Le, 0},
                         Material{vec3(a), kMaterialMirror, Le, 0}};
      const uint m = mirrors ? 1u : 0u;
      addInwardCube(scene, {0, m, 0, m, 0, 0});
      // Paths at albedo 0.99 average 100 bounces: fewer pixels, more samples each.
      const int size = a > 0.95f ? 8 : 16;
      const SceneData data = finish(scene, CameraDesc{vec3(0.1f, -0.2f, 0.05f), vec3(1, 0.3f, 0.7f),
                                                      vec3(0, 1, 0), 90.0f, size, size});
      const int spp = a > 0.95f ? 64 : 16;
      const Comparison c = renderBoth(data, spp);
      EXPECT_EQ(c.cpu.invalidSamples + c.gpu.invalidSamples, 0u);
      EXPECT_EQ(c.gpu.validationErrors, 0u);
      expectImageMean(c.cpuImage, Le / (1.0f - a), "cpu");
      expectImageMean(c.gpuImage, Le / (1.0f - a), "vulkan");
    }
  }
}

// Long renders: one pixel accumulated over a million samples equals the double-precision sum
// of the same samples. The device sums a batch's samples in float (2,000 here) and the host
// folds the float sums into its exact film after every batch; a plain float running sum of
// the same samples is shown to be far off, so the bound can tell.
TEST(RobustEnergy, MillionSamplePixelOnVulkanMatchesADoubleSum) {
  Scene scene;
  scene.materials = {Material{vec3(0.5f, 0.6f, 0.7f), kMaterialDiffuse, vec3(0.0f), 0},
                     Material{vec3(0.0f), kMaterialDiffuse, vec3(5.0f, 4.0f, 3.0f), 0}};
  const vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  addQuad(scene, -y, z, x, 0);               // a floor facing up
  addQuad(scene, y, 0.3f * x, 0.3f * z, 1);  // a small light above it, facing down
  // One pixel on the floor; direct light only (NEE and BSDF sampling with MIS), so each
  // sample is cheap and the samples still vary.
  const SceneData data =
      finish(scene, CameraDesc{vec3(0, 0.5f, -2), vec3(0, -1, 0), vec3(0, 1, 0), 10.0f, 1, 1}, 1);
  constexpr uint32_t kSamples = 1000000;

  glm::dvec3 exact(0.0);
  vec3 naive(0.0f);
  uint64_t rays = 0;
  for (uint32_t s = 0; s < kSamples; ++s) {
    const vec3 L = sampleRadiance(data, uvec2(0), s, rays);
    exact += glm::dvec3(L);
    naive += L;
  }
  VulkanRenderOptions options = validatedOptions(int(kSamples));
  options.samplesPerPass = 2000;
  options.samplesPerFold = 2000;
  Film film(1, 1);
  const VulkanRenderStats stats = renderVulkan(data, options, film);
  EXPECT_EQ(stats.validationErrors, 0u);
  EXPECT_EQ(stats.truncatedSamples, 0u);
  EXPECT_EQ(stats.invalidSamples, 0u);
  ASSERT_EQ(film.sampleCount[0], kSamples);
  for (int c = 0; c < 3; ++c) {
    ASSERT_GT(exact[c], 0.0);
    const double gpuError = std::abs(film.sum(0)[c] - exact[c]) / exact[c];
    const double floatError = std::abs(double(naive[c]) - exact[c]) / exact[c];
    std::printf("channel %d: relative error of the device sum %.3g, of a float sum %.3g\n", c,
                gpuError, floatError);
    EXPECT_LT(gpuError, 1e-6) << "channel " << c;
    EXPECT_GT(floatError, 1e-5) << "channel " << c;
  }
}

// Every pixel finite and below `bound`, no invalid samples, backends in agreement (unless
// the scene has coincident surfaces: which of two coplanar triangles a ray sees is decided
// by the last bit of two equal distances, which the backends may round apart).
void expectSaneAndAgreeing(const SceneData& data, int spp, float bound,
                           bool requireAgreement = true) {
  const Comparison c = renderBoth(data, spp);
  EXPECT_EQ(c.cpu.invalidSamples, 0u);
  EXPECT_EQ(c.gpu.invalidSamples, 0u);
  EXPECT_EQ(c.gpu.validationErrors, 0u);
  for (const Image* image : {&c.cpuImage, &c.gpuImage}) {
    for (const vec3& p : image->pixels) {
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
      ASSERT_LE(std::max(p.x, std::max(p.y, p.z)), bound);
      ASSERT_GE(std::min(p.x, std::min(p.y, p.z)), 0.0f);
    }
  }
  if (!requireAgreement) return;
  EXPECT_LE(double(c.diff.pixelsOverThreshold), 0.005 * double(c.diff.pixelCount))
      << "max " << c.diff.maxAbsError;
}

// A white box lit through its ceiling, with `extra` added by the caller.
SceneData litBox(const std::function<void(Scene&)>& extra) {
  Scene scene;
  scene.materials = {Material{vec3(0.7f), kMaterialDiffuse, vec3(0.0f), 0},
                     Material{vec3(0.2f, 0.6f, 0.2f), kMaterialDiffuse, vec3(0.0f), 0},
                     Material{vec3(0.0f), kMaterialDiffuse, vec3(4.0f), 0}};
  addInwardCube(scene, {0, 0, 0, 2, 0, 0});
  extra(scene);
  return finish(scene,
                CameraDesc{vec3(0, 0, -0.9f), vec3(0, -0.3f, 0), vec3(0, 1, 0), 80.0f, 24, 24}, 64);
}

TEST(RobustDegenerate, SliverAndZeroAreaEmittersOnBothBackends) {
  const SceneData data = litBox([](Scene& scene) {
    // A needle-thin sliver emitter, and a zero-area (collinear) one that must never be sampled.
    scene.triangles.push_back(
        Triangle{vec3(-0.5f, 0, 0), 2, vec3(0.5f, 0, 0), kNoEmitter, vec3(0.5f, 1e-6f, 0), 0});
    scene.triangles.push_back(
        Triangle{vec3(-0.5f, 0.2f, 0), 2, vec3(0.5f, 0.2f, 0), kNoEmitter, vec3(0, 0.2f, 0), 0});
  });
  for (const Emitter& e : data.emitters) {
    const Triangle& t = data.bvh.triangles[e.triangle];
    EXPECT_GT(length(cross(t.v1 - t.v0, t.v2 - t.v0)), 0.0f) << "zero-area emitter sampled";
  }
  expectSaneAndAgreeing(data, 8, 100.0f);
}

TEST(RobustDegenerate, CoplanarOverlappingSurfacesOnBothBackends) {
  const SceneData data = litBox([](Scene& scene) {
    addQuad(scene, vec3(0, -0.999f, 0), vec3(0, 0, 0.5f), vec3(0.5f, 0, 0), 1);
    addQuad(scene, vec3(0.2f, -0.999f, 0), vec3(0, 0, 0.5f), vec3(0.5f, 0, 0), 0);
  });
  expectSaneAndAgreeing(data, 8, 100.0f, /*requireAgreement=*/false);
}

TEST(RobustDegenerate, CameraInsideAClosedObjectOnBothBackends) {
  // Inside a closed sphere of diffuse triangles lit by nothing: black, never NaN.
  Scene scene;
  scene.materials = {Material{vec3(0.8f), kMaterialDiffuse, vec3(0.0f), 0},
                     Material{vec3(0.0f), kMaterialDiffuse, vec3(5.0f), 0}};
  for (Triangle t : test::makeSphere(vec3(0), 0.3f, 12, 16)) scene.triangles.push_back(t);
  addQuad(scene, vec3(0, 2, 0), vec3(0.5f, 0, 0), vec3(0, 0, 0.5f), 1);  // light outside
  const SceneData data = finish(
      scene, CameraDesc{vec3(0.01f, 0.02f, 0), vec3(0, 0, 1), vec3(0, 1, 0), 90, 16, 16}, 64);
  const Comparison c = renderBoth(data, 8);
  EXPECT_EQ(c.cpu.invalidSamples + c.gpu.invalidSamples, 0u);
  for (const vec3& p : c.gpuImage.pixels) EXPECT_EQ(p, vec3(0.0f));
  for (const vec3& p : c.cpuImage.pixels) EXPECT_EQ(p, vec3(0.0f));
}

TEST(RobustDegenerate, EmitterFacingAwayAndGrazingLightOnBothBackends) {
  // A floor lit by an emitter standing on it edge-on (cos at the light -> 0 along the floor)
  // and by one that faces away from everything (it lights nothing).
  Scene scene;
  scene.materials = {Material{vec3(0.7f), kMaterialDiffuse, vec3(0.0f), 0},
                     Material{vec3(0.0f), kMaterialDiffuse, vec3(10.0f), 0}};
  addQuad(scene, vec3(0), vec3(0, 0, 2), vec3(2, 0, 0), 0);  // floor, normal +y
  addQuad(scene, vec3(0, 0.25f, 0), vec3(0, 0.25f, 0), vec3(0.5f, 0, 0) * -1.0f, 1);  // upright
  addQuad(scene, vec3(0, 3, 0), vec3(0.5f, 0, 0), vec3(0, 0, 0.5f), 1);  // faces up, away
  const SceneData data =
      finish(scene, CameraDesc{vec3(0, 1.5f, -2.5f), vec3(0), vec3(0, 1, 0), 60, 24, 24}, 64);
  expectSaneAndAgreeing(data, 8, 100.0f);
}

TEST(RobustDegenerate, TwoFacingMirrorsAtMaxDepth64OnBothBackends) {
  Scene scene;
  scene.materials = {Material{vec3(1.0f), kMaterialMirror, vec3(0.0f), 0},
                     Material{vec3(0.5f), kMaterialDiffuse, vec3(1.0f), 0}};
  addQuad(scene, vec3(0, 0, 1), vec3(0, 3, 0), vec3(3, 0, 0), 0);   // faces -z
  addQuad(scene, vec3(0, 0, -1), vec3(3, 0, 0), vec3(0, 3, 0), 0);  // faces +z
  addQuad(scene, vec3(0, 2, 0), vec3(0.3f, 0, 0), vec3(0, 0, 0.3f), 1);
  const SceneData data = finish(
      scene, CameraDesc{vec3(0.1f, 0, 0.5f), vec3(0.2f, -0.2f, -1), vec3(0, 1, 0), 50, 16, 16}, 64);
  expectSaneAndAgreeing(data, 8, 100.0f);
}

// The Cornell box with every coordinate (geometry and camera) multiplied by `scale`.
SceneData scaledCornell(float scale, int size) {
  Scene scene = loadScene(kConfigs / "cornell-box.json");
  for (Triangle& t : scene.triangles) {
    t.v0 *= scale;
    t.v1 *= scale;
    t.v2 *= scale;
  }
  scene.camera.position *= scale;
  scene.camera.target *= scale;
  return prepareScene(scene, RenderSettings{.width = size, .height = size});
}

// Each backend's image of a transformed scene against its image of the original: the same
// acceptance as between the backends (at most 0.5 % of pixels over 1e-3, means within 1e-3).
// Measured: scaled, no pixel over (RMSE ~5e-8); moved to 1e5, 2 of 1024 pixels (paths that
// graze an edge moved by the input's rounding), means within 4e-4.
void expectSameImages(const Comparison& c, const Comparison& unit) {
  for (const auto& [image, reference] :
       {std::pair{&c.cpuImage, &unit.cpuImage}, std::pair{&c.gpuImage, &unit.gpuImage}}) {
    const DiffStats d = diffImages(*image, *reference, 1e-3);
    EXPECT_LE(double(d.pixelsOverThreshold), 0.005 * double(d.pixelCount))
        << "rmse " << d.rmse << " max " << d.maxAbsError;
    glm::dvec3 a(0.0), b(0.0);
    for (size_t i = 0; i < image->pixels.size(); ++i) {
      a += glm::dvec3(image->pixels[i]);
      b += glm::dvec3(reference->pixels[i]);
    }
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a[ch], b[ch], 1e-3 * b[ch]) << "channel " << ch;
  }
}

TEST(RobustScale, CornellBoxScaledBy1eMinus4And1e4RendersTheSameImageOnBothBackends) {
  // Ray offsets scale with the coordinates and the intersection test is watertight, so the
  // image must not depend on the scene's units: no acne, no light leaking at the blocks.
  constexpr int kSize = 32, kSpp = 16;
  const Comparison unit = renderBoth(scaledCornell(1.0f, kSize), kSpp);
  for (float scale : {1e-4f, 1e4f}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    const Comparison c = renderBoth(scaledCornell(scale, kSize), kSpp);
    EXPECT_EQ(c.cpu.invalidSamples + c.gpu.invalidSamples, 0u);
    expectSameImages(c, unit);
  }
}

TEST(RobustScale, CornellBoxFarFromTheOriginRendersTheSameImageOnBothBackends) {
  // Translated by 1e5 on every axis (coordinates rounded to float there, as a scene file
  // would be): the renderer moves it back next to the origin, exactly, so only the rounding
  // of the input geometry (at most 0.004 units in a 556-unit box) can change the image.
  constexpr int kSize = 32, kSpp = 16;
  Scene scene = loadScene(kConfigs / "cornell-box.json");
  const Comparison unit =
      renderBoth(prepareScene(scene, RenderSettings{.width = kSize, .height = kSize}), kSpp);
  const vec3 offset(1e5f);
  for (Triangle& t : scene.triangles) {
    t.v0 += offset;
    t.v1 += offset;
    t.v2 += offset;
  }
  scene.camera.position += offset;
  scene.camera.target += offset;
  const SceneData far = prepareScene(scene, RenderSettings{.width = kSize, .height = kSize});
  EXPECT_NE(far.shift, vec3(0.0f));
  const Comparison c = renderBoth(far, kSpp);
  EXPECT_EQ(c.cpu.invalidSamples + c.gpu.invalidSamples, 0u);
  expectSameImages(c, unit);
}

}  // namespace
}  // namespace pt
