// Stochastic progressive photon mapping (cpu/sppm.h, shaders/sppm_vertex.h): its image approaches
// the path tracer's as iterations add up and the radii shrink, the same seed gives the same bits on
// any number of threads, the pixel update is Hachisuka and Jensen's, the hash grid finds exactly
// the visible points within their radius, and the command line and the readers choose it and
// refuse what it cannot do.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cpu/integrator.h"
#include "cpu/sppm.h"
#include "cpu/sppm_grid.h"
#include "image/film_state.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/pbrt/pbrt_scene.h"
#include "sppm_vertex.h"
#include "test_util.h"
#include "vulkan/backend.h"

namespace pt {
namespace {

// The Cornell box at size x size pixels and the given depth, rendered by `integrator`; SPPM with
// the initial radius and photons per iteration given.
SceneData sppmTestScene(int size, int maxDepth, uint integrator, float radius = 1.0f,
                        int64_t photons = -1) {
  Scene scene = loadScene(test::kConfigs / "cornell-box.json");
  RenderSettings settings;
  settings.width = size;
  settings.height = size;
  settings.maxDepth = maxDepth;
  settings.integrator = integrator;
  SceneData data = prepareScene(std::move(scene), settings);
  data.sppm.radius = radius;
  data.sppm.photonsPerIteration = photons;
  return data;
}

Image renderImage(const SceneData& scene, int spp, int threads = 2) {
  Film film(int(scene.params.camera.width), int(scene.params.camera.height));
  CpuRenderOptions options;
  options.spp = spp;
  options.threads = threads;
  const CpuRenderStats stats = renderCpu(scene, options, film);
  EXPECT_EQ(stats.invalidSamples, 0u);
  EXPECT_EQ(stats.samplesDone, spp);
  return film.resolve();
}

double meanOf(const Image& image) {
  double sum = 0.0;
  for (const vec3& p : image.pixels) sum += double(p.x) + double(p.y) + double(p.z);
  return sum / (3.0 * double(image.pixels.size()));
}

double rmse(const Image& a, const Image& b) {
  return diffImages(a, b, 1e-3).rmse;
}

// ---- The hash grid ------------------------------------------------------------------------

TEST(SppmGrid, FindsExactlyThePointsWithinTheirRadius) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    // Points in a flat box (as visible points on a few walls are), radii spread over a decade,
    // a fifth of the pixels without a visible point.
    const size_t count = 1500;
    std::vector<vec3> points(count);
    std::vector<float> radii(count);
    std::vector<char> present(count);
    for (size_t i = 0; i < count; ++i) {
      points[i] = vec3(10.0f * unit(rng), 4.0f * unit(rng), trial == 2 ? 0.0f : 0.5f * unit(rng));
      radii[i] = 0.05f * std::pow(10.0f, unit(rng));
      present[i] = unit(rng) < 0.8f;
    }
    const SppmGrid grid(points, radii, present);
    ASSERT_FALSE(grid.empty());
    size_t found = 0;
    for (int q = 0; q < 4000; ++q) {
      // Queries in and around the points' bounds.
      const vec3 p(12.0f * unit(rng) - 1.0f, 6.0f * unit(rng) - 1.0f,
                   trial == 2 ? 0.0f : 1.0f * unit(rng) - 0.25f);
      std::vector<uint32_t> expected, got;
      for (size_t i = 0; i < count; ++i) {
        const vec3 d = points[i] - p;
        if (present[i] && dot(d, d) <= radii[i] * radii[i]) expected.push_back(uint32_t(i));
      }
      grid.forWithin(p, [&](uint32_t i) { got.push_back(i); });
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, expected) << "query (" << p.x << ", " << p.y << ", " << p.z << ")";
      found += got.size();
    }
    EXPECT_GT(found, 1000u);  // the queries do find points
  }
  // No visible point at all: an empty grid that finds nothing.
  const std::vector<vec3> none(3, vec3(0.0f));
  const SppmGrid empty(none, std::vector<float>(3, 1.0f), std::vector<char>(3, 0));
  EXPECT_TRUE(empty.empty());
  int calls = 0;
  empty.forWithin(vec3(0.0f), [&](uint32_t) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(SppmGrid, NextPrime) {
  EXPECT_EQ(nextPrime(0), 2u);
  EXPECT_EQ(nextPrime(2), 2u);
  EXPECT_EQ(nextPrime(24), 29u);
  EXPECT_EQ(nextPrime(65536), 65537u);
}

// ---- The pixel update ---------------------------------------------------------------------

TEST(SppmPixelUpdate, MatchesTheFormula) {
  SppmPixelState p = sppmStartPixel(2.0f);
  EXPECT_EQ(p.radius, 2.0f);
  EXPECT_EQ(p.n, 0.0f);
  // No photon: nothing changes.
  const SppmPixelState same = sppmUpdatePixel(p, vec3(5.0f), 0u);
  EXPECT_EQ(same.radius, p.radius);
  EXPECT_EQ(same.n, p.n);
  EXPECT_EQ(same.tau, p.tau);

  // N' = N + 2/3 M, r' = r sqrt(N' / (N + M)), tau' = (tau + phi) r'^2 / r^2; in double.
  double n = 0.0, r = 2.0;
  glm::dvec3 tau(0.0);
  const std::vector<std::pair<uint, vec3>> passes = {{6u, vec3(1.0f, 2.0f, 3.0f)},
                                                     {0u, vec3(0.0f)},
                                                     {3u, vec3(0.5f)},
                                                     {40u, vec3(7.0f, 0.0f, 1.0f)}};
  for (const auto& [m, phi] : passes) {
    p = sppmUpdatePixel(p, phi, m);
    if (m > 0) {
      const double nNew = n + 2.0 / 3.0 * m;
      const double rNew = r * std::sqrt(nNew / (n + m));
      tau = (tau + glm::dvec3(phi)) * (rNew * rNew) / (r * r);
      n = nNew;
      r = rNew;
    }
    EXPECT_NEAR(p.n, n, 1e-5 * n);
    EXPECT_NEAR(p.radius, r, 1e-6 * r);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.tau[c], tau[c], 1e-5 * (tau[c] + 1e-6));
  }
  // The first update: 6 photons keep 4, the radius shrinks by sqrt(4 / 6).
  EXPECT_NEAR(sppmUpdatePixel(sppmStartPixel(2.0f), vec3(0.0f), 6u).radius,
              2.0 * std::sqrt(4.0 / 6.0), 1e-6);
  // The estimate: Ld's mean plus tau / (iterations photons pi r^2).
  const vec3 L = sppmPixelRadiance(vec3(8.0f), p, 4.0f, 100.0f);
  EXPECT_NEAR(L.x, 2.0 + tau.x / (4.0 * 100.0 * M_PI * r * r), 1e-5);
}

