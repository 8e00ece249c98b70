// The camera's samples (shaders/filter.h) and what the scene readers make of pbrt-v4's camera
// and film: each pixel filter's film offsets against its |f| by a chi-square test (and a wrong
// shape shown to fail), mitchell's signed weights, the box of one pixel giving the film points
// and rays of the renderer before filters bit for bit, the thin lens (a pinhole at radius 0,
// sharp on the plane in focus), screen windows and crop windows against hand-computed rays
// and pixels, CPU and lavapipe agreeing, the JSON camera's options and errors, and --strict.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "common/check.h"
#include "cpu/integrator.h"
#include "filter.h"
#include "render/camera.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/camera_filter.h"
#include "scene/load_scene.h"
#include "scene/pbrt/pbrt_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

// ---- the filters' definitions, written out again in double (pbrt-v4's filters.h) -----------

struct Filter1D {
  std::function<double(double)> f;  // the 1D filter f1 of one axis
  double radius;
};

Filter1D boxFilter(double r) {
  return {[r](double x) { return std::abs(x) <= r ? 1.0 : 0.0; }, r};
}
Filter1D triangleFilter(double r) {
  return {[r](double x) { return std::max(0.0, r - std::abs(x)); }, r};
}
Filter1D gaussianFilter(double r, double sigma) {
  return {[r, sigma](double x) {
            const auto g = [sigma](double v) { return std::exp(-v * v / (2.0 * sigma * sigma)); };
            return std::abs(x) <= r ? std::max(0.0, g(x) - g(r)) : 0.0;
          },
          r};
}
// pbrt-v4's Mitchell1D(2x / r).
Filter1D mitchellFilter(double r, double b, double c) {
  return {
      [r, b, c](double x) {
        const double t = std::abs(2.0 * x / r);
        if (t <= 1.0) {
          return ((12 - 9 * b - 6 * c) * t * t * t + (-18 + 12 * b + 6 * c) * t * t + (6 - 2 * b)) /
                 6.0;
        }
        if (t <= 2.0) {
          return ((-b - 6 * c) * t * t * t + (6 * b + 30 * c) * t * t + (-12 * b - 48 * c) * t +
                  (8 * b + 24 * c)) /
                 6.0;
        }
        return 0.0;
      },
      r};
}

// The integral of g over [a, b]: Gauss-Legendre on `pieces` pieces (|f| has kinks where f
// changes sign, which the rule integrates with an error that falls as the square of their
// width: 64 pieces of a histogram cell are far below what the sample counts resolve).
double integrate(const std::function<double(double)>& g, double a, double b, int pieces = 64) {
  static const test::GaussLegendre rule(8);
  double sum = 0.0;
  for (int i = 0; i < pieces; ++i) {
    const double lo = a + (b - a) * i / pieces, hi = a + (b - a) * (i + 1) / pieces;
    for (size_t k = 0; k < rule.nodes.size(); ++k) {
      sum +=
          0.5 * (hi - lo) * rule.weights[k] * g(0.5 * (lo + hi) + 0.5 * (hi - lo) * rule.nodes[k]);
    }
  }
  return sum;
}

// A Camera holding nothing but the filter (all sampleFilm reads).
Camera filterCamera(const PixelFilterDesc& filter) {
  Camera cam{};
  setFilterConstants(cam, filter, "test");
  return cam;
}

PixelFilterDesc makeFilter(uint type, float rx, float ry, float sigma = 0.5f, float b = 1.0f / 3.0f,
                           float c = 1.0f / 3.0f) {
  PixelFilterDesc d;
  d.type = type;
  d.radiusX = rx;
  d.radiusY = ry;
  d.sigma = sigma;
  d.b = b;
  d.c = c;
  return d;
}

// Uniform numbers as the samplers make them: 24 bits, in [0, 1).
struct Uniform {
  std::mt19937_64 engine;
  explicit Uniform(uint64_t seed) : engine(seed) {}
  float next() { return float(engine() >> 40) * (1.0f / 16777216.0f); }
  vec2 next2() {
    const float x = next();
    return vec2(x, next());
  }
};

struct Histogram {
  std::vector<double> observed, expected;
};

