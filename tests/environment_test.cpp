// Environment images (shaders/environment.h): pbrt-v4's equal-area octahedral map and the
// lat-long map, the piecewise-constant distribution's samples against its density (Pearson's
// chi-square, tests/chi2.h), the density's integral, the furnace under a uniform image on both
// backends, light sampling, BSDF sampling and MIS converging to one image under a non-uniform
// one, and the pbrt and JSON readers' parameters and errors. Every image is written here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "common/numbers.h"
#include "cpu/integrator.h"
#include "environment.h"
#include "furnace_scene.h"
#include "render/environment_map.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/pbrt/pbrt_scene.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vulkan/device_limits.h"

namespace pt {
namespace {

// A sky that is nothing like uniform: a gradient down the rows, a tint across, and a bright
// patch, so that the distribution's rows and columns all differ.
Image makeSky(int width, int height) {
  Image image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float v = (float(y) + 0.5f) / float(height);
      const float u = (float(x) + 0.5f) / float(width);
      image.at(x, y) = vec3(0.2f + 1.5f * v, 0.3f + u, 0.5f + 0.5f * u * v);
    }
  }
  for (int y = height / 4; y < height / 4 + std::max(1, height / 8); ++y) {
    for (int x = width / 2; x < width / 2 + std::max(1, width / 8); ++x) {
      image.at(x, y) = vec3(8.0f, 7.0f, 6.0f);
    }
  }
  return image;
}

// A rotation of 30 degrees about (1, 2, 3) as the image frame's axes.
std::array<vec3, 3> rotatedFrame() {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1, 2, 3));
  const double c = std::cos(kPiD / 6.0), s = std::sin(kPiD / 6.0);
  std::array<vec3, 3> frame;
  for (int i = 0; i < 3; ++i) {
    glm::dvec3 e(0.0);
    e[i] = 1.0;
    frame[size_t(i)] =
        vec3(e * c + glm::cross(axis, e) * s + axis * (glm::dot(axis, e) * (1.0 - c)));
  }
  return frame;
}

// An environment map over `texels` (kept alive by the caller).
EnvironmentMap mapOf(const Image& image, uint mapping, const std::vector<vec4>& texels,
                     const std::array<vec3, 3>& frame) {
  return EnvironmentMap{frame[0],           frame[1], frame[2],     uint(image.width),
                        uint(image.height), mapping,  texels.data()};
}

TEST(EqualAreaMap, RoundTrip) {
  double worst = 0.0;
  for (int j = 0; j <= 64; ++j) {
    for (int i = 0; i <= 64; ++i) {
      const vec2 uv(float(i) / 64.0f, float(j) / 64.0f);
      const vec3 d = equalAreaSquareToSphere(uv);
      EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
      const vec2 back = equalAreaSphereToSquare(d);
      // The square's boundary folds onto itself (the edges' halves meet at -z): compare
      // directions there, points elsewhere.
      const bool edge = i == 0 || j == 0 || i == 64 || j == 64;
      const double err = edge ? double(glm::length(equalAreaSquareToSphere(back) - d))
                              : double(glm::length(back - uv));
      worst = std::max(worst, err);
    }
  }
  EXPECT_LT(worst, 2e-6);
  // Sphere -> square -> sphere for random directions.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int i = 0; i < 10000; ++i) {
    const vec3 d = sampleUniformSphere(vec2(uniform(rng), uniform(rng)));
    EXPECT_LT(glm::length(equalAreaSquareToSphere(equalAreaSphereToSquare(d)) - d), 2e-6f);
  }
  // Its landmarks: the centre is +z, the corners -z, the edges' midpoints the equator.
  EXPECT_EQ(equalAreaSquareToSphere(vec2(0.5f, 0.5f)), vec3(0, 0, 1));
  EXPECT_NEAR(equalAreaSquareToSphere(vec2(0.0f, 0.0f)).z, -1.0f, 1e-6f);
  EXPECT_NEAR(equalAreaSquareToSphere(vec2(1.0f, 0.5f)).x, 1.0f, 1e-6f);
}

