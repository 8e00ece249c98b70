// The bidirectional path tracer (cpu/bdpt.h, shaders/bdpt_*.h): it converges to the path
// tracer's image, each strategy alone converges to the part of the image it can sample (pbrt's
// own check), the MIS weights of a path's strategies sum to 1, and the same seed gives the same
// bits on any number of threads. The statistical bounds come from each estimate's variance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bdpt_connect.h"
#include "bdpt_vertex.h"
#include "cpu/bdpt.h"
#include "cpu/integrator.h"
#include "render/prepare.h"
#include "scene/camera_filter.h"
#include "scene/load_scene.h"
#include "test_util.h"

namespace pt {
namespace {

// A scene of configs/ at a small size, rendered with the given integrator and depth (and pixel
// filter, where one is given).
SceneData bdptTestScene(const std::string& config, int size, int maxDepth, uint integrator,
                        const std::optional<PixelFilterDesc>& filter = std::nullopt) {
  Scene scene = loadScene(test::kConfigs / config);
  if (filter) scene.camera.filter = *filter;
  RenderSettings settings;
  settings.width = size;
  settings.height = size;
  settings.maxDepth = maxDepth;
  settings.integrator = integrator;
  return prepareScene(std::move(scene), settings);
}

// tests/data/sphere-lights.pbrt (two sphere lights over a diffuse floor) at size x size pixels,
// rendered with the given integrator and depth.
SceneData sphereLightsScene(int size, int maxDepth, uint integrator) {
  RenderSettings settings;
  settings.width = size;
  settings.height = size;
  settings.maxDepth = maxDepth;
  settings.integrator = integrator;
  SceneData data = prepareScene(loadScene(test::kSphereLightsScene), settings);
  EXPECT_TRUE(data.effects.sphereLights);
  return data;
}

// The image cut into square blocks, each estimate the block's summed pixel values: per pixel
// sample (every one an independent draw of the whole estimator), the sum of what it adds to
// each block, and over the samples the mean and variance of those sums. With `stripes`, each
// block has two more estimates, its pixels summed with the signs of alternate columns,
// (-1)^x, and of alternate rows, (-1)^y: the image's finest detail, which a pixel filter
// blurs (a step between two pixels adds twice its height times the share of the filter past
// the pixel's edge to the stripes of a block that it crosses).
struct BdptBlockStats {
  int blockSize = 0, blocksX = 0, blocksY = 0, layers = 1;
  double samples = 0.0;
  std::vector<double> sum, sumSquares;  // per block (and stripe layer), the whole image last
  std::map<int, double> current;        // this sample's adds, by block