// N film offsets of `cam`'s filter in a cells x cells grid over [-rx, rx] x [-ry, ry], and the
// counts that |fx(x)| |fy(y)| predicts (the 2D density is separable, so each cell's integral
// is the product of the axes' integrals).
Histogram histogram(const Camera& cam, const Filter1D& fx, const Filter1D& fy, int n, int cells,
                    uint64_t seed) {
  Histogram h;
  h.observed.assign(size_t(cells * cells), 0.0);
  h.expected.assign(size_t(cells * cells), 0.0);
  Uniform u(seed);
  for (int i = 0; i < n; ++i) {
    const FilmSample s = sampleFilm(cam, u.next2());
    const double x = double(s.point.x) - 0.5, y = double(s.point.y) - 0.5;
    const int cx =
        std::clamp(int(std::floor((x + fx.radius) / (2.0 * fx.radius) * cells)), 0, cells - 1);
    const int cy =
        std::clamp(int(std::floor((y + fy.radius) / (2.0 * fy.radius) * cells)), 0, cells - 1);
    EXPECT_LE(std::abs(x), fx.radius * (1.0 + 1e-6));
    EXPECT_LE(std::abs(y), fy.radius * (1.0 + 1e-6));
    h.observed[size_t(cy * cells + cx)] += 1.0;
  }
  auto shares = [cells](const Filter1D& f) {
    std::vector<double> p(static_cast<size_t>(cells), 0.0);
    const auto g = [&f](double x) { return std::abs(f.f(x)); };
    double total = 0.0;
    for (int i = 0; i < cells; ++i) {
      const double lo = -f.radius + 2.0 * f.radius * i / cells;
      total += p[size_t(i)] = integrate(g, lo, lo + 2.0 * f.radius / cells);
    }
    for (double& v : p) v /= total;
    return p;
  };
  const std::vector<double> px = shares(fx), py = shares(fy);
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i)
      h.expected[size_t(j * cells + i)] = n * px[size_t(i)] * py[size_t(j)];
  }
  return h;
}

// The filters' parameters as the camera holds them, in float.
constexpr double kThird = double(1.0f / 3.0f);

constexpr int kSamples = 200000;
constexpr int kCells = 20;
// Every chi-square test below must pass at a significance that keeps the chance of a correct
// sampler failing any of them below 1e-3 (they are deterministic: a fixed seed each).
const double kFilterSignificance = test::sidakSignificance(1e-3, 10);

struct FilterCase {
  const char* name;
  PixelFilterDesc desc;
  Filter1D fx, fy;
};

class FilterSampling : public ::testing::TestWithParam<FilterCase> {};

// The offsets are distributed as |f| (filter importance sampling, exactly).
TEST_P(FilterSampling, OffsetsFollowTheFilter) {
  const FilterCase& c = GetParam();
  const Camera cam = filterCamera(c.desc);
  const Histogram h = histogram(cam, c.fx, c.fy, kSamples, kCells, 7);
  const test::Chi2Result r = test::pearsonChi2(h.observed, h.expected);
  EXPECT_EQ(r.zeroDensityHits, 0.0);
  EXPECT_GT(r.pValue, kFilterSignificance) << "chi2 " << r.statistic << " dof " << r.dof;
}

// Every weight is 1 but mitchell's: sign(f(x) f(y)) times (integral |f| / integral f), the
// ratio of the filter's integrals computed here by quadrature; and its mean is 1.
TEST_P(FilterSampling, WeightsAreTheSignTimesTheRatioOfIntegrals) {
  const FilterCase& c = GetParam();
  const Camera cam = filterCamera(c.desc);
  double ratio = 1.0;
  for (const Filter1D* f : {&c.fx, &c.fy}) {
    const auto g = *f;
    ratio *= integrate([&](double x) { return std::abs(g.f(x)); }, -g.radius, g.radius, 8192) /
             integrate(g.f, -g.radius, g.radius, 8192);
  }
  EXPECT_NEAR(cam.filterWeight, ratio, 1e-6 * ratio);
  Uniform u(11);
  double sum = 0.0;
  int negative = 0;
  for (int i = 0; i < kSamples / 4; ++i) {
    const FilmSample s = sampleFilm(cam, u.next2());
    const double f = c.fx.f(double(s.point.x) - 0.5) * c.fy.f(double(s.point.y) - 0.5);
    ASSERT_EQ(std::abs(s.weight), cam.filterWeight);
    // Far enough from a root of f that its sign is not a matter of rounding.
    if (std::abs(f) > 1e-4) ASSERT_EQ(s.weight > 0.0f, f > 0.0) << s.point.x << " " << s.point.y;
    negative += s.weight < 0.0f;
    sum += s.weight;
  }
  const int n = kSamples / 4;
  const double mean = sum / n;
  const double stddev = std::sqrt(std::max(0.0, ratio * ratio - 1.0) / n);
  EXPECT_NEAR(mean, 1.0, 5.0 * stddev + 1e-12);
  if (c.desc.type != kFilterMitchell) {
    EXPECT_EQ(cam.filterWeight, 1.0f);
    EXPECT_EQ(negative, 0);
  } else {
    EXPECT_GT(negative, 0);  // the negative lobes are sampled, not skipped
  }
}