// Pearson's chi-square test of directions drawn by `draw(u)` against the density `pdf`
// (chi2.h's grid, focused where pilot samples fall, as lights_test.cpp's lightChi2).
template <typename Draw, typename Pdf>
test::Chi2Result directionChi2(const Draw& draw, const Pdf& pdf, uint32_t seed) {
  constexpr int kSamples = 200000;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<glm::vec3> pilot;
  for (int i = 0; i < 2000; ++i) pilot.push_back(draw(vec2(uniform(rng), uniform(rng))));
  const test::SphereGrid grid = test::focusedGrid(pilot, 16, 32);
  std::vector<double> observed(size_t(grid.cellCount()), 0.0);
  for (int i = 0; i < kSamples; ++i) {
    observed[size_t(grid.cellOf(draw(vec2(uniform(rng), uniform(rng)))))] += 1.0;
  }
  return test::pearsonChi2(observed, test::expectedCounts(grid, pdf, kSamples));
}

TEST(EqualAreaMap, UniformSquareIsUniformSphere) {
  const auto draw = [](vec2 u) { return equalAreaSquareToSphere(u); };
  const test::Chi2Result good = directionChi2(
      draw, [](vec3) { return 1.0 / (4.0 * kPiD); }, 5u);
  EXPECT_GE(good.pValue, 1e-4) << "chi2 " << good.statistic << ", " << good.dof << " dof";
  // A density 20 % heavier towards +z is told apart.
  const auto leaning = [](vec3 w) { return (1.0 + 0.2 * double(w.z)) / (4.0 * kPiD); };
  const test::Chi2Result bad = directionChi2(draw, leaning, 5u);
  EXPECT_LT(bad.pValue, 1e-4) << "chi2 " << bad.statistic;
}

struct MappingCase {
  uint mapping;
  int width, height;
};
const MappingCase kMappings[] = {{kEnvironmentOctahedral, 16, 16}, {kEnvironmentLatLong, 24, 12}};

TEST(EnvironmentSampling, SamplesFollowTheirDensity) {
  for (const MappingCase& m : kMappings) {
    SCOPED_TRACE(m.mapping);
    // The complete distribution only: the compensated one is 0 over whole regions, whose
    // edges the grid's quadrature cannot follow (DensityIntegratesToOne and the renders check
    // it).
    for (bool compensated : {false}) {
      const Image sky = makeSky(m.width, m.height);
      const std::vector<vec4> texels = buildEnvironmentTexels(sky, m.mapping, compensated);
      const EnvironmentMap env = mapOf(sky, m.mapping, texels, rotatedFrame());
      const auto draw = [&](vec2 u) { return sampleEnvironmentLight(env, vec3(0.0f), u, 1.0f).wi; };
      const auto pdf = [&](vec3 w) { return double(environmentLookup(env, w).pdf); };
      const test::Chi2Result good = directionChi2(draw, pdf, 11u);
      EXPECT_GE(good.pValue, 1e-4) << "chi2 " << good.statistic << ", " << good.dof << " dof";
      // A density tilted 20 % is told apart; for the lat-long map, so is the density without
      // the map's sin theta (the Jacobian of the poles' shrinking texels).
      const auto tilted = [&](vec3 w) { return pdf(w) * (1.0 + 0.2 * double(w.x)); };
      const test::Chi2Result bad = directionChi2(draw, tilted, 11u);
      EXPECT_LT(bad.pValue, 1e-4) << "chi2 " << bad.statistic;
      if (m.mapping == kEnvironmentLatLong) {
        const auto noSin = [&](vec3 w) {
          const vec3 d = environmentFromWorld(env, w);
          return pdf(w) * std::sqrt(std::max(0.0, 1.0 - double(d.y) * double(d.y)));
        };
        const test::Chi2Result noJacobian = directionChi2(draw, noSin, 11u);
        EXPECT_LT(noJacobian.pValue, 1e-4) << "chi2 " << noJacobian.statistic;
      }
    }
  }
}