  BdptBlockStats(int width, int height, int block, bool stripes = false)
      : blockSize(block),
        blocksX((width + block - 1) / block),
        blocksY((height + block - 1) / block),
        layers(stripes ? 3 : 1) {
    sum.assign(size_t(blocks() + 1), 0.0);
    sumSquares = sum;
  }
  // The estimates before the whole image's.
  int blocks() const { return blocksX * blocksY * layers; }
  std::string name(int k) const {
    if (k == blocks()) return "image";
    const int layer = k / (blocksX * blocksY);
    return std::string(layer == 0   ? "block "
                       : layer == 1 ? "column stripes of block "
                                    : "row stripes of block ") +
           std::to_string(k % (blocksX * blocksY));
  }
  void add(int x, int y, double v) {
    const int b = (y / blockSize) * blocksX + x / blockSize;
    current[b] += v;
    if (layers == 3) {
      current[blocksX * blocksY + b] += (x & 1) != 0 ? -v : v;
      current[2 * blocksX * blocksY + b] += (y & 1) != 0 ? -v : v;
    }
    current[blocks()] += v;
  }
  void endSample() {
    for (const auto& [b, v] : current) {
      sum[size_t(b)] += v;
      sumSquares[size_t(b)] += v * v;
    }
    current.clear();
    samples += 1.0;
  }
  // Block b's estimate (pixel values summed: each pixel's samples averaged over spp) and its
  // standard error, for `pixels` pixel samples per pass (the image's pixel count).
  double estimate(int b, double pixels) const { return sum[size_t(b)] / samples * pixels; }
  double standardError(int b, double pixels) const {
    const double mean = sum[size_t(b)] / samples;
    const double variance = std::max(0.0, sumSquares[size_t(b)] / samples - mean * mean);
    return std::sqrt(variance / samples) * pixels;
  }
};

// How the tests spread a splat: as the renderer does (BdptSplatter), or (a deliberate error,
// for the test that the checks catch it) whole into the one pixel it lands in, as a box of one
// pixel would, whatever the filter.
enum class BdptSplats { kFilter, kOnePixel };

// Adds a BDPT contribution of pixel (x, y) (a splat: where it lands, spread by `splats`) to
// stats, channel-summed.
void addBdptContribution(const BdptSplatter& splatter, int x, int y, const BdptContribution& c,
                         vec3 value, BdptBlockStats& stats,
                         BdptSplats splats = BdptSplats::kFilter) {
  const double v = double(value.x) + double(value.y) + double(value.z);
  if (!c.splat) {
    stats.add(x, y, v);
    return;
  }
  if (splats == BdptSplats::kFilter) {
    splatter.forPixels(c.filmPoint, [&](int sx, int sy, float w) { stats.add(sx, sy, v * w); });
    return;
  }
  const Camera& cam = splatter.cam;
  const int fx = int(std::floor(c.filmPoint.x)) - int(cam.cropX);
  const int fy = int(std::floor(c.filmPoint.y)) - int(cam.cropY);
  if (fx >= 0 && fy >= 0 && fx < int(cam.width) && fy < int(cam.height)) stats.add(fx, fy, v);
}

// The blocks (and the whole image, last) where two independent estimates disagree: by more than
// kSigmas standard errors of their difference (4.5: a chance below 1e-5 per block that a
// correct renderer fails). `report` adds a test failure for each.
constexpr double kBdptSigmas = 4.5;
int blocksThatDisagree(const BdptBlockStats& a, const BdptBlockStats& b, double pixels,
                       const std::string& what, bool report) {
  int failed = 0;
  for (int k = 0; k <= a.blocks(); ++k) {
    const double diff = a.estimate(k, pixels) - b.estimate(k, pixels);
    const double se = std::hypot(a.standardError(k, pixels), b.standardError(k, pixels));
    if (!(std::abs(diff) <= kBdptSigmas * se)) {
      ++failed;
      if (!report) continue;
      ADD_FAILURE() << what << ": " << a.name(k) << " " << a.estimate(k, pixels) << " vs "
                    << b.estimate(k, pixels) << ", standard error " << se;
    }
  }
  return failed;
}

// Asserts that two independent estimates agree in every block and in the whole image.
void expectBlocksAgree(const BdptBlockStats& a, const BdptBlockStats& b, double pixels,
                       const std::string& what) {
  EXPECT_EQ(blocksThatDisagree(a, b, pixels, what, /*report=*/true), 0) << what;
}

// The path tracer's and BDPT's block estimates of a scene of size x size pixels, prepared for
// each (pt, bd); BDPT's splats spread by `splats`.
void renderBothWays(const SceneData& pt, const SceneData& bd, int size, int sppPath, int sppBdpt,
                    BdptBlockStats& path, BdptBlockStats& bdpt,
                    BdptSplats splats = BdptSplats::kFilter) {
  uint64_t rays = 0;
  for (int s = 0; s < sppPath; ++s) {
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const vec3 L = sampleRadiance(pt, uvec2(x, y), uint(s), rays);
        path.add(x, y, double(L.x) + double(L.y) + double(L.z));
        path.endSample();
      }
    }
  }
  const BdptSplatter splatter(bd.params.camera);
  for (int s = 0; s < sppBdpt; ++s) {
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        bdptSample(bd, uvec2(x, y), uint(s), BdptStrategy{}, rays, [&](const BdptContribution& c) {
          addBdptContribution(splatter, x, y, c, c.L * c.weight, bdpt, splats);
        });
        bdpt.endSample();
      }
    }
  }
}