INSTANTIATE_TEST_SUITE_P(
    PbrtFilters, FilterSampling,
    ::testing::Values(
        FilterCase{"box", makeFilter(kFilterBox, 0.5f, 0.5f), boxFilter(0.5), boxFilter(0.5)},
        FilterCase{"wideBox", makeFilter(kFilterBox, 1.5f, 0.75f), boxFilter(1.5), boxFilter(0.75)},
        FilterCase{"triangle", makeFilter(kFilterTriangle, 2.0f, 2.0f), triangleFilter(2.0),
                   triangleFilter(2.0)},
        FilterCase{"gaussian", makeFilter(kFilterGaussian, 1.5f, 1.5f), gaussianFilter(1.5, 0.5),
                   gaussianFilter(1.5, 0.5)},
        FilterCase{"gaussianWide", makeFilter(kFilterGaussian, 1.0f, 3.0f, 1.25f),
                   gaussianFilter(1.0, 1.25), gaussianFilter(3.0, 1.25)},
        FilterCase{"mitchell", makeFilter(kFilterMitchell, 2.0f, 2.0f),
                   mitchellFilter(2.0, kThird, kThird), mitchellFilter(2.0, kThird, kThird)},
        FilterCase{"catmullRom", makeFilter(kFilterMitchell, 1.5f, 2.5f, 0.5f, 0.0f, 0.5f),
                   mitchellFilter(1.5, 0.0, 0.5), mitchellFilter(2.5, 0.0, 0.5)},
        // Negative inside |t| < 1 too: two more sign changes there.
        FilterCase{"mitchellDip", makeFilter(kFilterMitchell, 2.0f, 2.0f, 0.5f, 0.1f, -1.0f),
                   mitchellFilter(2.0, double(0.1f), -1.0),
                   mitchellFilter(2.0, double(0.1f), -1.0)}),
    [](const ::testing::TestParamInfo<FilterCase>& info) { return std::string(info.param.name); });

// The test can fail: samples of one shape against another shape's counts are rejected.
TEST(FilterSamplingChi2, AWrongShapeFails) {
  // A gaussian of sigma 0.5 against one of sigma 0.55.
  const Camera gaussian = filterCamera(makeFilter(kFilterGaussian, 1.5f, 1.5f));
  Histogram h = histogram(gaussian, gaussianFilter(1.5, 0.55), gaussianFilter(1.5, 0.55), kSamples,
                          kCells, 7);
  EXPECT_LT(test::pearsonChi2(h.observed, h.expected).pValue, 1e-9);
  // The triangle against the box.
  const Camera triangle = filterCamera(makeFilter(kFilterTriangle, 2.0f, 2.0f));
  h = histogram(triangle, boxFilter(2.0), boxFilter(2.0), kSamples, kCells, 7);
  EXPECT_LT(test::pearsonChi2(h.observed, h.expected).pValue, 1e-9);
  // Mitchell against its positive part only: its negative lobes hold samples.
  const Camera mitchell = filterCamera(makeFilter(kFilterMitchell, 2.0f, 2.0f));
  const Filter1D m = mitchellFilter(2.0, kThird, kThird);
  const Filter1D positive{[m](double x) { return std::max(0.0, m.f(x)); }, 2.0};
  h = histogram(mitchell, positive, positive, kSamples, kCells, 7);
  const test::Chi2Result r = test::pearsonChi2(h.observed, h.expected);
  EXPECT_GT(r.zeroDensityHits, 0.0);
  EXPECT_EQ(r.pValue, 0.0);
}

