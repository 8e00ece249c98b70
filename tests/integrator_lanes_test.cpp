// sampleRadianceLanes, the CPU reference's paths several at a time, against sampleRadiance,
// whose steps it runs lane by lane: the same radiance bit for bit and the same ray count, on every
// instruction set Highway builds here, in settings that take each of its branches.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cpu/integrator.h"
#include "cpu/integrator_lanes.h"
#include "render/prepare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

using test::kConfigs;

struct Case {
  std::string config;
  RenderSettings settings;
  bool latLong = false;  // the environment image read as a lat-long map
  std::optional<PixelFilterDesc> filter;  // replaces the scene's pixel filter
};

// lanes-shading-normals.pbrt with its constant environment replaced by a rotated image
// (environment.h), written into `dir`, and its lat-long variant (scene files take only one).
std::string environmentImageScene(const test::TempDir& dir) {
  Image sky(16, 16);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      sky.at(x, y) = vec3(0.1f + 0.05f * float(x), 0.2f + 0.03f * float(y), 0.3f);
    }
  }
  sky.at(9, 4) = vec3(30.0f, 25.0f, 20.0f);
  writeImage(sky, dir / "sky.pfm");
  std::string text = test::readFile(std::filesystem::path(PT_SOURCE_DIR) /
                                    "tests/data/lanes-shading-normals.pbrt");
  const std::string constant = "LightSource \"infinite\" \"rgb L\" [0.2 0.25 0.3]\n";
  const size_t at = text.find(constant);
  EXPECT_NE(at, std::string::npos);
  text.replace(at, constant.size(),
               "AttributeBegin\nRotate 35 1 0.5 0\nLightSource \"infinite\" \"string filename\" "
               "\"sky.pfm\"\nAttributeEnd\n");
  return dir.write("lanes-environment.pbrt", text).string();
}

std::vector<Case> cases(const test::TempDir& dir) {
  const RenderSettings small{.width = 20, .height = 14};
  std::vector<Case> list;
  for (const char* config : {"cornell-box.json", "cornell-mirror.json", "bunny-box.json",
                             "cornell-materials.json", "veach-mis.json", "sun-and-sky.json"}) {
    list.push_back({config, small});
  }
  // Point, spot, distant and infinite lights with each strategy (the infinite light weighed by
  // MIS, taken at full weight, or not at all when rays leave the scene).
  for (uint strategy : {kStrategyNee, kStrategyBsdf}) {
    RenderSettings s = small;
    s.strategy = strategy;
    list.push_back({"sun-and-sky.json", s});
  }
  // Vertex normals (shading normals) on diffuse and conductor surfaces, with each strategy.
  const std::string normals =
      (std::filesystem::path(PT_SOURCE_DIR) / "tests/data/lanes-shading-normals.pbrt").string();
  for (uint strategy : {kStrategyMis, kStrategyNee, kStrategyBsdf}) {
    RenderSettings s = small;
    s.strategy = strategy;
    list.push_back({normals, s});
  }
  // Every light kind, textures, an alpha cut-out and a bump map, every material kind, with each
  // strategy; and the textured example scene.
  const std::string everything =
      (std::filesystem::path(PT_SOURCE_DIR) / "tests/data/lanes-every-feature.pbrt").string();
  for (uint strategy : {kStrategyMis, kStrategyNee, kStrategyBsdf}) {
    RenderSettings s = small;
    s.strategy = strategy;
    list.push_back({everything, s});
  }
  list.push_back({"textured-sky.json", small});
  // Participating media (the volume integrator, which the lanes run path by path).
  list.push_back({"fog-beam.json", small});
  list.push_back({"tinted-glass.json", small});
  // An environment image, octahedral (the pbrt file's) and lat-long, with each strategy.
  const std::string environment = environmentImageScene(dir);
  for (uint strategy : {kStrategyMis, kStrategyNee, kStrategyBsdf}) {
    RenderSettings s = small;
    s.strategy = strategy;
    list.push_back({environment, s});
    list.push_back({environment, s, true});
  }
  auto variant = [&](auto&& change) {
    RenderSettings s = small;
    change(s);
    list.push_back({"cornell-mirror.json", s});
  };
  variant([](RenderSettings& s) { s.strategy = kStrategyNee; });
  variant([](RenderSettings& s) { s.strategy = kStrategyBsdf; });
  variant([](RenderSettings& s) { s.sampler = kSamplerIndependent; });
  variant([](RenderSettings& s) { s.russianRoulette = false; });
  variant([](RenderSettings& s) { s.maxDepth = 0; });
  variant([](RenderSettings& s) { s.maxDepth = 2; });
  variant([](RenderSettings& s) { s.fastIntersection = true; });
  variant([](RenderSettings& s) { s.seed = 12345u; });
  // The pixel filters whose camera rays the lanes set up together: a wider box, the triangle
  // and the gaussian (pbrt-v4's default radii).
  list.push_back({"cornell-box.json", small, false, PixelFilterDesc{kFilterBox, 1.0f, 0.75f}});
  list.push_back({"cornell-box.json", small, false, PixelFilterDesc{kFilterTriangle, 2.0f, 2.0f}});
  list.push_back(
      {"cornell-box.json", small, false, PixelFilterDesc{kFilterGaussian, 1.5f, 1.5f, 0.5f}});
  return list;
}