// The same for a scene of configs/ (with pixel filter `filter`, where one is given).
void renderBothWays(const std::string& config, int size, int maxDepth, int sppPath, int sppBdpt,
                    BdptBlockStats& path, BdptBlockStats& bdpt,
                    const std::optional<PixelFilterDesc>& filter = std::nullopt,
                    BdptSplats splats = BdptSplats::kFilter) {
  renderBothWays(bdptTestScene(config, size, maxDepth, kIntegratorPath, filter),
                 bdptTestScene(config, size, maxDepth, kIntegratorBdpt, filter), size, sppPath,
                 sppBdpt, path, bdpt, splats);
}

TEST(BdptConverges, CornellBoxMatchesThePathTracer) {
  constexpr int kSize = 24;
  BdptBlockStats path(kSize, kSize, 8), bdpt(kSize, kSize, 8);
  renderBothWays("cornell-box.json", kSize, 4, 256, 128, path, bdpt);
  expectBlocksAgree(path, bdpt, kSize * kSize, "cornell-box");
}

// Glossy: conductors and a dielectric (importance transport through the glass).
TEST(BdptConverges, GlossyMaterialsMatchThePathTracer) {
  constexpr int kSize = 24;
  BdptBlockStats path(kSize, kSize, 8), bdpt(kSize, kSize, 8);
  renderBothWays("cornell-materials.json", kSize, 4, 256, 128, path, bdpt);
  expectBlocksAgree(path, bdpt, kSize * kSize, "cornell-materials");
}

// Sphere lights: light subpaths start on the analytic sphere, strategy s = 1 samples its cone,
// camera subpaths find its triangles; all weighed with the sphere's density by area.
TEST(BdptConverges, SphereLightsMatchThePathTracer) {
  constexpr int kSize = 24;
  BdptBlockStats path(kSize, kSize, 8), bdpt(kSize, kSize, 8);
  renderBothWays(sphereLightsScene(kSize, 4, kIntegratorPath),
                 sphereLightsScene(kSize, 4, kIntegratorBdpt), kSize, 256, 128, path, bdpt);
  expectBlocksAgree(path, bdpt, kSize * kSize, "sphere-lights");
}

// pbrt's check: each strategy alone, without its weight, estimates the light of its depth,
// which all strategies of that depth together estimate weighed (a diffuse scene: every strategy
// samples every path). Both come of the same samples: the bound is the spread of their
// difference. Returns the number of blocks (and images) that fail it, each reported where
// `report`.
int strategiesThatDisagree(const SceneData& data, BdptSplats splats, int spp, bool stripes,
                           bool report) {
  constexpr int blockSize = 8;
  const int kSize = int(data.params.camera.width);
  const BdptSplatter splatter(data.params.camera);
  const int strategies[][2] = {{0, 3}, {1, 2}, {2, 1}, {0, 4}, {1, 3}, {2, 2}, {3, 1}};
  std::vector<BdptBlockStats> diffs(std::size(strategies),
                                    BdptBlockStats(kSize, kSize, blockSize, stripes));
  std::vector<BdptBlockStats> alone(std::size(strategies),
                                    BdptBlockStats(kSize, kSize, blockSize, stripes));
  uint64_t rays = 0;
  for (int s = 0; s < spp; ++s) {
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        bdptSample(data, uvec2(x, y), uint(s), BdptStrategy{}, rays,
                   [&](const BdptContribution& c) {
                     for (size_t k = 0; k < std::size(strategies); ++k) {
                       const int depth = strategies[k][0] + strategies[k][1];
                       if (c.s + c.t != depth) continue;
                       // The weighed depth, less the strategy unweighed.
                       addBdptContribution(splatter, x, y, c, c.L * c.weight, diffs[k], splats);
                       if (c.s == strategies[k][0] && c.t == strategies[k][1]) {
                         addBdptContribution(splatter, x, y, c, -c.L, diffs[k], splats);
                         addBdptContribution(splatter, x, y, c, c.L, alone[k], splats);
                       }
                     }
                   });
        for (BdptBlockStats& d : diffs) d.endSample();
        for (BdptBlockStats& a : alone) a.endSample();
      }
    }
  }
  const double pixels = kSize * kSize;
  int failed = 0;
  for (size_t k = 0; k < std::size(strategies); ++k) {
    const std::string name =
        std::to_string(strategies[k][0]) + "," + std::to_string(strategies[k][1]);
    EXPECT_GT(alone[k].estimate(alone[k].blocks(), pixels), 0.0) << name << " finds light";
    for (int b = 0; b <= diffs[k].blocks(); ++b) {
      if (std::abs(diffs[k].estimate(b, pixels)) <=
          kBdptSigmas * diffs[k].standardError(b, pixels)) {
        continue;
      }
      ++failed;
      if (!report) continue;
      ADD_FAILURE() << "strategy " << name << " " << diffs[k].name(b) << ": "
                    << diffs[k].estimate(b, pixels) << ", standard error "
                    << diffs[k].standardError(b, pixels);
    }
  }
  return failed;
}