TEST(SppmPhotons, CountAtTheHitsPbrtV4Counts) {
  // pbrt-v4's rule: a photon's first hit is direct light (the camera paths' light samples count
  // it); its hits 1 to maxDepth - 1 count, however deep the camera path's visible point is.
  EXPECT_FALSE(sppmPhotonCounts(0, 5));
  EXPECT_TRUE(sppmPhotonCounts(1, 5));
  EXPECT_TRUE(sppmPhotonCounts(4, 5));
  EXPECT_FALSE(sppmPhotonCounts(5, 5));
  EXPECT_FALSE(sppmPhotonCounts(1, 1));
}

TEST(SppmPixelUpdate, RenderedRadiiFollowThePhotonCounts) {
  // After a render, each pixel's N is 2/3 of the photons it kept, and its radius follows
  // from N alone where every iteration brought photons: r^2 = r0^2 prod N_k+1 / (N_k + M_k)
  // cannot be checked without the M_k, but r < r0 exactly where N > 0.
  const SceneData scene = sppmTestScene(12, 3, kIntegratorSppm, 20.0f, 4096);
  Film film(12, 12);
  CpuRenderOptions options;
  options.spp = 8;
  options.threads = 2;
  SppmPixels pixels;
  options.sppmPixels = &pixels;
  renderSppm(scene, options, film);
  ASSERT_EQ(pixels.size(), 144u);
  int withPhotons = 0;
  for (const SppmPixelRecord& p : pixels) {
    if (p.n > 0.0f) {
      ++withPhotons;
      EXPECT_LT(p.radius, 20.0f);
    } else {
      EXPECT_EQ(p.radius, 20.0f);
    }
  }
  EXPECT_GT(withPhotons, 100);
}