TEST(FilterSamplingChi2, BadParametersAreRefused) {
  Camera cam{};
  auto error = [&](const PixelFilterDesc& d) {
    try {
      setFilterConstants(cam, d, "f");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error(makeFilter(kFilterBox, 0.0f, 0.5f)),
            "f: filter radius must be in (0, 4096] pixels, got 0");
  EXPECT_EQ(error(makeFilter(kFilterGaussian, 1.5f, 1.5f, -1.0f)),
            "f: gaussian filter: sigma must be a positive number, got -1");
  EXPECT_EQ(error(makeFilter(kFilterGaussian, 0.5f, 0.5f, 10.0f)),
            "f: gaussian filter: sigma 10 is too wide for radius 0.5 (the filter is within 0.1 % "
            "of a box there: use \"box\")");
  EXPECT_EQ(error(makeFilter(kFilterGaussian, 0.5f, 0.5f, 2.0f)), "no error");
}

// ---- the box of one pixel: the renderer's film points and rays before filters -------------

Camera boxCamera(int width, int height) {
  CameraDesc desc;
  desc.position = vec3(1.0f, 2.0f, -3.0f);
  desc.target = vec3(0.2f, 0.1f, 1.0f);
  desc.up = vec3(0.1f, 1.0f, 0.0f);
  desc.vfovDegrees = 47.0f;
  return makeCamera(desc, width, height);
}

// sampling.h's cameraDirection as it was before screen windows and crops, for comparison.
vec3 directionBeforeFilters(const Camera& cam, vec2 filmPoint) {
  const float u = 2.0f * filmPoint.x / float(cam.width) - 1.0f;
  const float v = 1.0f - 2.0f * filmPoint.y / float(cam.height);
  return normalize(cam.forward + (u * cam.tanHalfFovY * cam.aspect) * cam.right +
                   (v * cam.tanHalfFovY) * cam.up);
}

TEST(CameraBoxFilter, IsTheUniformJitterBitForBit) {
  const Camera cam = boxCamera(37, 23);
  ASSERT_EQ(cam.filterType, kFilterBox);
  EXPECT_EQ(0, std::memcmp(&cam.windowCenter, &cam.forward, sizeof(vec3)));
  Uniform u(3);
  std::vector<vec2> us = {vec2(0.0f), vec2(0.5f), vec2(1.0f - 1.0f / 16777216.0f, 0.25f)};
  for (int i = 0; i < 10000; ++i) us.push_back(u.next2());
  for (size_t i = 0; i < us.size(); ++i) {
    const FilmSample s = sampleFilm(cam, us[i]);
    ASSERT_EQ(0, std::memcmp(&s.point, &us[i], sizeof(vec2))) << i;
    ASSERT_EQ(s.weight, 1.0f);
    const uvec2 pixel(uint(i % 37), uint(i % 23));
    // The pinhole ignores the lens's numbers.
    const CameraSample ray = generateCameraRay(cam, pixel, us[i], vec2(0.3f, 0.9f));
    const vec3 before = directionBeforeFilters(cam, vec2(pixel) + us[i]);
    ASSERT_EQ(0, std::memcmp(&ray.direction, &before, sizeof(vec3))) << i;
    ASSERT_EQ(0, std::memcmp(&ray.origin, &cam.position, sizeof(vec3)));
  }
}

// ---- the thin lens -------------------------------------------------------------------------

TEST(CameraThinLens, RadiusZeroIsThePinholeBitForBit) {
  CameraDesc desc;
  desc.position = vec3(0.5f, 0.25f, -4.0f);
  desc.target = vec3(0.0f, 0.0f, 1.0f);
  desc.filter = makeFilter(kFilterGaussian, 1.5f, 1.5f);
  desc.focalDistance = 3.0f;
  const Camera pinhole = makeCamera(desc, 16, 12);
  Uniform u(5);
  for (int i = 0; i < 2000; ++i) {
    const vec2 uFilter = u.next2(), uLens = u.next2();
    const uvec2 pixel(uint(i % 16), uint(i % 12));
    const CameraSample a = generateCameraRay(pinhole, pixel, uFilter, uLens);
    const CameraSample b = generateCameraRay(pinhole, pixel, uFilter, vec2(0.0f));
    const FilmSample film = sampleFilm(pinhole, uFilter);
    const vec3 direction = cameraDirection(pinhole, vec2(pixel) + film.point);
    ASSERT_EQ(0, std::memcmp(&a.direction, &direction, sizeof(vec3)));
    ASSERT_EQ(0, std::memcmp(&b.direction, &direction, sizeof(vec3)));
    ASSERT_EQ(0, std::memcmp(&a.origin, &pinhole.position, sizeof(vec3)));
  }
  // No path reaches the lens's random numbers through its scattering events: the first event
  // whose dimensions include kDimLens is event number 2^30 - 1 (counting from 0).
  EXPECT_EQ((kDimLens - kDimFirstBounce) / kDimsPerBounce, (1u << 30) - 1u);
}

// Every ray of one film point passes through the same point of the plane in focus (the
// pinhole's ray's point there), leaving from the lens's disk: everything on that plane is
// sharp, as pbrt-v4's thin lens makes it.
TEST(CameraThinLens, APointInFocusIsOneFilmPointForEveryLensSample) {
  CameraDesc desc;
  desc.position = vec3(1.0f, 2.0f, -3.0f);
  desc.target = vec3(0.2f, 0.1f, 1.0f);
  desc.up = vec3(0.1f, 1.0f, 0.0f);
  desc.vfovDegrees = 40.0f;
  desc.lensRadius = 0.25f;
  desc.focalDistance = 7.5f;
  desc.screenWindow = std::array<float, 4>{-1.2f, 1.6f, -0.9f, 1.1f};
  desc.filter = makeFilter(kFilterTriangle, 2.0f, 2.0f);
  const Camera cam = makeCamera(desc, 20, 10);
  const dvec3 position(cam.position), forward(cam.forward);
  Uniform u(9);
  double lensRadius2 = 0.0;
  int lensSamples = 0;
  for (int i = 0; i < 200; ++i) {
    const vec2 uFilter = u.next2();
    const uvec2 pixel(uint(i % 20), uint(i % 10));
    const vec2 filmPoint = vec2(pixel) + sampleFilm(cam, uFilter).point;
    // The pinhole ray's point on the plane in focus, from its direction alone.
    const dvec3 d(cameraDirection(cam, filmPoint));
    const dvec3 inFocus = position + d * (double(cam.focalDistance) / glm::dot(d, forward));
    for (int j = 0; j < 32; ++j) {
      const CameraSample ray = generateCameraRay(cam, pixel, uFilter, u.next2());
      const dvec3 o(ray.origin), dir(ray.direction);
      // The origin lies on the lens: in the plane through the position across forward, within
      // the radius.
      const dvec3 offset = o - position;
      EXPECT_NEAR(glm::dot(offset, forward), 0.0, 1e-6);
      EXPECT_LE(glm::length(offset), double(cam.lensRadius) * (1.0 + 1e-6));
      lensRadius2 += glm::dot(offset, offset);
      ++lensSamples;
      // The ray passes through the point in focus.
      const dvec3 toFocus = inFocus - o;
      const double miss = glm::length(glm::cross(toFocus, dir));
      ASSERT_LT(miss, 1e-5 * glm::length(toFocus)) << i << " " << j;
      EXPECT_GT(glm::dot(toFocus, dir), 0.0);
    }
  }
  // Uniform on the disk: the mean squared radius is R^2 / 2 (to a few standard errors).
  const double r2 = double(cam.lensRadius) * cam.lensRadius;
  EXPECT_NEAR(lensRadius2 / lensSamples, 0.5 * r2, 5.0 * r2 * std::sqrt(1.0 / 12.0 / lensSamples));
}

TEST(CameraThinLens, ConcentricDiskIsUniform) {
  // Four rings of equal area and eight sectors: 32 cells of equal probability.
  constexpr int kRings = 4, kSectors = 8, kN = 64000;
  std::vector<double> observed(kRings * kSectors, 0.0), expected(kRings * kSectors, kN / 32.0);
  Uniform u(13);
  for (int i = 0; i < kN; ++i) {
    const vec2 p = sampleConcentricDisk(u.next2());
    const double r2 = double(p.x) * p.x + double(p.y) * p.y;
    ASSERT_LE(r2, 1.0 + 1e-6);
    const int ring = std::min(kRings - 1, int(r2 * kRings));
    const double angle = std::atan2(double(p.y), double(p.x)) + 3.14159265358979323846;
    const int sector =
        std::min(kSectors - 1, int(angle / (2.0 * 3.14159265358979323846) * kSectors));
    observed[size_t(ring * kSectors + sector)] += 1.0;
  }
  EXPECT_GT(test::pearsonChi2(observed, expected).pValue, kFilterSignificance);
  EXPECT_EQ(sampleConcentricDisk(vec2(0.5f)), vec2(0.0f));
}

// ---- screen windows and crops --------------------------------------------------------------

// The camera at the origin looking down +z with +y up and vfov 90 (tan(vfov / 2) = 1): right
// = forward x up = -x. Film point (x, y) of a W x H film over the window [x0, x1] x [y0, y1]
// looks along forward + X right + Y up, X = x0 + (x1 - x0) x / W, Y = y1 - (y1 - y0) y / H.
CameraDesc axisCamera() {
  CameraDesc desc;
  desc.position = vec3(0.0f);
  desc.target = vec3(0.0f, 0.0f, 1.0f);
  desc.up = vec3(0.0f, 1.0f, 0.0f);
  desc.vfovDegrees = 90.0f;
  return desc;
}

void expectDirection(const Camera& cam, vec2 filmPoint, dvec3 expected) {
  const vec3 d = cameraDirection(cam, filmPoint);
  const dvec3 e = glm::normalize(expected);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(d[k], e[k], 2e-7) << "film point " << filmPoint.x << "," << filmPoint.y;
  }
}