// The same on the Cornell box at 16x16 and depth 3 (with pixel filter `filter`, where one is
// given).
int strategiesThatDisagree(const std::optional<PixelFilterDesc>& filter, BdptSplats splats, int spp,
                           bool stripes, bool report) {
  return strategiesThatDisagree(bdptTestScene("cornell-box.json", 16, 3, kIntegratorBdpt, filter),
                                splats, spp, stripes, report);
}

TEST(BdptStrategies, EachAloneMatchesItsDepthWeighed) {
  EXPECT_EQ(strategiesThatDisagree(std::nullopt, BdptSplats::kFilter, 96, false, /*report=*/true),
            0);
}

// The same with sphere lights: s = 1 alone (the cone's samples), s = 0 alone (the triangles a
// camera subpath finds), light tracing alone (the sphere's points and cosine-weighted
// directions) each estimate their depth's light.
TEST(BdptStrategies, EachAloneMatchesItsDepthWeighedWithSphereLights) {
  EXPECT_EQ(strategiesThatDisagree(sphereLightsScene(16, 3, kIntegratorBdpt), BdptSplats::kFilter,
                                   96, false, /*report=*/true),
            0);
}

// ---- The MIS weights of one path's strategies ---------------------------------------------

// A complete path x0 (camera) ... x{n-1} (an emitter a camera subpath found), as the strategies
// (s, t), s + t = n, would have sampled it: each vertex's density from the camera's side and
// from the light's. pdfScale multiplies one vertex's light-side density (a deliberately wrong
// pdfRev, for the test that the check catches it).
struct BdptFullPath {
  std::vector<BdptVertex> x;  // camera subpath vertices; x.back() the emissive surface
  BdptVertex light;           // x.back() as a light vertex
  std::vector<float> fromCamera, fromLight;
};