// ---- Rendering ----------------------------------------------------------------------------

TEST(SppmRender, SameBitsWithOneAndTwoThreadsAndAgain) {
  const SceneData scene = sppmTestScene(16, 4, kIntegratorSppm, 15.0f, 3000);
  const Image one = renderImage(scene, 3, 1);
  const Image two = renderImage(scene, 3, 2);
  const Image again = renderImage(scene, 3, 2);
  ASSERT_EQ(one.pixels.size(), two.pixels.size());
  EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(vec3)), 0);
  EXPECT_EQ(std::memcmp(two.pixels.data(), again.pixels.data(), two.pixels.size() * sizeof(vec3)),
            0);
  // Another seed, another image.
  SceneData other = scene;
  other.params.seed = 5;
  const Image reseeded = renderImage(other, 3, 2);
  EXPECT_NE(
      std::memcmp(two.pixels.data(), reseeded.pixels.data(), two.pixels.size() * sizeof(vec3)), 0);
}

TEST(SppmRender, AStopEndsAfterAWholeIteration) {
  // Stopped as its second iteration starts, the render holds the image of one iteration, bit
  // for bit.
  const SceneData scene = sppmTestScene(12, 3, kIntegratorSppm, 15.0f, 2000);
  const Image one = renderImage(scene, 1);
  Film film(12, 12);
  std::atomic<bool> stop{false};
  CpuRenderOptions options;
  options.spp = 5;
  options.threads = 2;
  options.stop = &stop;
  options.progress = [&](double done) {
    if (done > 0.0) stop = true;
  };
  const CpuRenderStats stats = renderSppm(scene, options, film);
  EXPECT_TRUE(stats.stopped);
  EXPECT_EQ(stats.samplesDone, 1);
  const Image stopped = film.resolve();
  EXPECT_EQ(std::memcmp(one.pixels.data(), stopped.pixels.data(), one.pixels.size() * sizeof(vec3)),
            0);
}

TEST(SppmRender, ContinuedFromItsStateGivesTheSameBits) {
  // Five iterations in one call, and two then three from the state the first call left: the
  // same bits. A checkpoint after each iteration finds the film holding that iteration's
  // estimate: after the second, the two-iteration image.
  const SceneData scene = sppmTestScene(12, 3, kIntegratorSppm, 15.0f, 2000);
  const Image five = renderImage(scene, 5);
  const Image two = renderImage(scene, 2);
  SppmPixels pixels;
  Film film(12, 12);
  CpuRenderOptions options;
  options.threads = 2;
  options.spp = 2;
  options.sppmPixels = &pixels;
  std::vector<Image> checkpoints;
  options.checkpoint = [&](int done) {
    EXPECT_EQ(done, int(checkpoints.size()) + 1);
    checkpoints.push_back(film.resolve());
  };
  EXPECT_EQ(renderSppm(scene, options, film).samplesDone, 2);
  ASSERT_EQ(checkpoints.size(), 2u);
  EXPECT_EQ(checkpoints[1].pixels, two.pixels);
  EXPECT_EQ(film.resolve().pixels, two.pixels);
  ASSERT_EQ(pixels.size(), 144u);
  options.firstSample = 2;
  options.spp = 3;
  options.checkpoint = nullptr;
  EXPECT_EQ(renderSppm(scene, options, film).samplesDone, 3);
  EXPECT_EQ(film.resolve().pixels, five.pixels);
  EXPECT_NE(five.pixels, two.pixels);
}

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// ---- The Vulkan backend (lavapipe here) -------------------------------------------------------