// The guide tables start each search near its answer; the bin found must be the one the whole
// CDF gives: the first whose end exceeds u (the last where none does). Checked against a linear
// scan, for the marginal and every row of an image whose sides are not powers of two, with
// rows and columns of weight 0 (empty bins), at random u and at both sides of every guide
// threshold k / G.
TEST(EnvironmentSampling, GuideTablesFindTheBinOfTheWholeSearch) {
  Image sky = makeSky(77, 21);
  for (int x = 0; x < sky.width; ++x) sky.at(x, 5) = vec3(0.0f);
  for (int y = 0; y < sky.height; ++y) {
    for (int x = 30; x < 45; ++x) sky.at(x, y) = vec3(0.0f);
  }
  const std::vector<vec4> texels = buildEnvironmentTexels(sky, kEnvironmentLatLong, false);
  const EnvironmentMap env = mapOf(sky, kEnvironmentLatLong, texels, rotatedFrame());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  int checked = 0;
  for (int row = -1; row < sky.height; ++row) {
    const uint count = row < 0 ? env.height : env.width;
    const auto scan = [&](float u) {
      for (uint i = 0; i < count; ++i) {
        if (environmentCdfEnd(env, row, i) > u) return i;
      }
      return count - 1;
    };
    std::vector<float> us;
    for (int i = 0; i < 200; ++i) us.push_back(uniform(rng));
    const uint g = environmentGuideSize(count);
    for (uint k = 0; k <= g; ++k) {
      const float t = float(k) / float(g);
      us.push_back(t);
      us.push_back(std::nextafter(t, 0.0f));
    }
    for (uint i = 0; i < count; ++i) us.push_back(environmentCdfEnd(env, row, i));
    for (float u : us) {
      if (!(u >= 0.0f && u < 1.0f)) continue;
      ASSERT_EQ(environmentFindBin(env, row, count, u), scan(u)) << "row " << row << " u " << u;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20 * 200);
  // 77 bins: guides of 16 entries (77 / 8 rounded up, to a power of two); 21 rows: 4.
  EXPECT_EQ(environmentGuideSize(77), 16u);
  EXPECT_EQ(environmentGuideSize(21), 4u);
  EXPECT_EQ(environmentGuideSize(8), 1u);
}

TEST(EnvironmentSampling, SampledPdfIsTheDirectionsPdfAndRadiance) {
  for (const MappingCase& m : kMappings) {
    SCOPED_TRACE(m.mapping);
    const Image sky = makeSky(m.width, m.height);
    const std::vector<vec4> texels = buildEnvironmentTexels(sky, m.mapping, false);
    const EnvironmentMap env = mapOf(sky, m.mapping, texels, rotatedFrame());
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    int differing = 0;
    constexpr int kCount = 20000;
    for (int i = 0; i < kCount; ++i) {
      const AnalyticLightSample s =
          sampleEnvironmentLight(env, vec3(1, 2, 3), vec2(uniform(rng), uniform(rng)), 5.0f);
      ASSERT_GT(s.pdf, 0.0f);
      EXPECT_FALSE(s.delta);
      EXPECT_NEAR(glm::length(s.wi), 1.0f, 1e-6f);
      EXPECT_LT(glm::length(s.target - (vec3(1, 2, 3) + 10.0f * s.wi)), 1e-5f);
      const EnvironmentLookup e = environmentLookup(env, s.wi);
      // The same texel but where the direction rounds across a texel's edge.
      if (!(std::fabs(e.pdf - s.pdf) <= 1e-4f * s.pdf) || e.Le != s.Li) ++differing;
    }
    EXPECT_LE(differing, kCount / 1000) << differing << " samples";
  }
}

TEST(EnvironmentSampling, DensityIntegratesToOne) {
  for (const MappingCase& m : kMappings) {
    for (bool compensated : {false, true}) {
      SCOPED_TRACE(m.mapping);
      const Image sky = makeSky(m.width, m.height);
      const std::vector<vec4> texels = buildEnvironmentTexels(sky, m.mapping, compensated);
      const EnvironmentMap env = mapOf(sky, m.mapping, texels, rotatedFrame());
      // The midpoint rule on a fine (theta, phi) grid: the density is piecewise constant, so
      // only the cells its texels' edges cross are off, and those errors largely cancel.
      constexpr int kTheta = 1000, kPhi = 2000;
      double total = 0.0;
      for (int i = 0; i < kTheta; ++i) {
        const double theta = kPiD * (i + 0.5) / kTheta;
        double ring = 0.0;
        for (int j = 0; j < kPhi; ++j) {
          const double phi = 2.0 * kPiD * (j + 0.5) / kPhi;
          const vec3 w(float(std::sin(theta) * std::cos(phi)),
                       float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
          ring += double(environmentLookup(env, w).pdf);
        }
        total += ring * std::sin(theta) * (kPiD / kTheta) * (2.0 * kPiD / kPhi);
      }
      EXPECT_NEAR(total, 1.0, 2e-3);
    }
  }
}

// ---- Rendering ------------------------------------------------------------------------------

// The cube of albedo 0.5 (furnace_scene.h).
std::string cubeScene(int size, int spp, const std::string& light) {
  return test::furnaceScene(size, spp, light);
}

TEST(EnvironmentRender, FurnaceUnderAUniformImageOnBothBackends) {
  const test::TempDir dir;
  Image white(8, 8);
  for (vec3& c : white.pixels) c = vec3(1.0f);
  writeImage(white, dir / "white.pfm");
  const std::string light =
      "AttributeBegin\nRotate 40 1 1 0\nLightSource \"infinite\" \"string filename\" "
      "[\"white.pfm\"]\nAttributeEnd\n";
  for (uint mapping : {kEnvironmentOctahedral, kEnvironmentLatLong}) {
    for (uint strategy : {kStrategyMis, kStrategyNee, kStrategyBsdf}) {
      // BSDF sampling alone reads only the radiance, the same for both maps here.
      if (mapping == kEnvironmentLatLong && strategy == kStrategyBsdf) continue;
      SCOPED_TRACE(std::to_string(mapping) + " " + std::to_string(strategy));
      Scene scene = loadPbrtScene(dir.write("f.pbrt", cubeScene(24, 64, light)));
      ASSERT_TRUE(scene.environment);
      if (mapping == kEnvironmentLatLong) {
        scene.environment->mapping = kEnvironmentLatLong;
        Image wide(16, 8);
        for (vec3& c : wide.pixels) c = vec3(1.0f);
        scene.environment->image = wide;
      }
      RenderSettings settings;
      settings.strategy = strategy;
      const SceneData data = prepareScene(std::move(scene), settings);
      EXPECT_TRUE(data.effects.environmentImage) << data.effects.toString();
      const Comparison cmp = renderBoth(data, data.spp);
      if (strategy == kStrategyMis) expectAgreement(cmp);
      for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
        test::expectFurnaceMean(*image, 0.012);
      }
    }
  }
}

// A diffuse plane and a cube under the non-uniform sky, rotated: the image `strategy` renders
// on the CPU, at `spp`.
SceneData skyScene(const test::TempDir& dir, uint mapping, uint strategy, int spp) {
  writeImage(makeSky(32, 32), dir / "sky.pfm");
  const std::string light =
      "AttributeBegin\nRotate 30 1 2 3\nLightSource \"infinite\" \"string filename\" "
      "[\"sky.pfm\"] \"float scale\" [0.8]\nAttributeEnd\n"
      "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.6 0.5 0.4]\n"
      "Shape \"trianglemesh\" \"point3 P\" [-4 -4 -1  4 -4 -1  4 4 -1  -4 4 -1]"
      " \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n";
  Scene scene = loadPbrtScene(dir.write("sky.pbrt", cubeScene(24, spp, light)));
  if (mapping == kEnvironmentLatLong) {
    // pbrt-v4's files take only square octahedral images: the lat-long one goes in here.
    scene.environment->mapping = mapping;
    scene.environment->image = makeSky(48, 24);
    for (vec3& c : scene.environment->image.pixels) c *= 0.8f;
  }
  RenderSettings settings;
  settings.strategy = strategy;
  return prepareScene(std::move(scene), settings);
}

TEST(EnvironmentRender, StrategiesConvergeToOneImage) {
  const test::TempDir dir;
  for (uint mapping : {kEnvironmentOctahedral, kEnvironmentLatLong}) {
    SCOPED_TRACE(mapping);
    // Block means of 6 x 6 pixels with their standard errors, per strategy.
    struct Blocks {
      std::vector<double> mean, variance;
    };
    const auto blocksOf = [&](uint strategy) {
      const SceneData data = skyScene(dir, mapping, strategy, 64);
      const Camera& cam = data.params.camera;
      Film film(int(cam.width), int(cam.height));
      renderCpu(data, test::cpuOptions(2, data.spp), film);
      const Image image = film.resolve();
      Blocks b;
      for (int by = 0; by < 4; ++by) {
        for (int bx = 0; bx < 4; ++bx) {
          double sum = 0.0, sumSquares = 0.0;
          for (int y = 6 * by; y < 6 * by + 6; ++y) {
            for (int x = 6 * bx; x < 6 * bx + 6; ++x) {
              const vec3 c = image.at(x, y);
              const double v = (double(c.x) + double(c.y) + double(c.z)) / 3.0;
              sum += v;
              sumSquares += v * v;
            }
          }
          const double mean = sum / 36.0;
          b.mean.push_back(mean);
          b.variance.push_back(std::max(0.0, sumSquares / 36.0 - mean * mean) / 36.0);
        }
      }
      return b;
    };
    const Blocks mis = blocksOf(kStrategyMis);
    const Blocks nee = blocksOf(kStrategyNee);
    const Blocks bsdf = blocksOf(kStrategyBsdf);
    // The pixels within a block differ in what they show, so their spread overstates the noise
    // of the block's mean: a generous bound still catches a pdf off by a fraction.
    for (size_t i = 0; i < mis.mean.size(); ++i) {
      for (const Blocks* other : {&nee, &bsdf}) {
        const double sigma = std::sqrt(mis.variance[i] + other->variance[i]);
        EXPECT_NEAR(other->mean[i], mis.mean[i], 4.0 * sigma + 0.01 * mis.mean[i]) << "block " << i;
      }
    }
  }
}

TEST(EnvironmentRender, BothBackendsAgreeUnderMis) {
  const test::TempDir dir;
  for (uint mapping : {kEnvironmentOctahedral, kEnvironmentLatLong}) {
    SCOPED_TRACE(mapping);
    const SceneData data = skyScene(dir, mapping, kStrategyMis, 8);
    EXPECT_NE(data.effects.toString().find("environment-image"), std::string::npos);
    expectAgreement(renderBoth(data, data.spp));
  }
}

TEST(EnvironmentRender, TooManyTexelsForTheDeviceIsOneLine) {
  // 1024 x 1024 texels, 256 of the marginal's, and the guide tables' (1024 + 1) x 129 floats
  // (129 entries each: 1024 / 8 + 1) in 33057 texels, against a limit one short.
  const size_t count = 1024u * 1024u + 256u + 33057u;
  EXPECT_EQ(environmentTexelCount(1024, 1024), count);
  EXPECT_NO_THROW(checkEnvironmentTexels("dev", count, "sky.exr", count));
  try {
    checkEnvironmentTexels("dev", count - 1, "sky.exr", count);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("sky.exr: ", 0), 0u) << what;
    EXPECT_NE(what.find("maxTexelBufferElements"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(EnvironmentRender, BlackImageIsNoLight) {
  const test::TempDir dir;
  writeImage(Image(4, 4), dir / "black.pfm");
  const SceneData data = prepareScene(
      loadPbrtScene(dir.write(
          "b.pbrt",
          cubeScene(8, 1, "LightSource \"infinite\" \"string filename\" \"black.pfm\"\n"))),
      RenderSettings{});
  EXPECT_EQ(data.params.environmentEmitter, kNoEmitter);
  EXPECT_FALSE(data.effects.environmentImage);
}

// The measurement behind kEnvironmentCompensationDefault (run by hand:
// pt_tests --gtest_also_run_disabled_tests --gtest_filter='*MeasureCompensation*'): relMSE of
// MIS renders at equal spp, with and without pbrt-v4's compensated distribution, against a
// long render, for a sky with a small bright sun and for a smooth sky, on diffuse and rough
// conductor surfaces.
TEST(EnvironmentRender, DISABLED_MeasureCompensation) {
  const test::TempDir dir;
  const std::string objects =
      "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.6 0.5 0.4]\n"
      "Shape \"trianglemesh\" \"point3 P\" [-4 -4 -1  4 -4 -1  4 4 -1  -4 4 -1]"
      " \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n"
      "AttributeBegin\nTranslate 1.8 -1.5 0\nMaterial \"conductor\" \"float roughness\" [0.3]\n"
      "Shape \"sphere\" \"float radius\" 0.8\nAttributeEnd\n";
  for (int sky = 0; sky < 2; ++sky) {
    Image image(64, 64);
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        const vec3 w = equalAreaSquareToSphere(vec2((x + 0.5f) / 64.0f, (y + 0.5f) / 64.0f));
        image.at(x, y) = vec3(0.3f + 0.4f * std::max(w.z, 0.0f), 0.4f + 0.3f * std::max(w.z, 0.0f),
                              0.6f + 0.2f * w.x);
      }
    }
    if (sky == 0) {
      for (int y = 20; y < 22; ++y) {
        for (int x = 40; x < 42; ++x) image.at(x, y) = vec3(2000.0f, 1800.0f, 1500.0f);
      }
    }
    writeImage(image, dir / "sky.pfm");
    const std::string light =
        "LightSource \"infinite\" \"string filename\" \"sky.pfm\"\n" + objects;
    const auto render = [&](bool compensated, int spp, uint32_t seed) {
      RenderSettings settings;
      settings.environmentCompensation = compensated;
      settings.spp = spp;
      settings.seed = seed;
      settings.sampler = kSamplerIndependent;
      const SceneData data =
          prepareScene(loadPbrtScene(dir.write("m.pbrt", cubeScene(48, spp, light))), settings);
      const Camera& cam = data.params.camera;
      Film film(int(cam.width), int(cam.height));
      renderCpu(data, test::cpuOptions(2, spp), film);
      return film.resolve();
    };
    const Image reference = render(false, 4096, 99u);
    for (bool compensated : {false, true}) {
      double relMse = 0.0;
      constexpr int kRuns = 8;
      for (uint32_t run = 0; run < kRuns; ++run) {
        relMse += diffImages(render(compensated, 16, run + 1), reference, 1e-3).relMse / kRuns;
      }
      std::printf("sky %s, compensated %d: relMSE %.5g (16 spp, mean of %d runs)\n",
                  sky == 0 ? "with sun" : "smooth", int(compensated), relMse, kRuns);
    }
  }
}

// ---- Readers --------------------------------------------------------------------------------

TEST(EnvironmentReaders, PbrtImageInfiniteLight) {
  const test::TempDir dir;
  Image sky(4, 4);
  for (int i = 0; i < 16; ++i) sky.pixels[size_t(i)] = vec3(float(i), 1.0f, -1.0f);
  writeImage(sky, dir / "sky.pfm");
  const Scene scene = loadPbrtScene(dir.write(
      "s.pbrt", cubeScene(8, 1,
                          "AttributeBegin\nRotate 90 1 0 0\nLightSource \"infinite\" \"string "
                          "filename\" \"sky.pfm\" \"float scale\" [2]\nAttributeEnd\n")));
  ASSERT_TRUE(scene.environment);
  EXPECT_TRUE(scene.lights.empty());
  const EnvironmentImage& env = *scene.environment;
  EXPECT_EQ(env.mapping, kEnvironmentOctahedral);
  EXPECT_EQ(env.image.at(3, 0), vec3(6.0f, 2.0f, 0.0f));  // scaled, negatives clamped
  // Rotate 90 about x: the light's z axis becomes the world's -y (x stays x, or -x through the
  // camera's mirror).
  EXPECT_NEAR(env.toWorld[2].y, -1.0f, 1e-6f);
  EXPECT_NEAR(std::fabs(env.toWorld[0].x), 1.0f, 1e-6f);
  // "illuminance": pbrt-v4's upper-hemisphere sum makes the map's illuminance the value given.
  Image white(8, 8);
  for (vec3& c : white.pixels) c = vec3(1.0f);
  writeImage(white, dir / "white.exr");
  const Scene lit = loadPbrtScene(
      dir.write("e.pbrt", cubeScene(8, 1,
                                    "LightSource \"infinite\" \"string filename\" \"white.exr\" "
                                    "\"float illuminance\" [3]\n")));
  double illuminance = 0.0;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      const vec3 w = equalAreaSquareToSphere(vec2((x + 0.5f) / 8.0f, (y + 0.5f) / 8.0f));
      if (w.z > 0.0f) illuminance += double(lit.environment->image.at(x, y).y) * double(w.z);
    }
  }
  EXPECT_NEAR(illuminance * 2.0 * kPiD / 64.0, 3.0, 1e-4);
}