BdptFullPath bdptFullPath(const PathScene& ps, const BdptPath& camera, uint n, int wrongVertex) {
  BdptFullPath f;
  f.x.assign(camera.v, camera.v + n);
  const BdptVertex& end = f.x[n - 1];
  const Emitter e = loadEmitter(ps, end.emitter);
  if ((e.triangle & kEmitterLight) != 0u) {
    // A sphere light's triangle: the light's vertex at the same point, with its normal.
    const Light light = loadLight(ps, e.triangle & ~kEmitterLight);
    f.light = bdptSphereLightVertex(ps, end.emitter, light, end.ng, vec3(1.0f), end.key);
    f.light.p = end.p;
  } else {
    f.light = bdptTriangleLightVertex(ps, end.emitter, end.p, vec2(0.0f), vec3(1.0f),
                                      end.key);  // untextured: b unread
  }
  f.fromCamera.assign(n, 0.0f);
  f.fromLight.assign(n, 0.0f);
  for (uint i = 1; i < n; ++i) {
    f.fromCamera[i] = bdptPdf(ps, f.x[i > 1 ? i - 2 : 0], f.x[i - 1], f.x[i]);
  }
  f.fromLight[n - 1] = bdptPdfLightOrigin(ps, f.light, f.x[n - 2]);
  f.fromLight[n - 2] = bdptPdfLight(ps, f.light, f.x[n - 2]);
  for (int i = int(n) - 3; i >= 0; --i) {
    const BdptVertex& next = i + 2 == int(n) - 1 ? f.light : f.x[size_t(i + 2)];
    f.fromLight[size_t(i)] = bdptPdf(ps, next, f.x[size_t(i + 1)], f.x[size_t(i)]);
  }
  if (wrongVertex > 0) f.fromLight[size_t(wrongVertex)] *= 1.5f;
  return f;
}

// Whether strategy (s, t) can sample the path: it connects two vertices that are not delta.
bool bdptStrategyPossible(const BdptFullPath& f, uint s, uint t) {
  const uint n = uint(f.x.size());
  if (s == 0) return true;  // the camera subpath found the emitter
  const BdptVertex& pt = f.x[t - 1];
  const BdptVertex& qs = s == 1 ? f.light : f.x[n - s];
  return bdptIsConnectible(pt) && bdptIsConnectible(qs);
}

// The weights of every strategy that can sample the path, by bdptMisWeight on subpaths built
// from the path's densities, or (uniform) 1 / n each, ignoring that delta vertices rule some
// strategies out.
float bdptWeightSum(const PathScene& ps, const BdptFullPath& f, bool uniform) {
  const uint n = uint(f.x.size());
  float sum = 0.0f;
  for (uint s = 0; s < n; ++s) {
    const uint t = n - s;
    if (s == 1 && t == 1) continue;
    if (!bdptStrategyPossible(f, s, t)) continue;
    if (uniform) {
      sum += 1.0f / float(n);
      continue;
    }
    BdptPath camera, light;
    camera.count = t;
    light.count = s;
    for (uint i = 0; i < t; ++i) {
      camera.v[i] = f.x[i];
      camera.v[i].pdfFwd = f.fromCamera[i];
      camera.v[i].pdfRev = f.fromLight[i];
    }
    for (uint j = 0; j < s; ++j) {
      const uint i = n - 1 - j;
      light.v[j] = j == 0 ? f.light : f.x[i];
      light.v[j].pdfFwd = f.fromLight[i];
      light.v[j].pdfRev = f.fromCamera[i];
    }
    const BdptVertex sampled = s == 1 ? light.v[0] : camera.v[0];
    sum += bdptMisWeight(ps, light, camera, sampled, s, t);
  }
  return sum;
}