TEST(CameraScreenWindow, RaysAsHandComputed) {
  CameraDesc desc = axisCamera();
  // The default window of an 8 x 4 film: [-2, 2] x [-1, 1].
  Camera cam = makeCamera(desc, 8, 4);
  expectDirection(cam, vec2(0.0f, 0.0f), dvec3(2.0, 1.0, 1.0));
  expectDirection(cam, vec2(8.0f, 4.0f), dvec3(-2.0, -1.0, 1.0));
  expectDirection(cam, vec2(4.0f, 2.0f), dvec3(0.0, 0.0, 1.0));
  // An off-centre window [-1, 3] x [-2, 2].
  desc.screenWindow = std::array<float, 4>{-1.0f, 3.0f, -2.0f, 2.0f};
  cam = makeCamera(desc, 8, 4);
  expectDirection(cam, vec2(0.0f, 0.0f), dvec3(1.0, 2.0, 1.0));    // X = -1, Y = 2
  expectDirection(cam, vec2(8.0f, 4.0f), dvec3(-3.0, -2.0, 1.0));  // X = 3, Y = -2
  expectDirection(cam, vec2(4.0f, 2.0f), dvec3(-1.0, 0.0, 1.0));   // X = 1, Y = 0
  expectDirection(cam, vec2(2.0f, 3.0f), dvec3(0.0, -1.0, 1.0));   // X = 0, Y = -1
  // --width and --height change the film, not the window.
  cam = makeCamera(desc, 16, 16);
  expectDirection(cam, vec2(16.0f, 0.0f), dvec3(-3.0, 2.0, 1.0));
}

