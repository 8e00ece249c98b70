// The CPU reference integrator against closed-form answers and against itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cpu/integrator.h"
#include "render/prepare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

using test::kConfigs;

// A closed cube [-s, s]^3 whose faces all face inward, every face with material `faceMaterial`
// except those listed in `otherFaces` (face index 0..5), which get material `other`. (The +x,
// +y and +z faces are split along the other diagonal than test::addInwardCube's.)
Scene makeFurnace(float s, std::vector<Material> materials, uint faceMaterial = 0,
                  std::vector<int> otherFaces = {}, uint other = 0) {
  Scene scene;
  scene.materials = std::move(materials);
  const vec3 axes[3] = {vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1)};
  int face = 0;
  for (int a = 0; a < 3; ++a) {
    for (float side : {-1.0f, 1.0f}) {
      const vec3 inward = -side * axes[a];
      const vec3 u = s * axes[(a + 1) % 3];
      const vec3 v = s * cross(inward, axes[(a + 1) % 3]);  // cross(u, v) = s^2 inward
      const bool isOther =
          std::find(otherFaces.begin(), otherFaces.end(), face) != otherFaces.end();
      test::addQuad(scene, side * s * axes[a], u, v, isOther ? other : faceMaterial);
      ++face;
    }
  }
  for (uint i = 0; i < scene.triangles.size(); ++i) scene.triangles[i].primitive = i;
  scene.camera = CameraDesc{
      vec3(0.1f * s, -0.2f * s, 0.05f * s), vec3(1, 0.3f, 0.7f), vec3(0, 1, 0), 90.0f, 16, 16};
  scene.integrator.maxDepth = 100000;  // the closed form sums every bounce
  return scene;
}

struct Estimate {
  vec3 mean{0.0f};
  vec3 standardError{0.0f};
};

// Mean over all pixels and samples, with its standard error from the spread of pixel means
// (every pixel has the same expectation in a furnace).
Estimate estimateImageMean(const SceneData& data, int spp) {
  const Camera& cam = data.params.camera;
  std::vector<glm::dvec3> pixelMeans;
  uint64_t rays = 0;
  for (uint y = 0; y < cam.height; ++y) {
    for (uint x = 0; x < cam.width; ++x) {
      glm::dvec3 sum(0.0);
      for (int s = 0; s < spp; ++s)
        sum += glm::dvec3(sampleRadiance(data, uvec2(x, y), uint(s), rays));
      pixelMeans.push_back(sum / double(spp));
    }
  }
  glm::dvec3 mean(0.0), sq(0.0);
  for (const auto& m : pixelMeans) mean += m;
  mean /= double(pixelMeans.size());
  for (const auto& m : pixelMeans) sq += (m - mean) * (m - mean);
  const double n = double(pixelMeans.size());
  return Estimate{vec3(mean), vec3(sqrt(sq / (n - 1) / n))};
}

void expectWithin3Sigma(const Estimate& e, vec3 expected) {
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(e.standardError[c], 0.0f);
    EXPECT_NEAR(e.mean[c], expected[c], 3.0f * e.standardError[c])
        << "channel " << c << ", standard error " << e.standardError[c];
  }
}

// White furnace: every surface emits Le and reflects a fraction a, so L = Le / (1 - a).
TEST(CpuFurnace, DiffuseEnclosureMatchesClosedForm) {
  for (float albedo : {0.3f, 0.8f}) {
    for (uint strategy : {kStrategyMis, kStrategyNee, kStrategyBsdf}) {
      SCOPED_TRACE("albedo " + std::to_string(albedo) + " strategy " + std::to_string(strategy));
      const vec3 Le(1.0f, 0.5f, 0.25f);
      Scene scene = makeFurnace(1.0f, {Material{vec3(albedo), kMaterialDiffuse, Le, 0}});
      scene.integrator.strategy = strategy;
      const SceneData data = prepareScene(scene, RenderSettings{});
      expectWithin3Sigma(estimateImageMean(data, 64), Le / (1.0f - albedo));
    }
  }
}

TEST(CpuFurnace, MirrorsAndDiffuseMatchClosedForm) {
  // Two faces are mirrors of the same reflectance and emission: L = Le / (1 - a) still.
  const float a = 0.6f;
  const vec3 Le(1.0f);
  Scene scene = makeFurnace(
      1.0f, {Material{vec3(a), kMaterialDiffuse, Le, 0}, Material{vec3(a), kMaterialMirror, Le, 0}},
      0, {0, 3}, 1);
  const SceneData data = prepareScene(scene, RenderSettings{});
  EXPECT_TRUE(data.effects.mirror && data.effects.diffuse);
  expectWithin3Sigma(estimateImageMean(data, 64), Le / (1.0f - a));
}