// For the complete paths that camera subpaths of a scene find (cornell-mirror's: diffuse and
// mirror surfaces, the area light), the largest |sum of weights - 1|, how many paths had a delta
// vertex and how many ended on a sphere light.
struct BdptWeightCheck {
  float worst = 0.0f;
  int paths = 0;
  int withMirror = 0;
  int onSphere = 0;
};
BdptWeightCheck checkBdptWeights(bool uniform, int wrongVertex, const SceneData& data) {
  const PathScene ps = data.pathScene();
  BdptWeightCheck check;
  uint64_t rays = 0;
  for (uint sample = 0; sample < 48; ++sample) {
    for (uint y = 0; y < 16; ++y) {
      for (uint x = 0; x < 16; ++x) {
        BdptPath camera, light;
        bdptSubpaths(data, uvec2(x, y), sample, camera, light, rays);
        for (uint n = 3; n <= camera.count; ++n) {
          const BdptVertex& end = camera.v[n - 1];
          if (!bdptIsLight(end) || end.type != kBdptSurface) continue;
          if (!(maxComponent(bdptLe(ps, end, camera.v[n - 2])) > 0.0f)) continue;
          if (wrongVertex > 0 && int(n) < wrongVertex + 3) continue;
          const BdptFullPath f = bdptFullPath(ps, camera, n, wrongVertex);
          bool mirror = false;
          for (uint i = 1; i + 1 < n; ++i) mirror = mirror || f.x[i].s.scatter == kScatterMirror;
          check.withMirror += mirror ? 1 : 0;
          check.onSphere += (loadEmitter(ps, f.x.back().emitter).triangle & kEmitterLight) != 0u;
          ++check.paths;
          check.worst = std::max(check.worst, std::abs(bdptWeightSum(ps, f, uniform) - 1.0f));
        }
      }
    }
  }
  return check;
}
BdptWeightCheck checkBdptWeights(bool uniform, int wrongVertex) {
  return checkBdptWeights(uniform, wrongVertex,
                          bdptTestScene("cornell-mirror.json", 16, 6, kIntegratorBdpt));
}

TEST(BdptMisWeights, SumToOneOverTheStrategiesOfAPath) {
  const BdptWeightCheck check = checkBdptWeights(/*uniform=*/false, /*wrongVertex=*/-1);
  EXPECT_GT(check.paths, 200);
  EXPECT_GT(check.withMirror, 20);  // delta vertices are among them
  EXPECT_LT(check.worst, 1e-4f);
}

// The same check catches weights that ignore delta vertices and a wrong reverse density.
TEST(BdptMisWeights, TheCheckCatchesWrongWeights) {
  const BdptWeightCheck uniform = checkBdptWeights(/*uniform=*/true, /*wrongVertex=*/-1);
  EXPECT_GT(uniform.worst, 0.1f);
  const BdptWeightCheck wrongPdf = checkBdptWeights(/*uniform=*/false, /*wrongVertex=*/1);
  EXPECT_GT(wrongPdf.paths, 50);
  EXPECT_GT(wrongPdf.worst, 1e-2f);
}

// Paths that end on a sphere light's triangles: every strategy takes the analytic sphere's
// density by area for the light's point (s = 0 as the light subpath's start and s = 1 do).
TEST(BdptMisWeights, SumToOneWithSphereLights) {
  const BdptWeightCheck check = checkBdptWeights(/*uniform=*/false, /*wrongVertex=*/-1,
                                                 sphereLightsScene(16, 5, kIntegratorBdpt));
  EXPECT_GT(check.paths, 200);
  EXPECT_EQ(check.onSphere, check.paths);
  EXPECT_LT(check.worst, 1e-4f);
}

// The same seed gives the same bits, on one thread or two (splats summed exactly).
TEST(BdptRender, SameImageWithOneAndTwoThreads) {
  const SceneData data = bdptTestScene("cornell-box.json", 16, 4, kIntegratorBdpt);
  CpuRenderOptions options;
  options.spp = 4;
  Film one(16, 16), two(16, 16);
  options.threads = 1;
  renderCpu(data, options, one);
  options.threads = 2;
  renderCpu(data, options, two);
  const Image a = one.resolve();
  const Image b = two.resolve();
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  double total = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    ASSERT_EQ(a.pixels[i], b.pixels[i]) << "pixel " << i;
    total += double(a.pixels[i].x);
  }
  EXPECT_GT(total, 0.0);
}

// ---- Pixel filters -------------------------------------------------------------------------

// pbrt-v4's filter of type `type` with its defaults (gaussian: radius 1.5, sigma 0.5; triangle
// and mitchell: radius 2).
PixelFilterDesc bdptFilter(uint type) {
  return defaultFilter(type);
}