TEST(CameraCrop, PixelsAsPbrtV4ComputesThem) {
  CameraDesc desc = axisCamera();
  EXPECT_EQ(cropPixels(desc, 10, 8), (std::array<int, 4>{0, 10, 0, 8}));
  // ceil(10 * 0.25) = 3, ceil(10 * 0.75) = 8, ceil(8 * 0.1) = 1, ceil(8 * 0.5) = 4.
  desc.cropWindow = std::array<float, 4>{0.25f, 0.75f, 0.1f, 0.5f};
  EXPECT_EQ(cropPixels(desc, 10, 8), (std::array<int, 4>{3, 8, 1, 4}));
  // Ordered and clamped to [0, 1].
  desc.cropWindow = std::array<float, 4>{0.75f, 0.25f, -0.5f, 2.0f};
  EXPECT_EQ(cropPixels(desc, 10, 8), (std::array<int, 4>{3, 8, 0, 8}));
  desc.cropWindow.reset();
  desc.pixelBounds = std::array<int, 4>{2, 5, 1, 7};
  EXPECT_EQ(cropPixels(desc, 10, 8), (std::array<int, 4>{2, 5, 1, 7}));
  desc.pixelBounds = std::array<int, 4>{-3, 20, 3, 2};  // clipped to the film, ordered
  EXPECT_EQ(cropPixels(desc, 10, 8), (std::array<int, 4>{0, 10, 2, 3}));
  // The camera: the image is the crop, the rays the film's.
  desc.pixelBounds = std::array<int, 4>{2, 5, 1, 7};
  const Camera cam = makeCamera(desc, 10, 8);
  EXPECT_EQ(cam.width, 3u);
  EXPECT_EQ(cam.height, 6u);
  EXPECT_EQ(cam.cropX, 2u);
  EXPECT_EQ(cam.cropY, 1u);
  EXPECT_EQ(cam.filmWidth, 10u);
  EXPECT_EQ(cam.filmHeight, 8u);
  expectDirection(cam, vec2(0.0f, 0.0f), dvec3(1.25, 1.0, 1.0));
  // A crop of nothing (a film made smaller by --width) is an error.
  try {
    makeCamera(desc, 2, 8);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "the crop window selects no pixel of the 2x8 film");
  }
}

// ---- whole renders ------------------------------------------------------------------------

SceneData cornellWithCamera(int size, const std::function<void(CameraDesc&)>& camera) {
  Scene scene = loadScene(test::kConfigs / "cornell-box.json");
  camera(scene.camera);
  return prepareScene(std::move(scene), RenderSettings{.width = size, .height = size});
}

void thinLensAndGaussian(CameraDesc& c) {
  c.filter = makeFilter(kFilterGaussian, 1.5f, 1.5f);
  c.lensRadius = 25.0f;
  c.focalDistance = 1000.0f;  // behind the blocks: they are blurred
}

void mitchellWindowCrop(CameraDesc& c) {
  c.filter = makeFilter(kFilterMitchell, 2.0f, 2.0f);
  c.screenWindow = std::array<float, 4>{-0.6f, 1.0f, -1.0f, 0.6f};
  c.cropWindow = std::array<float, 4>{0.0f, 0.75f, 0.25f, 1.0f};
}

Image renderCpuImage(const SceneData& data, int spp) {
  Film film(int(data.params.camera.width), int(data.params.camera.height));
  const CpuRenderStats stats = renderCpu(data, test::cpuOptions(2, spp), film);
  EXPECT_EQ(stats.invalidSamples, 0u);
  return film.resolve();
}

// A crop renders exactly its pixels of the whole film's image: the random numbers and the
// rays are the film pixel's. For the box (vector lanes) and for filters and lenses (filter.h
// lane by lane).
TEST(CameraCrop, RendersTheWholeImagesPixelsBitForBit) {
  for (auto* setUp : {+[](CameraDesc&) {}, +[](CameraDesc& c) { thinLensAndGaussian(c); }}) {
    const SceneData whole = cornellWithCamera(16, setUp);
    const SceneData crop = cornellWithCamera(16, [&](CameraDesc& c) {
      setUp(c);
      c.pixelBounds = std::array<int, 4>{3, 14, 6, 11};
    });
    ASSERT_EQ(crop.params.camera.width, 11u);
    ASSERT_EQ(crop.params.camera.height, 5u);
    const Image a = renderCpuImage(whole, 2), b = renderCpuImage(crop, 2);
    for (int y = 0; y < b.height; ++y) {
      for (int x = 0; x < b.width; ++x) {
        ASSERT_EQ(0, std::memcmp(&b.at(x, y), &a.at(x + 3, y + 6), sizeof(vec3))) << x << "," << y;
      }
    }
    // sampleRadiance, the reference (and --debug-pixel), takes the crop's pixels likewise.
    uint64_t rays = 0;
    const vec3 l1 = sampleRadiance(crop, uvec2(2, 1), 0, rays);
    const vec3 l2 = sampleRadiance(whole, uvec2(5, 7), 0, rays);
    EXPECT_EQ(0, std::memcmp(&l1, &l2, sizeof(vec3)));
  }
}