TEST(CpuFurnace, MaxDepthTruncatesTheSeries) {
  // With maxDepth d and no Russian roulette the answer is Le (1 + a + ... + a^d).
  const float a = 0.5f;
  Scene scene = makeFurnace(1.0f, {Material{vec3(a), kMaterialDiffuse, vec3(1.0f), 0}});
  scene.integrator.russianRoulette = false;
  scene.integrator.maxDepth = 2;
  const SceneData data = prepareScene(scene, RenderSettings{});
  expectWithin3Sigma(estimateImageMean(data, 64), vec3(1.0f + a + a * a));
}

TEST(CpuCornell, DirectlyVisibleLightIsExactlyLe) {
  const Scene scene = loadScene(kConfigs / "cornell-box.json");
  const SceneData data = prepareScene(scene, RenderSettings{.spp = 4});
  const Camera& cam = data.params.camera;
  ASSERT_EQ(cam.width, 256u);
  Film film(256, 256);
  const RenderStats stats = renderCpu(data, test::cpuOptions(2, 4), film);
  EXPECT_EQ(stats.invalidSamples, 0u);
  EXPECT_GT(stats.rays, 256u * 256u * 4u);
  const Image image = film.resolve();
  // A pixel is fully covered when a 5 x 5 grid over it, corners included, sees the light.
  int covered = 0;
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) {
      bool all = true;
      for (int i = 0; i <= 4 && all; ++i) {
        for (int j = 0; j <= 4 && all; ++j) {
          const auto hit = closestHit(data.bvh, cameraRay(cam, vec2(x + 0.25f * i, y + 0.25f * j)));
          all = hit && data.bvh.triangles[hit->triangle].emitter != kNoEmitter;
        }
      }
      if (!all) continue;
      ++covered;
      EXPECT_EQ(image.at(x, y), vec3(17.0f, 12.0f, 4.0f)) << "pixel " << x << "," << y;
    }
  }
  // The scene description counts 340 fully covered pixels (4 x 4 sub-pixel grid).
  EXPECT_GE(covered, 320);
  EXPECT_LE(covered, 345);
}

TEST(CpuCornell, SameImageWithOneAndTwoThreads) {
  const Scene scene = loadScene(kConfigs / "cornell-mirror.json");
  const SceneData data = prepareScene(scene, RenderSettings{.width = 48, .height = 48});
  Film one(48, 48), two(48, 48);
  renderCpu(data, test::cpuOptions(1, 8), one);
  renderCpu(data, test::cpuOptions(2, 8), two);
  const Image a = one.resolve(), b = two.resolve();
  for (size_t i = 0; i < a.pixels.size(); ++i) ASSERT_EQ(a.pixels[i], b.pixels[i]) << i;
  // And a different seed gives a different image (the seed is really used).
  const SceneData other = prepareScene(scene, RenderSettings{.width = 48, .height = 48, .seed = 7});
  Film three(48, 48);
  renderCpu(other, test::cpuOptions(2, 8), three);
  EXPECT_NE(three.resolve().pixels, a.pixels);
}

TEST(CpuCornell, SamplingStrategiesAgree) {
  // NEE only, BSDF sampling only and MIS estimate the same integral: if MIS counted light
  // twice or dropped it, its mean would separate from the others by many standard errors.
  Scene scene = loadScene(kConfigs / "cornell-box.json");
  // The standard errors below come from each pixel's sample variance, which assumes
  // independent samples (stratified ones would make them too large, the test too lenient).
  scene.integrator.sampler = kSamplerIndependent;
  Estimate e[3];
  for (uint s : {kStrategyMis, kStrategyNee, kStrategyBsdf}) {
    scene.integrator.strategy = s;
    const SceneData data = prepareScene(scene, RenderSettings{.width = 24, .height = 24});
    // Pixel means differ across the image; the standard error of the image mean comes from
    // per-pixel variances instead.
    const Camera& cam = data.params.camera;
    constexpr int kSpp = 256;
    glm::dvec3 mean(0.0), var(0.0);
    uint64_t rays = 0;
    for (uint y = 0; y < cam.height; ++y) {
      for (uint x = 0; x < cam.width; ++x) {
        glm::dvec3 sum(0.0), sq(0.0);
        for (int i = 0; i < kSpp; ++i) {
          const glm::dvec3 L(sampleRadiance(data, uvec2(x, y), uint(i), rays));
          sum += L;
          sq += L * L;
        }
        const glm::dvec3 m = sum / double(kSpp);
        mean += m;
        var += (sq / double(kSpp) - m * m) / double(kSpp - 1);
      }
    }
    const double n = double(cam.width * cam.height);
    e[s] = Estimate{vec3(mean / n), vec3(sqrt(var) / n)};
  }
  for (uint s : {kStrategyNee, kStrategyBsdf}) {
    for (int c = 0; c < 3; ++c) {
      const float se = std::sqrt(e[0].standardError[c] * e[0].standardError[c] +
                                 e[s].standardError[c] * e[s].standardError[c]);
      EXPECT_NEAR(e[0].mean[c], e[s].mean[c], 3.0f * se) << "strategy " << s << " channel " << c;
    }
  }
}

}  // namespace
}  // namespace pt