TEST(EnvironmentReaders, PbrtErrorsNameFileLineColumn) {
  const test::TempDir dir;
  writeImage(Image(4, 2), dir / "wide.pfm");
  writeImage(Image(4, 4), dir / "sky.pfm");
  const auto errorOf = [&](const std::string& light) -> std::string {
    try {
      loadPbrtScene(dir.write("bad.pbrt", cubeScene(8, 1, light)));
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const auto expectError = [&](const std::string& light, const std::string& what) {
    const std::string e = errorOf(light);
    EXPECT_NE(e.find("bad.pbrt:9:"), std::string::npos) << e;
    EXPECT_NE(e.find(what), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  };
  expectError("LightSource \"infinite\" \"string filename\" \"sky.pfm\" \"rgb L\" [1 1 1]\n",
              "exclude each other");
  expectError("LightSource \"infinite\" \"string filename\" \"wide.pfm\"\n", "not square");
  expectError("LightSource \"infinite\" \"string filename\" \"wide.pfm\"\n", "wide.pfm");
  expectError("LightSource \"infinite\" \"string filename\" \"missing.exr\"\n", "missing.exr");
  // A portal is pbrt-v4's sampling aid only: a warning, an error under --strict.
  const std::string portal =
      "LightSource \"infinite\" \"string filename\" \"sky.pfm\" \"point3 portal\" "
      "[0 0 0  1 0 0  1 1 0  0 1 0]\n";
  const Scene warned = loadPbrtScene(dir.write("p.pbrt", cubeScene(8, 1, portal)));
  ASSERT_FALSE(warned.warnings.empty());
  EXPECT_NE(warned.warnings[0].find("portal"), std::string::npos);
  try {
    loadPbrtScene(dir / "p.pbrt", SceneLoadOptions{.strict = true});
    ADD_FAILURE() << "no error under --strict";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("portal"), std::string::npos);
  }
}

TEST(EnvironmentReaders, JsonEnvironmentImage) {
  const test::TempDir dir;
  writeImage(makeSky(8, 4), dir / "sky.exr");
  writeImage(makeSky(4, 4), dir / "square.pfm");
  const std::string start =
      R"({"materials": [{"name": "m", "type": "diffuse", "reflectance": [0.5, 0.5, 0.5]}],
          "shapes": [{"type": "triangles", "material": "m",
                      "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 2]]}],
          "lights": )";
  const Scene scene = loadScene(
      dir.write("ok.json", start + R"([{"type": "environment", "filename": "sky.exr", "scale": 2,
                              "rotate": {"axis": [0, 1, 0], "degrees": 90}}]})"));
  ASSERT_TRUE(scene.environment);
  EXPECT_EQ(scene.environment->mapping, kEnvironmentLatLong);
  EXPECT_NEAR(scene.environment->image.at(0, 0).x, 2.0f * makeSky(8, 4).at(0, 0).x, 1e-6f);
  // 90 degrees about +y takes x to -z.
  EXPECT_NEAR(scene.environment->toWorld[0].z, -1.0f, 1e-6f);
  const Scene octahedral =
      loadScene(dir.write("oct.json", start + R"([{"type": "environment", "filename": "square.pfm",
                               "mapping": "octahedral"}]})"));
  EXPECT_EQ(octahedral.environment->mapping, kEnvironmentOctahedral);

  const auto errorOf = [&](const std::string& lights) -> std::string {
    try {
      loadScene(dir.write("bad.json", start + lights + "}"));
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const auto expectError = [&](const std::string& lights, const std::string& what) {
    const std::string e = errorOf(lights);
    EXPECT_NE(e.find(what), std::string::npos) << e;
  };
  expectError(R"([{"type": "environment", "filename": "sky.exr", "radiance": [1, 1, 1]}])",
              "lights[0].radiance: unknown key");
  expectError(R"([{"type": "environment", "filename": "sky.exr", "mapping": "cube"}])",
              "lights[0].mapping: unknown mapping");
  expectError(R"([{"type": "environment", "filename": "sky.exr", "mapping": "octahedral"}])",
              "not square");
  expectError(R"([{"type": "environment", "filename": "missing.exr"}])", "lights[0].filename");
  expectError(R"([{"type": "environment", "filename": "sky.exr", "scale": -1}])",
              "lights[0].scale");
  expectError(R"([{"type": "environment", "filename": "sky.exr",
                   "rotate": {"axis": [0, 0, 0], "degrees": 3}}])",
              "lights[0].rotate.axis");
  expectError(R"([{"type": "environment", "filename": "sky.exr"},
                  {"type": "environment", "filename": "sky.exr"}])",
              "lights[1].filename: a second environment image");
}

}  // namespace
}  // namespace pt
