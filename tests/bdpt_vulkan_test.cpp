// Bidirectional path tracing on the Vulkan backend (vulkan/bdpt.h, shaders/bdpt.glsl) against
// the CPU reference (cpu/bdpt.h): the same strategies from the same headers, every sum exact on
// both sides, so the images differ only where the floats of a path do. On lavapipe here; the
// suite's name keeps it out of the sanitized run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cpu/bdpt.h"
#include "cpu/integrator.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/pbrt/pbrt_scene.h"
#include "test_util.h"
#include "vulkan/backend.h"

namespace pt {
namespace {

std::string readConfig(const std::string& name) {
  std::ifstream in(test::kConfigs / name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A scene at 16x16 pixels rendered by BDPT to depth 4.
SceneData bdptSceneOf(Scene scene) {
  RenderSettings settings{.width = 16, .height = 16, .maxDepth = 4};
  settings.integrator = kIntegratorBdpt;
  return prepareScene(std::move(scene), settings);
}

// Both backends' images of one strategy alone (unweighted), and the mean of each.
struct StrategyImages {
  Image cpu, gpu;
  double cpuMean = 0.0, gpuMean = 0.0;
  VulkanRenderStats stats;
};

StrategyImages renderStrategy(const SceneData& data, int s, int t, int spp) {
  const Camera& cam = data.params.camera;
  Film cpu(int(cam.width), int(cam.height)), gpu(int(cam.width), int(cam.height));
  CpuRenderOptions cpuOptions = test::cpuOptions(2, spp);
  cpuOptions.bdptStrategy = BdptStrategy{s, t};
  renderCpu(data, cpuOptions, cpu);
  VulkanRenderOptions options = validatedOptions(spp);
  options.bdptStrategy = BdptStrategy{s, t};
  StrategyImages r;
  r.stats = renderVulkan(data, options, gpu);
  r.cpu = cpu.resolve();
  r.gpu = gpu.resolve();
  for (size_t i = 0; i < r.cpu.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      r.cpuMean += r.cpu.pixels[i][c];
      r.gpuMean += r.gpu.pixels[i][c];
    }
  }
  return r;
}

// The path tracer's rule (render_compare.h): 99.5 % of pixels within 1e-3, the means to 1e-3.
// The Cornell box (diffuse).
TEST(BdptVulkan, CornellBoxAgreesWithTheCpuReference) {
  expectAgreement(renderBoth(bdptSceneOf(loadScene(test::kConfigs / "cornell-box.json")), 2));
}

// cornell-materials: smooth and rough conductors and a glass sphere (specular vertices, which
// MIS skips, and light through the dielectric).
TEST(BdptVulkan, SpecularMaterialsAgreeWithTheCpuReference) {
  const SceneData materials = bdptSceneOf(loadScene(test::kConfigs / "cornell-materials.json"));
  ASSERT_TRUE(materials.effects.dielectric && materials.effects.conductor);
  expectAgreement(renderBoth(materials, 2));
}

// The box lit by a point and a spot light as well: delta lights, which no camera subpath
// finds, and light subpaths that start at a point.
TEST(BdptVulkan, DeltaLightsAgreeWithTheCpuReference) {
  std::string json = readConfig("cornell-box.json");
  ASSERT_EQ(json.find("\"lights\""), std::string::npos);
  json.insert(json.find('{') + 1, R"(
    "lights": [
      {"type": "point", "position": [150, 400, 250], "intensity": [200000, 150000, 100000]},
      {"type": "spot", "position": [400, 500, 100], "target": [350, 0, 350],
       "intensity": [400000, 400000, 600000], "coneAngle": 30, "coneDeltaAngle": 10}],)");
  test::TempDir dir;
  const SceneData delta = bdptSceneOf(loadScene(dir.write("delta.json", json)));
  ASSERT_TRUE(delta.effects.deltaLights);
  const Comparison lit = renderBoth(delta, 2);
  expectAgreement(lit);
  // The delta lights add light the box's own does not: the image is brighter than the box's.
  const SceneData box = bdptSceneOf(loadScene(test::kConfigs / "cornell-box.json"));
  Film film(16, 16);
  renderCpu(box, test::cpuOptions(2, 2), film);
  const Image boxImage = film.resolve();
  vec3 boxMean(0.0f);
  for (const vec3& p : boxImage.pixels) boxMean += p / float(boxImage.pixels.size());
  for (int c = 0; c < 3; ++c) EXPECT_GT(lit.cpuMean[c], 1.5f * boxMean[c]) << c;
}

// A filter wider than a pixel spreads each light-tracing splat over several pixels, weighed
// by the filter's values (mitchell's negative lobes among them: the device's sums borrow).
TEST(BdptVulkan, SplatsUnderAWideFilterAgree) {
  std::string pbrt = readConfig("cornell-box.pbrt");
  const std::string boxFilter = "PixelFilter \"box\"";
  ASSERT_NE(pbrt.find(boxFilter), std::string::npos);
  pbrt.replace(pbrt.find(boxFilter), boxFilter.size(), "PixelFilter \"mitchell\"");
  const SceneData mitchell = bdptSceneOf(loadPbrtSceneText(pbrt, test::kConfigs / "mitchell.pbrt"));
  ASSERT_EQ(mitchell.params.camera.filterType, kFilterMitchell);
  expectAgreement(renderBoth(mitchell, 2));
}

// One strategy alone agrees with the CPU's and lights the image (the Cornell box's, or
// `scene`'s).
void expectStrategyAgrees(int s, int t, const std::filesystem::path& scene) {
  const SceneData data = bdptSceneOf(loadScene(scene));
  const StrategyImages r = renderStrategy(data, s, t, 2);
  EXPECT_EQ(r.stats.invalidSamples, 0u);
  EXPECT_EQ(r.stats.validationErrors, 0u);
  EXPECT_GT(r.cpuMean, 0.0);
  EXPECT_NEAR(r.gpuMean, r.cpuMean, 1e-3 * r.cpuMean);
  const DiffStats diff = diffImages(r.gpu, r.cpu, 1e-3);
  EXPECT_LE(double(diff.pixelsOverThreshold), 0.005 * double(diff.pixelCount))
      << "rmse " << diff.rmse;
}
void expectStrategyAgrees(int s, int t) {
  expectStrategyAgrees(s, t, test::kConfigs / "cornell-box.json");
}

// Two sphere lights (tests/data/sphere-lights.pbrt): light subpaths that start on the analytic
// sphere, strategy s = 1's samples of its cone, camera subpaths that find its triangles. Light
// tracing (2, 1) alone: only the light subpaths' starts and their splats.
TEST(BdptVulkan, SphereLightsAgreeWithTheCpuReference) {
  const SceneData spheres = bdptSceneOf(loadScene(test::kSphereLightsScene));
  ASSERT_TRUE(spheres.effects.sphereLights);
  expectAgreement(renderBoth(spheres, 2));
  expectStrategyAgrees(2, 1, test::kSphereLightsScene);
}

// Light tracing (2, 1): every bit of it splats (a device that dropped its splats would leave
// the image black).
TEST(BdptVulkan, LightTracingAloneAgrees) {
  expectStrategyAgrees(2, 1);
}

// (0, 3): camera subpaths that find the light after one bounce, in their own pixels.
TEST(BdptVulkan, CameraSubpathsAloneAgree) {
  expectStrategyAgrees(0, 3);
}

// The splats' atomics arrive in any order: the exact sums give the same bits every run.
TEST(BdptVulkan, SameBitsRunToRun) {
  const SceneData box = bdptSceneOf(loadScene(test::kConfigs / "cornell-box.json"));
  auto render = [&] {
    Film film(16, 16);
    const VulkanRenderStats stats = renderVulkan(box, validatedOptions(2), film);
    EXPECT_EQ(stats.samplesDone, 2);
    return film.resolve();
  };
  const Image a = render();
  const Image b = render();
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0);
}

// On the command line: bdpt renders with --backend vulkan, slices of its samples (any sample
// may start one: the device's film is exact) merge to the one-run image's bits, and a slice's
// checkpoint resumed to the whole gives them too.
TEST(BdptCli, SplitMergedAndResumedOnVulkan) {
  test::TempDir dir;
  const std::string render = "render " + (test::kConfigs / "cornell-box.json").string() +
                             " --backend vulkan --integrator bdpt --max-depth 4 --width 16 "
                             "--height 16 ";
  const test::PtResult one = test::runPt(render + "--spp 3 --out " + (dir / "one.exr").string());
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_NE(one.out.find("integrator=bdpt"), std::string::npos) << one.out;
  EXPECT_NE(one.out.find("backend=vulkan"), std::string::npos) << one.out;
  const test::PtResult b1 =
      test::runPt(render + "--samples 0:1 --checkpoint " + (dir / "b.ptstate").string());
  ASSERT_EQ(b1.status, 0) << b1.err;
  const test::PtResult b2 =
      test::runPt(render + "--samples 1:2 --checkpoint " + (dir / "c.ptstate").string());
  ASSERT_EQ(b2.status, 0) << b2.err;
  const test::PtResult merged =
      test::runPt("merge " + (dir / "b.ptstate").string() + " " + (dir / "c.ptstate").string() +
                  " --out " + (dir / "merged.exr").string());
  ASSERT_EQ(merged.status, 0) << merged.err;
  // The first slice's state continued to three samples.
  const test::PtResult resumed =
      test::runPt(render + "--samples 0:3 --resume " + (dir / "b.ptstate").string() + " --out " +
                  (dir / "resumed.exr").string());
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("1 of 3 samples per pixel done"), std::string::npos) << resumed.err;
  const Image x = readImage(dir / "one.exr");
  for (const char* name : {"merged.exr", "resumed.exr"}) {
    const Image y = readImage(dir / name);
    ASSERT_EQ(x.pixels.size(), y.pixels.size());
    EXPECT_EQ(std::memcmp(x.pixels.data(), y.pixels.data(), x.pixels.size() * sizeof(vec3)), 0)
        << name;
  }
}

// Lavapipe's silent loop cap (65,535 iterations an invocation) against one invocation's whole
// pixel sample: a closed box of white diffuse walls (reflectance 1, so Russian roulette ends no
// subpath early) to depth 32, under a gaussian filter 12 pixels wide (each light vertex splats
// over hundreds of pixels). There every sample runs into the cap: the render is given up in one
// line, exit status 2, and no image is written, since the cut samples' splats may be in the sums
// already. A device without the cap renders it; at depth 3 lavapipe does too.
TEST(BdptCli, SamplesPastTheLoopCapAreRefusedOnVulkan) {
  test::TempDir dir;
  const std::string box = R"(
Integrator "bdpt" "integer maxdepth" [ 32 ]
LookAt 0 0 -0.8  0 0 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Sampler "independent" "integer pixelsamples" [ 1 ]
PixelFilter "gaussian" "float xradius" [ 12 ] "float yradius" [ 12 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 1 1 1 ]
Shape "trianglemesh" "point3 P" [ -1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1 ]
  "integer indices" [ 0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2 ]
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
Shape "trianglemesh" "point3 P" [ -0.1 0.99 -0.1  0.1 0.99 -0.1  0.1 0.99 0.1  -0.1 0.99 0.1 ]
  "integer indices" [ 0 2 1 0 3 2 ]
AttributeEnd
)";
  const std::string scene = dir.write("box.pbrt", box).string();
  const test::PtResult deep =
      test::runPt("render " + scene + " --backend vulkan --out " + (dir / "deep.exr").string());
  if (deep.status == 0) {
    EXPECT_EQ(deep.out.find("llvmpipe"), std::string::npos) << deep.out;
  } else {
    EXPECT_EQ(deep.status, 2) << deep.err;
    EXPECT_NE(deep.err.find("256 pixel samples ran into the device's loop-iteration cap"),
              std::string::npos)
        << deep.err;
    // One line from the error on (a progress line may come before it).
    const size_t error = deep.err.find("bdpt on ");
    ASSERT_NE(error, std::string::npos) << deep.err;
    EXPECT_EQ(std::count(deep.err.begin() + std::ptrdiff_t(error), deep.err.end(), '\n'), 1)
        << deep.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "deep.exr"));
  }
  const test::PtResult shallow =
      test::runPt("render " + scene + " --backend vulkan --max-depth 3 --out " +
                  (dir / "shallow.exr").string());
  EXPECT_EQ(shallow.status, 0) << shallow.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "shallow.exr"));
}

}  // namespace
}  // namespace pt