// A config at size x size pixels rendered by SPPM.
SceneData sppmSceneOf(const char* config, int size) {
  RenderSettings settings{.width = size, .height = size};
  settings.integrator = kIntegratorSppm;
  return prepareScene(loadScene(test::kConfigs / config), settings);
}

// Each pixel's photon flux is summed exactly on the device (64-bit atomics on ExactSum's fixed
// point) and rounded once on the host, as the CPU sums it: the backends differ only where their
// floats do (a path's last bits, a point on a cell's or a radius's edge), so the path tracer's
// rule holds, 99.5 % of pixels within 1e-3 and the means to 1e-3.
TEST(SppmVulkan, AgreesWithTheCpuReference) {
  // The Cornell box (diffuse: the visible points are first hits) at depth 4, and the water
  // caustic (a smooth dielectric: visible points seen through it, photons through it onto the
  // floor) at its depth of 8.
  const Comparison box = renderBoth(sppmTestScene(16, 4, kIntegratorSppm, 15.0f, 3000), 3);
  expectAgreement(box);
  SceneData water = sppmSceneOf("water-caustic.json", 16);
  water.sppm.radius = 0.1f;
  water.sppm.photonsPerIteration = 4000;
  EXPECT_TRUE(water.effects.dielectric);
  const Comparison caustic = renderBoth(water, 3);
  expectAgreement(caustic);
  // The Mitchell filter's negative lobes weigh some camera samples, and so some visible points'
  // throughput and photons' flux, negative: the device's sums borrow as well as carry.
  std::string pbrt = readText(test::kConfigs / "cornell-box.pbrt");
  const std::string boxFilter = "PixelFilter \"box\"";
  ASSERT_NE(pbrt.find(boxFilter), std::string::npos);
  pbrt.replace(pbrt.find(boxFilter), boxFilter.size(), "PixelFilter \"mitchell\"");
  RenderSettings settings{.width = 16, .height = 16, .maxDepth = 4};
  settings.integrator = kIntegratorSppm;
  SceneData mitchell =
      prepareScene(loadPbrtSceneText(pbrt, test::kConfigs / "mitchell.pbrt"), settings);
  mitchell.sppm.radius = 15.0f;
  mitchell.sppm.photonsPerIteration = 3000;
  EXPECT_EQ(mitchell.params.camera.filterType, kFilterMitchell);
  expectAgreement(renderBoth(mitchell, 3));
  // The photons bring much of the light here: without them (a radius that finds nothing) the
  // image is far darker, so the agreement above checks the photon pass.
  water.sppm.radius = 1e-6f;
  EXPECT_LT(meanOf(renderImage(water, 3)), 0.9 * meanOf(caustic.cpuImage));
}

// Photons from sphere lights on both backends.
TEST(SppmVulkan, SphereLightsAgreeWithTheCpuReference) {
  RenderSettings settings{.width = 16, .height = 16, .maxDepth = 4};
  settings.integrator = kIntegratorSppm;
  SceneData spheres = prepareScene(loadScene(test::kSphereLightsScene), settings);
  ASSERT_TRUE(spheres.effects.sphereLights);
  spheres.sppm.radius = 0.25f;
  spheres.sppm.photonsPerIteration = 3000;
  expectAgreement(renderBoth(spheres, 3));
}

TEST(SppmVulkan, PhotonPassSplitByHitsPastTheLoopCap) {
  // The water caustic at 64x64 with pbrt-v4's default radius of 1: a photon's buckets at all its
  // hits together take lavapipe's SIMD groups past the loop cap, so the pass is run again split
  // by hits, the same sums in another order of dispatches; the image still agrees.
  SceneData water = sppmSceneOf("water-caustic.json", 64);
  water.sppm.photonsPerIteration = 2000;
  EXPECT_EQ(water.sppm.radius, 1.0f);
  const Comparison cmp = renderBoth(water, 1);
  expectAgreement(cmp);
  if (cmp.gpu.device.find("llvmpipe") != std::string::npos) {
    EXPECT_EQ(cmp.gpu.splitPhotonPasses, 1u);
  }
}