// The lanes (renderCpu) and the reference give the same bits with filters, lenses and crops.
TEST(CameraCrop, LanesEqualTheReference) {
  const SceneData data = cornellWithCamera(12, mitchellWindowCrop);
  const Image image = renderCpuImage(data, 1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      uint64_t rays = 0;
      const vec3 l = sampleRadiance(data, uvec2(uint(x), uint(y)), 0, rays);
      ASSERT_EQ(0, std::memcmp(&l, &image.at(x, y), sizeof(vec3))) << x << "," << y;
    }
  }
}

TEST(CameraAgree, GaussianThinLensOnBothBackends) {
  const SceneData data = cornellWithCamera(24, thinLensAndGaussian);
  expectAgreement(renderBoth(data, 8));
}

TEST(CameraAgree, MitchellScreenWindowCropOnBothBackends) {
  const SceneData data = cornellWithCamera(24, mitchellWindowCrop);
  ASSERT_EQ(data.params.camera.width, 18u);
  expectAgreement(renderBoth(data, 8));
}

// On lavapipe too, a crop is its pixels of the whole image, bit for bit.
TEST(CameraAgree, VulkanCropIsTheWholeImagesPixels) {
  const SceneData whole = cornellWithCamera(16, thinLensAndGaussian);
  const SceneData crop = cornellWithCamera(16, [](CameraDesc& c) {
    thinLensAndGaussian(c);
    c.cropWindow = std::array<float, 4>{0.25f, 0.75f, 0.5f, 1.0f};
  });
  Film a(16, 16), b(8, 8);
  renderVulkan(whole, validatedOptions(2), a);
  renderVulkan(crop, validatedOptions(2), b);
  const Image ia = a.resolve(), ib = b.resolve();
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      ASSERT_EQ(0, std::memcmp(&ib.at(x, y), &ia.at(x + 4, y + 8), sizeof(vec3))) << x << "," << y;
    }
  }
}

// ---- the JSON camera -----------------------------------------------------------------------

std::string withCamera(const test::TempDir& dir, const std::string& camera) {
  const std::string text = R"({"camera": )" + camera + R"(,
    "materials": [{"name": "white"}],
    "shapes": [{"type": "quad", "material": "white",
                "vertices": [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]}]})";
  return dir.write("scene.json", text).string();
}

TEST(CameraJson, OptionsAsPbrtV4Names) {
  test::TempDir dir;
  Scene scene = loadScene(withCamera(dir, R"({"width": 20, "height": 10})"));
  // Today's camera by default: the box of one pixel, a pinhole, the whole film.
  EXPECT_EQ(scene.camera.filter.type, kFilterBox);
  EXPECT_EQ(scene.camera.filter.radiusX, 0.5f);
  EXPECT_EQ(scene.camera.lensRadius, 0.0f);
  EXPECT_FALSE(scene.camera.screenWindow || scene.camera.cropWindow || scene.camera.pixelBounds);
  scene = loadScene(withCamera(dir, R"({"width": 20, "height": 10,
      "filter": {"type": "gaussian", "radius": [1, 2], "sigma": 0.7},
      "lensRadius": 0.5, "focalDistance": 12, "screenWindow": [-1, 3, -2, 2],
      "cropWindow": [0.25, 0.5, 0, 1]})"));
  EXPECT_EQ(scene.camera.filter.type, kFilterGaussian);
  EXPECT_EQ(scene.camera.filter.radiusX, 1.0f);
  EXPECT_EQ(scene.camera.filter.radiusY, 2.0f);
  EXPECT_EQ(scene.camera.filter.sigma, 0.7f);
  EXPECT_EQ(scene.camera.lensRadius, 0.5f);
  EXPECT_EQ(scene.camera.focalDistance, 12.0f);
  EXPECT_EQ(scene.camera.screenWindow, (std::array<float, 4>{-1, 3, -2, 2}));
  EXPECT_EQ(scene.camera.cropWindow, (std::array<float, 4>{0.25f, 0.5f, 0, 1}));
  scene = loadScene(withCamera(dir, R"({"filter": {"type": "mitchell", "B": 0, "C": 0.5},
      "pixelBounds": [1, 3, 2, 4]})"));
  EXPECT_EQ(scene.camera.filter.radiusX, 2.0f);  // pbrt-v4's default radius for mitchell
  EXPECT_EQ(scene.camera.filter.b, 0.0f);
  EXPECT_EQ(scene.camera.filter.c, 0.5f);
  EXPECT_EQ(scene.camera.pixelBounds, (std::array<int, 4>{1, 3, 2, 4}));
  scene = loadScene(withCamera(dir, R"({"filter": {"type": "triangle"}})"));
  EXPECT_EQ(scene.camera.filter.radiusY, 2.0f);
}