uint32_t bitsOf(float x) {
  uint32_t b;
  std::memcpy(&b, &x, sizeof(b));
  return b;
}

TEST(CpuLanes, EqualsTheReferenceBitForBit) {
  const test::TempDir dir;
  for (const Case& c : cases(dir)) {
    SCOPED_TRACE(c.config + (c.latLong ? " (lat-long)" : "") +
                 (c.filter ? " filter " + std::to_string(c.filter->type) : ""));
    Scene scene = loadScene(kConfigs / c.config);
    if (c.latLong) scene.environment->mapping = kEnvironmentLatLong;
    if (c.filter) scene.camera.filter = *c.filter;
    const SceneData data = prepareScene(std::move(scene), c.settings);
    if (c.config.find("lanes-environment") != std::string::npos) {
      ASSERT_TRUE(data.effects.environmentImage) << data.effects.toString();
    }
    if (c.config.find("fog-beam") != std::string::npos ||
        c.config.find("tinted-glass") != std::string::npos) {
      ASSERT_TRUE(data.effects.media) << data.effects.toString();
    }
    if (c.config.find("shading-normals") != std::string::npos) {
      ASSERT_TRUE(data.effects.shadingNormals) << data.effects.toString();
    }
    if (c.config.find("every-feature") != std::string::npos) {
      const EffectSet& fx = data.effects;
      ASSERT_TRUE(fx.textures && fx.alphaCutouts && fx.bumpMaps && fx.twoSidedEmitters &&
                  fx.sphereLights && fx.deltaLights && fx.environment)
          << fx.toString();
    }
    const Camera& cam = data.params.camera;
    std::vector<uvec2> pixels;
    for (uint y = 0; y < cam.height; ++y) {
      for (uint x = 0; x < cam.width; ++x) pixels.push_back(uvec2(x, y));
    }
    for (uint32_t sample : {0u, 1u, 7u}) {
      std::vector<vec3> expected(pixels.size());
      uint64_t expectedRays = 0;
      for (size_t i = 0; i < pixels.size(); ++i) {
        expected[i] = sampleRadiance(data, pixels[i], sample, expectedRays);
      }
      test::forEachHighwayTarget(radianceLanesTargets(), [&] {
        // All pixels in one call, and a call for one pixel and for none.
        std::vector<vec3> out(pixels.size(), vec3(-1.0f));
        uint64_t rays = 0;
        sampleRadianceLanes(data, pixels.data(), pixels.size(), sample, out.data(), rays);
        EXPECT_EQ(rays, expectedRays) << "sample " << sample;
        int differing = 0;
        for (size_t i = 0; i < pixels.size(); ++i) {
          for (int k = 0; k < 3; ++k) {
            if (bitsOf(out[i][k]) != bitsOf(expected[i][k]) && ++differing <= 3) {
              ADD_FAILURE() << "sample " << sample << " pixel (" << pixels[i].x << ", "
                            << pixels[i].y << ") channel " << k << ": " << out[i][k]
                            << " against the reference's " << expected[i][k];
            }
          }
        }
        EXPECT_EQ(differing, 0) << "sample " << sample;
        vec3 one(-1.0f);
        uint64_t oneRays = 0;
        sampleRadianceLanes(data, &pixels[5], 1, sample, &one, oneRays);
        EXPECT_EQ(bitsOf(one.x), bitsOf(expected[5].x));
        sampleRadianceLanes(data, pixels.data(), 0, sample, &one, oneRays);
        EXPECT_EQ(bitsOf(one.x), bitsOf(expected[5].x));  // untouched
      });
    }
  }
}

}  // namespace
}  // namespace pt