TEST(SppmVulkan, SameBitsRunToRun) {
  // The photons' atomics arrive in any order; the exact sums make the image the same bits.
  SceneData scene = sppmTestScene(16, 4, kIntegratorSppm, 15.0f, 3000);
  auto render = [](const SceneData& s) {
    Film film(int(s.params.camera.width), int(s.params.camera.height));
    const VulkanRenderStats stats = renderVulkan(s, validatedOptions(3), film);
    EXPECT_EQ(stats.samplesDone, 3);
    EXPECT_EQ(stats.invalidSamples, 0u);
    EXPECT_EQ(stats.validationErrors, 0u);
    return film.resolve();
  };
  const Image a = render(scene);
  const Image b = render(scene);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(vec3)), 0);
  scene.params.seed = 5;
  const Image reseeded = render(scene);
  EXPECT_NE(std::memcmp(a.pixels.data(), reseeded.pixels.data(), a.pixels.size() * sizeof(vec3)),
            0);
}

TEST(SppmConverges, CornellBoxApproachesThePathTracer) {
  // A 16x16 Cornell box of depth 3: the path tracer's image at 4096 samples per pixel is the
  // reference. SPPM's error falls as iterations add up (its radii shrink, its photons grow),
  // and at 64 iterations its image's mean is within 2.5 % of the reference's (1.4 % above it
  // there; 0.1 % at 256 and 1024 iterations, measured).
  constexpr int kSize = 16, kDepth = 3;
  const Image reference = renderImage(sppmTestScene(kSize, kDepth, kIntegratorPath), 4096);
  const SceneData scene = sppmTestScene(kSize, kDepth, kIntegratorSppm, 25.0f, 4096);
  const Image few = renderImage(scene, 4);
  const Image many = renderImage(scene, 64);
  const double errorFew = rmse(few, reference);
  const double errorMany = rmse(many, reference);
  const double meanRef = meanOf(reference);
  std::printf("sppm vs path: rmse %.4f at 4 iterations, %.4f at 64; mean %.4f, %.4f vs %.4f\n",
              errorFew, errorMany, meanOf(few), meanOf(many), meanRef);
  EXPECT_LT(errorMany, 0.6 * errorFew);
  EXPECT_NEAR(meanOf(many), meanRef, 0.025 * meanRef);
}

// Sphere lights (tests/data/sphere-lights.pbrt, depth 3): the photons start on the analytic
// sphere, uniform by area with cosine-weighted directions (the camera paths' direct light is the
// path tracer's). As above, the error falls and at 64 iterations the mean is within 2.5 % of
// the path tracer's at 4096 samples per pixel.
TEST(SppmConverges, SphereLightsApproachThePathTracer) {
  constexpr int kSize = 16;
  auto scene = [](uint integrator) {
    RenderSettings settings{.width = kSize, .height = kSize, .maxDepth = 3};
    settings.integrator = integrator;
    SceneData data = prepareScene(loadScene(test::kSphereLightsScene), settings);
    EXPECT_TRUE(data.effects.sphereLights);
    data.sppm.radius = 0.25f;
    data.sppm.photonsPerIteration = 4096;
    return data;
  };
  const Image reference = renderImage(scene(kIntegratorPath), 4096);
  const SceneData sppm = scene(kIntegratorSppm);
  const Image few = renderImage(sppm, 4);
  const Image many = renderImage(sppm, 64);
  const double errorFew = rmse(few, reference);
  const double errorMany = rmse(many, reference);
  const double meanRef = meanOf(reference);
  std::printf(
      "sppm vs path, sphere lights: rmse %.4f at 4 iterations, %.4f at 64; mean %.4f, "
      "%.4f vs %.4f\n",
      errorFew, errorMany, meanOf(few), meanOf(many), meanRef);
  EXPECT_LT(errorMany, 0.6 * errorFew);
  EXPECT_NEAR(meanOf(many), meanRef, 0.025 * meanRef);
  // The photons bring a good part of the light: without them (a radius that finds nothing) the
  // image is darker, so the mean checks their start.
  SceneData none = sppm;
  none.sppm.radius = 1e-6f;
  EXPECT_LT(meanOf(renderImage(none, 4)), 0.95 * meanRef);
}