// filterIntegral is the integral of filterValue: a midpoint sum over a 400 x 400 grid of the
// filter's square (its kinks on the grid lines), for default and other parameters.
TEST(BdptFilters, FilterIntegralIsTheIntegralOfItsValue) {
  auto make = [](uint type, float rx, float ry) {
    PixelFilterDesc f = defaultFilter(type);
    f.radiusX = rx;
    f.radiusY = ry;
    return f;
  };
  std::vector<PixelFilterDesc> filters = {
      defaultFilter(kFilterBox),      make(kFilterBox, 1.5f, 0.75f),
      defaultFilter(kFilterTriangle), make(kFilterTriangle, 1.0f, 1.5f),
      defaultFilter(kFilterGaussian), make(kFilterGaussian, 2.0f, 1.0f),
      defaultFilter(kFilterMitchell), make(kFilterMitchell, 1.5f, 2.0f)};
  filters[5].sigma = 0.8f;
  filters[7].b = 0.0f;
  filters[7].c = 0.5f;
  for (const PixelFilterDesc& f : filters) {
    Camera cam{};
    setFilterConstants(cam, f, "test");
    constexpr int kSteps = 400;
    const double hx = 2.0 * f.radiusX / kSteps, hy = 2.0 * f.radiusY / kSteps;
    double sum = 0.0;
    for (int j = 0; j < kSteps; ++j) {
      for (int i = 0; i < kSteps; ++i) {
        const vec2 p(float(-f.radiusX + (i + 0.5) * hx), float(-f.radiusY + (j + 0.5) * hy));
        sum += double(filterValue(cam, p)) * hx * hy;
      }
    }
    EXPECT_NEAR(sum / filterIntegral(cam), 1.0, 2e-4)
        << "filter " << f.type << " radius " << f.radiusX << " x " << f.radiusY;
    EXPECT_EQ(filterValue(cam, vec2(f.radiusX * 1.01f, 0.0f)), 0.0f);
  }
}

// BDPT with pbrt-v4's default gaussian (and the triangle, and mitchell's negative lobes)
// converges to the path tracer's image with the same filter: the camera's strategies sample
// the filter as the path tracer does, light tracing's splats spread over the pixels the filter
// reaches.
void expectFilteredConverges(const std::string& config, uint filterType, const std::string& what) {
  constexpr int kSize = 24;
  BdptBlockStats path(kSize, kSize, 8), bdpt(kSize, kSize, 8);
  renderBothWays(config, kSize, 4, 256, 128, path, bdpt, bdptFilter(filterType));
  expectBlocksAgree(path, bdpt, kSize * kSize, what);
}

TEST(BdptFilters, GaussianCornellBoxMatchesThePathTracer) {
  expectFilteredConverges("cornell-box.json", kFilterGaussian, "cornell-box, gaussian");
}
TEST(BdptFilters, TriangleCornellBoxMatchesThePathTracer) {
  expectFilteredConverges("cornell-box.json", kFilterTriangle, "cornell-box, triangle");
}
TEST(BdptFilters, MitchellCornellBoxMatchesThePathTracer) {
  expectFilteredConverges("cornell-box.json", kFilterMitchell, "cornell-box, mitchell");
}
// The glass sphere's caustic on the floor: light tracing (t = 1) carries much of it.
TEST(BdptFilters, GaussianGlossyMatchesThePathTracer) {
  expectFilteredConverges("cornell-materials.json", kFilterGaussian, "cornell-materials, gaussian");
}

// Each strategy alone, light tracing's (2,1) and (3,1) among them, equals its depth weighed,
// under the gaussian and the triangle, in the blocks and their stripes.
TEST(BdptFilters, StrategiesAloneMatchTheirDepthWeighed) {
  EXPECT_EQ(strategiesThatDisagree(bdptFilter(kFilterGaussian), BdptSplats::kFilter, 384, true,
                                   /*report=*/true),
            0);
  EXPECT_EQ(strategiesThatDisagree(bdptFilter(kFilterTriangle), BdptSplats::kFilter, 384, true,
                                   /*report=*/true),
            0);
}