TEST(CameraJson, BadValuesAreOneLineErrorsNamingTheField) {
  test::TempDir dir;
  auto error = [&](const std::string& camera) {
    const std::string path = withCamera(dir, camera);
    try {
      loadScene(path);
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_EQ(message.rfind(path + ": camera", 0), 0u) << message;
      return message.substr(path.size() + 2);
    }
    return std::string("no error");
  };
  EXPECT_EQ(error(R"({"filter": {"type": "gausian"}})"),
            "camera.filter.type: unknown filter type 'gausian' (did you mean 'gaussian'?)");
  EXPECT_EQ(error(R"({"filter": {"type": "box", "sigma": 1}})"),
            "camera.filter.sigma: unknown key (expected 'type' or 'radius')");
  EXPECT_EQ(error(R"({"filter": {"type": "gaussian", "sigma": -1}})"),
            "camera.filter.sigma: expected a positive number, got the number -1");
  EXPECT_EQ(error(R"({"filter": {"type": "gaussian", "radius": [1, 0]}})"),
            "camera.filter.radius[1]: expected a radius in (0, 4096] pixels, got the number 0");
  EXPECT_EQ(error(R"({"filter": {"type": "gaussian", "radius": 0.5, "sigma": 10}})"),
            "camera.filter: gaussian filter: sigma 10 is too wide for radius 0.5 (the filter is "
            "within 0.1 % of a box there: use \"box\")");
  EXPECT_EQ(error(R"({"lensRadius": -1})"),
            "camera.lensRadius: expected a lens radius >= 0 (0: a pinhole), got the number -1");
  EXPECT_EQ(error(R"({"focalDistance": 0})"),
            "camera.focalDistance: expected a positive distance, got the number 0");
  EXPECT_EQ(error(R"({"screenWindow": [0, 0, -1, 1]})"),
            "camera.screenWindow: expected a window of some width and height [x0, x1, y0, y1], "
            "got an array of 4 elements");
  EXPECT_EQ(error(R"({"cropWindow": [0.5, 0.25, 0, 1]})"),
            "camera.cropWindow: expected fractions of the film [x0, x1, y0, y1] with 0 <= x0 < x1 "
            "<= 1 and 0 <= y0 < y1 <= 1");
  EXPECT_EQ(error(R"({"width": 4, "height": 4, "cropWindow": [0.1, 0.2, 0, 1]})"),
            "camera.cropWindow: selects no pixel of the 4x4 film");
  EXPECT_EQ(error(R"({"width": 4, "height": 4, "pixelBounds": [0, 5, 0, 1]})"),
            "camera.pixelBounds: expected pixels [x0, x1) x [y0, y1) of the 4x4 film, x0 < x1 "
            "and y0 < y1");
  EXPECT_EQ(error(R"({"cropWindow": [0, 1, 0, 1], "pixelBounds": [0, 1, 0, 1]})"),
            "camera: give cropWindow or pixelBounds, not both");
}

// ---- --strict ------------------------------------------------------------------------------

TEST(CliStrict, AWarningBecomesExitStatus2AndOneLine) {
  test::TempDir dir;
  const fs::path scene = dir.write(
      "warns.pbrt",
      "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\n"
      "Sampler \"independent\" \"integer pixelsamples\" 1\n"
      "WorldBegin\n"
      "AttributeBegin\n  AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
      "  Shape \"trianglemesh\" \"point3 P\" [-1 -1 3  1 -1 3  0 1 3] \"integer indices\" [0 2 1]\n"
      "AttributeEnd\n"
      "Shape \"curve\" \"point3 P\" [0 0 0 1 0 0 2 0 0 3 0 0]\n");
  const std::string out = " --backend cpu --out " + (dir / "a.exr").string();
  const test::PtResult plain = test::runPt("render " + scene.string() + out);
  EXPECT_EQ(plain.status, 0) << plain.err;
  EXPECT_NE(plain.err.find("warning: " + scene.string() +
                           ":8: Shape \"curve\" skipped: curves (hair) are not supported yet"),
            std::string::npos)
      << plain.err;
  fs::remove(dir / "a.exr");
  const test::PtResult strict = test::runPt("render " + scene.string() + " --strict" + out);
  EXPECT_EQ(strict.status, 2);
  EXPECT_EQ(strict.err,
            scene.string() +
                ":8:1: Shape \"curve\" skipped: curves (hair) are not supported yet (an error "
                "with --strict)\n");
  EXPECT_FALSE(fs::exists(dir / "a.exr"));
  // A file without warnings renders under --strict.
  EXPECT_EQ(test::runPt("render " + (test::kConfigs / "cornell-box.pbrt").string() +
                        " --strict --backend cpu --spp 1 --width 8 --height 8 --out " +
                        (dir / "b.exr").string())
                .status,
            0);
}

}  // namespace
}  // namespace pt