// ---- Choosing it, and what it refuses -----------------------------------------------------

// cornell-box.json with its "integrator" object replaced by `integrator`.
std::filesystem::path withIntegrator(const test::TempDir& dir, const std::string& name,
                                     const std::string& integrator) {
  std::string s = readText(test::kConfigs / "cornell-box.json");
  const size_t from = s.find("\"integrator\"");
  const size_t to = s.find('}', from);
  EXPECT_NE(from, std::string::npos);
  s.replace(from, to + 1 - from, "\"integrator\": " + integrator);
  const std::filesystem::path path = dir / name;
  std::ofstream(path) << s;
  return path;
}

TEST(SppmCli, ChosenRefusedAndChecked) {
  test::TempDir dir;
  const std::string box = (test::kConfigs / "cornell-box.json").string();
  const std::string small = " --spp 2 --width 12 --height 12 --out ";
  const test::PtResult r = test::runPt("render " + box + " --backend cpu --integrator sppm" +
                                       small + (dir / "a.exr").string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("integrator=sppm estimator=consistent(biased) photons_per_iteration=144 "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("spp=2 "), std::string::npos) << r.out;

  auto refused = [&](const std::string& args, const std::string& message) {
    const test::PtResult x = test::runPt("render " + args);
    EXPECT_EQ(x.status, 2) << args;
    EXPECT_NE(x.err.find(message), std::string::npos) << args << ": " << x.err;
    EXPECT_EQ(std::count(x.err.begin(), x.err.end(), '\n'), 1) << x.err;  // one line
  };
  refused((test::kConfigs / "fog-beam.json").string() + " --backend cpu --integrator sppm" + small +
              (dir / "d.exr").string(),
          "fog-beam.json: the sppm integrator does not render participating media");
  refused(box + " --backend cpu --integrator sppm --samples 0:1 --out " + (dir / "h.exr").string() +
              " --checkpoint " + (dir / "h.ptstate").string(),
          "--samples: the sppm integrator's pixels depend on every iteration before, so its "
          "render cannot be split or merged");
  refused(box + " --backend cpu --integrator sppm --task-index 0 --task-count 2" + small +
              (dir / "h.exr").string() + " --checkpoint " + (dir / "h.ptstate").string(),
          "--task-index: the sppm integrator's pixels depend on every iteration before");
  refused(box + " --backend cpu --sppm-radius 3" + small + (dir / "i.exr").string(),
          "--sppm-radius: a parameter of the sppm integrator (give --integrator sppm)");
  const test::PtResult converge =
      test::runPt("converge " + box + " --backend cpu --integrator sppm --reference " +
                  (dir / "ref.exr").string() + " --csv " + (dir / "c.csv").string());
  EXPECT_EQ(converge.status, 2);
  EXPECT_NE(converge.err.find("the sppm integrator's iterations cannot"), std::string::npos)
      << converge.err;

  // JSON: the type with its parameters, and bad ones named by file and field.
  const auto good = withIntegrator(
      dir, "good.json", R"({"type": "sppm", "spp": 2, "radius": 3.5, "photonsperiteration": 99})");
  const Scene scene = loadScene(good);
  EXPECT_EQ(scene.integrator.integrator, kIntegratorSppm);
  EXPECT_EQ(scene.integrator.sppm.radius, 3.5f);
  EXPECT_EQ(scene.integrator.sppm.photonsPerIteration, 99);
  EXPECT_EQ(scene.integrator.maxDepth, 5);  // pbrt-v4's default for sppm
  const test::PtResult json =
      test::runPt("render " + good.string() + " --backend cpu --width 8 --height 8 --out " +
                  (dir / "e.exr").string());
  EXPECT_EQ(json.status, 0) << json.err;
  EXPECT_NE(json.out.find("photons_per_iteration=99 radius=3.5 "), std::string::npos) << json.out;
  EXPECT_EQ(loadScene(withIntegrator(dir, "name.json", "\"sppm\"")).integrator.integrator,
            kIntegratorSppm);

  const struct {
    const char* integrator;
    const char* message;
  } bad[] = {
      {R"({"type": "sppm", "radius": 0})",
       "integrator.radius: the initial search radius must be "
       "positive"},
      {R"({"type": "sppm", "radius": -2})",
       "integrator.radius: the initial search radius must be "
       "positive"},
      {R"({"type": "sppm", "photonsperiteration": 0})",
       "integrator.photonsperiteration: must be positive, or -1"},
      {R"({"type": "sppm", "photonsperiteration": -5})", "integrator.photonsperiteration"},
      {R"({"type": "path", "radius": 2})",
       "integrator.radius: is a parameter of the sppm integrator"},
  };
  for (const auto& b : bad) {
    const auto path = withIntegrator(dir, "bad.json", b.integrator);
    const test::PtResult x =
        test::runPt("render " + path.string() + " --backend cpu --out " + (dir / "f.exr").string());
    EXPECT_EQ(x.status, 2) << b.integrator;
    EXPECT_NE(x.err.find("bad.json"), std::string::npos) << x.err;
    EXPECT_NE(x.err.find(b.message), std::string::npos) << b.integrator << ": " << x.err;
  }

  // pbrt-v4's Integrator "sppm" with its parameters.
  std::string pbrt = readText(test::kConfigs / "cornell-box.pbrt");
  const std::string from = "Integrator \"path\" \"integer maxdepth\" [ 64 ]";
  ASSERT_NE(pbrt.find(from), std::string::npos);
  std::string sppm = pbrt;
  sppm.replace(sppm.find(from), from.size(),
               "Integrator \"sppm\" \"float radius\" 4 \"integer photonsperiteration\" 500 "
               "\"integer seed\" 3");
  std::ofstream(dir / "sppm.pbrt") << sppm;
  const Scene fromPbrt = loadScene(dir / "sppm.pbrt");
  EXPECT_EQ(fromPbrt.integrator.integrator, kIntegratorSppm);
  EXPECT_EQ(fromPbrt.integrator.sppm.radius, 4.0f);
  EXPECT_EQ(fromPbrt.integrator.sppm.photonsPerIteration, 500);
  EXPECT_EQ(fromPbrt.integrator.seed, 3u);
  EXPECT_EQ(fromPbrt.integrator.maxDepth, 5);
  std::string zero = pbrt;
  zero.replace(zero.find(from), from.size(), "Integrator \"sppm\" \"float radius\" 0");
  std::ofstream(dir / "zero.pbrt") << zero;
  const test::PtResult x = test::runPt("render " + (dir / "zero.pbrt").string() +
                                       " --backend cpu --out " + (dir / "g.exr").string());
  EXPECT_EQ(x.status, 2);
  EXPECT_NE(x.err.find("zero.pbrt:"), std::string::npos) << x.err;
  EXPECT_NE(x.err.find("'radius' of Integrator"), std::string::npos) << x.err;
}

// A render stopped at a checkpoint and resumed to more iterations gives the one run's image bit
// for bit, from the state file's pixels; its state cannot be merged. `backend`: cpu or vulkan.
void expectResumedEqualsOneRun(const std::string& backend) {
  test::TempDir dir;
  const std::string render = "render " + (test::kConfigs / "cornell-box.json").string() +
                             " --backend " + backend + " --integrator sppm --width 12 --height 12";
  const std::string radius = " --sppm-radius 15";
  const test::PtResult one =
      test::runPt(render + radius + " --spp 4 --out " + (dir / "one.pfm").string());
  ASSERT_EQ(one.status, 0) << one.err;
  const std::string state = (dir / "s.ptstate").string();
  const test::PtResult first = test::runPt(render + radius + " --spp 2 --checkpoint " + state +
                                           " --out " + (dir / "two.pfm").string());
  ASSERT_EQ(first.status, 0) << first.err;
  const test::PtResult twoAgain =
      test::runPt(render + radius + " --spp 2 --out " + (dir / "two-again.pfm").string());
  ASSERT_EQ(twoAgain.status, 0) << twoAgain.err;
  EXPECT_EQ(test::readFile(dir / "two.pfm"), test::readFile(dir / "two-again.pfm"));
  const FilmState saved = readFilmState(state);
  EXPECT_EQ(saved.sppm.size(), 144u);
  ASSERT_EQ(saved.ranges.size(), 1u);
  EXPECT_EQ(saved.ranges[0], (SampleRange{0, 2}));
  const test::PtResult resumed = test::runPt(render + radius + " --spp 4 --resume " + state +
                                             " --out " + (dir / "four.pfm").string());
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("2 of 4 samples per pixel done"), std::string::npos) << resumed.err;
  EXPECT_EQ(test::readFile(dir / "one.pfm"), test::readFile(dir / "four.pfm"));
  EXPECT_NE(test::readFile(dir / "one.pfm"), test::readFile(dir / "two.pfm"));
  EXPECT_EQ(readFilmState(state).ranges, (std::vector<SampleRange>{{0, 4}}));
  // Another radius is another render.
  const test::PtResult other = test::runPt(render + " --sppm-radius 3 --spp 6 --resume " + state +
                                           " --out " + (dir / "x.pfm").string());
  EXPECT_EQ(other.status, 2);
  EXPECT_NE(other.err.find("sppm_radius"), std::string::npos) << other.err;
  const test::PtResult merge = test::runPt("merge " + state + " --out " + (dir / "m.exr").string());
  EXPECT_EQ(merge.status, 2);
  EXPECT_NE(merge.err.find("s.ptstate: holds an sppm render"), std::string::npos) << merge.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "m.exr"));
}