// The strategy check sees the filter: splats put whole into the one pixel they land in (a box's
// behaviour) under the gaussian fail it, in the stripes of the blocks (the camera's strategies
// blur the image as the filter does, such splats do not).
TEST(BdptFilters, TheStrategyCheckCatchesOnePixelSplats) {
  EXPECT_GT(strategiesThatDisagree(bdptFilter(kFilterGaussian), BdptSplats::kOnePixel, 384, true,
                                   /*report=*/false),
            0);
  EXPECT_GT(strategiesThatDisagree(bdptFilter(kFilterTriangle), BdptSplats::kOnePixel, 384, true,
                                   /*report=*/false),
            0);
}

}  // namespace
}  // namespace pt

namespace pt {
namespace {

std::string bdptConfig(const std::string& name) {
  return (test::kConfigs / name).string();
}

// The command line: --integrator bdpt renders on the CPU and says so; Vulkan, --strategy S,T
// without bdpt and a negative maxdepth are one-line errors with exit status 2.
TEST(BdptCli, ChosenRefusedAndChecked) {
  test::TempDir dir;
  const test::PtResult r =
      test::runPt("render " + bdptConfig("cornell-box.json") +
                  " --backend cpu --integrator bdpt --max-depth 3 --spp 1 --width 16 --height 16 "
                  "--strategy 1,2 --out " +
                  (dir / "a.exr").string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("integrator=bdpt"), std::string::npos) << r.out;

  const test::PtResult path =
      test::runPt("render " + bdptConfig("cornell-box.json") +
                  " --backend cpu --strategy 1,2 --spp 1 --out " + (dir / "c.exr").string());
  EXPECT_EQ(path.status, 2);

  const std::filesystem::path bad = dir / "bad.pbrt";
  {
    std::ifstream in(bdptConfig("cornell-box.pbrt"));
    std::stringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    const std::string from = "Integrator \"path\" \"integer maxdepth\" [ 64 ]";
    ASSERT_NE(s.find(from), std::string::npos);
    s.replace(s.find(from), from.size(), "Integrator \"bdpt\" \"integer maxdepth\" -1");
    std::ofstream(bad) << s;
  }
  {
    std::ifstream in(bad);
    std::stringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    const std::string negative = "maxdepth\" -1";
    s.replace(s.find(negative), negative.size(), "maxdepth\" 3");
    // pbrt-v4's default filter, as most of its files have it.
    const std::string box = "PixelFilter \"box\"";
    ASSERT_NE(s.find(box), std::string::npos);
    s.replace(s.find(box), box.size(), "PixelFilter \"gaussian\"");
    std::ofstream(dir / "good.pbrt") << s;
  }
  const Scene good = loadScene(dir / "good.pbrt");
  EXPECT_EQ(good.integrator.integrator, kIntegratorBdpt);
  EXPECT_EQ(good.integrator.maxDepth, 3);
  // The file alone chooses BDPT, which renders it with its gaussian filter.
  const test::PtResult gaussian = test::runPt(
      "render " + (dir / "good.pbrt").string() +
      " --backend cpu --spp 2 --width 16 --height 16 --out " + (dir / "g.exr").string());
  EXPECT_EQ(gaussian.status, 0) << gaussian.err;
  EXPECT_NE(gaussian.out.find("integrator=bdpt"), std::string::npos) << gaussian.out;
  EXPECT_NE(gaussian.out.find("invalid_samples=0"), std::string::npos) << gaussian.out;

  const test::PtResult negative =
      test::runPt("render " + bad.string() + " --backend cpu --out " + (dir / "d.exr").string());
  EXPECT_EQ(negative.status, 2);
  EXPECT_NE(negative.err.find("bad.pbrt:15:19: maxdepth must not be negative"), std::string::npos)
      << negative.err;
}

}  // namespace
}  // namespace pt