TEST(SppmCli, ResumedEqualsOneRun) {
  expectResumedEqualsOneRun("cpu");
}
TEST(SppmCli, ResumedEqualsOneRunOnVulkan) {
  expectResumedEqualsOneRun("vulkan");
}

// On the Vulkan backend (lavapipe here: the name keeps it out of the sanitized run, which hides
// the driver), named in the statistics line as on the CPU.
TEST(SppmCli, RendersOnVulkan) {
  test::TempDir dir;
  const std::string box = (test::kConfigs / "cornell-box.json").string();
  const std::string small = " --spp 2 --width 12 --height 12 --out ";
  const test::PtResult gpu = test::runPt("render " + box + " --backend vulkan --integrator sppm" +
                                         small + (dir / "b.exr").string());
  EXPECT_EQ(gpu.status, 0) << gpu.err;
  EXPECT_NE(gpu.out.find("backend=vulkan "), std::string::npos) << gpu.out;
  EXPECT_NE(gpu.out.find("integrator=sppm estimator=consistent(biased) photons_per_iteration=144 "),
            std::string::npos)
      << gpu.out;
  // Where a photon checks more visible points at one hit than lavapipe's loop cap allows (the
  // water caustic at 128x128 with pbrt-v4's default radius of 1, a sixteenth of the pool), the
  // render is given up after its first iteration in one line; a device without the cap renders
  // it.
  const test::PtResult capped = test::runPt(
      "render " + (test::kConfigs / "water-caustic.json").string() +
      " --backend vulkan --integrator sppm --spp 1 --sppm-photons 2000 --width 128 --height 128 "
      "--out " +
      (dir / "capped.exr").string());
  if (capped.status == 0) {
    EXPECT_EQ(capped.out.find("llvmpipe"), std::string::npos) << capped.out;
  } else {
    EXPECT_EQ(capped.status, 2) << capped.err;
    EXPECT_NE(capped.err.find("ran into the device's loop-iteration cap"), std::string::npos)
        << capped.err;
    EXPECT_EQ(std::count(capped.err.begin(), capped.err.end(), '\n'), 1) << capped.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "capped.exr"));
  }
}

}  // namespace
}  // namespace pt
