// The random numbers both integrators draw (shaders/sampling.h): the Owen-scrambled Sobol
// points keep their stratification, differ between pixels and dimensions, and integrate
// better than independent numbers while staying unbiased.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>
#include <set>

#include "common/shared.h"
#include "cpu/bounce_random.h"
#include "test_util.h"

namespace pt {
namespace {

// Sobol's second dimension from its direction numbers, the textbook way: v_0 = 2^31,
// v_k = v_(k-1) xor (v_(k-1) >> 1), and the point is the XOR of v_k over the index's bits.
uint sobolSecondDimensionByDirectionNumbers(uint index) {
  uint result = 0, v = 1u << 31;
  for (; index != 0; index >>= 1, v ^= v >> 1) {
    if (index & 1u) result ^= v;
  }
  return result;
}

TEST(SobolSampler, SecondDimensionMatchesItsDirectionNumbers) {
  std::mt19937 rng(5);
  for (uint i = 0; i < 70000; ++i) {
    const uint index = i < 5000 ? i : uint(rng());
    ASSERT_EQ(sobolSecondDimension(index), sobolSecondDimensionByDirectionNumbers(index))
        << "index " << index;
  }
}

TEST(SobolSampler, NestedScrambleIsABijectionThatKeepsPrefixes) {
  // Each bit may only depend on the bits above it: values sharing their top k bits still
  // share them after the scramble, and no two values collide.
  std::set<uint> seen;
  for (uint x = 0; x < 4096; ++x) {
    const uint a = nestedUniformScramble(x << 20, 0x12345678u);
    EXPECT_TRUE(seen.insert(a).second);
    EXPECT_EQ(nestedUniformScramble((x << 20) | 0xFFFFFu, 0x12345678u) >> 20, a >> 20);
  }
}

TEST(SobolSampler, FastBitReversalIsGlmsAndTheShortcutsAreTheDefinition) {
  // shared_types.h's bitfieldReverse stands in for GLM's (and GLSL's) in the C++ build, and
  // sobolRandom2 leaves out reversals that cancel: both must keep every bit.
  uint state = 12345u;
  for (int n = 0; n < 100000; ++n) {
    state = state * 747796405u + 2891336453u;
    const uint x = state ^ (state >> 13u);
    ASSERT_EQ(bitfieldReverse(x), glm::bitfieldReverse(x)) << "x " << x;
  }
  for (uint dimension = 0; dimension < 8; ++dimension) {
    for (uint index = 0; index < 512; ++index) {
      const uvec2 pixel(index * 7u % 61u, dimension * 3u + 5u);
      const uvec4 h = pcg4d(uvec4(pixel.x, pixel.y, dimension, 9u * 0x9E3779B9u + 0x7F4A7C15u));
      const uint i = nestedUniformScramble(index, h.x);
      const uint x = nestedUniformScramble(glm::bitfieldReverse(i), h.y);
      const uint y = nestedUniformScramble(sobolSecondDimension(i), h.z);
      const vec2 expected = vec2(float(x >> 8u), float(y >> 8u)) * (1.0f / 16777216.0f);
      const vec2 got = sobolRandom2(pixel, index, dimension, 9u);
      ASSERT_EQ(got.x, expected.x) << "dimension " << dimension << " index " << index;
      ASSERT_EQ(got.y, expected.y) << "dimension " << dimension << " index " << index;
    }
  }
}

// Every elementary interval of area 2^-k (2^a columns by 2^(k-a) rows) holds exactly one
// of the 2^k points with indices first .. first + 2^k - 1.
void expectNet(uvec2 pixel, uint dimension, uint seed, uint first, int k) {
  const uint n = 1u << k;
  for (int a = 0; a <= k; ++a) {
    std::set<std::pair<uint, uint>> cells;
    for (uint i = first; i < first + n; ++i) {
      const vec2 u = sobolRandom2(pixel, i, dimension, seed);
      ASSERT_TRUE(u.x >= 0.0f && u.x < 1.0f && u.y >= 0.0f && u.y < 1.0f);
      cells.insert({uint(u.x * float(1u << a)), uint(u.y * float(1u << (k - a)))});
    }
    EXPECT_EQ(cells.size(), n) << "k=" << k << " a=" << a << " first=" << first;
  }
}

TEST(BounceRandomSimd, EqualsTheScalarDefinitionOnEveryTarget) {
  // The CPU reference's vector version of one scattering event's numbers gives the bits of
  // the definition that the shader uses, on every instruction set it may run on here, for
  // both samplers: small and extreme pixels, samples, dimensions and seeds, then random ones.
  const uint edge[] = {0u, 1u, 2u, 255u, 65535u, 0x7FFFFFFFu, 0xFFFFFFFCu, 0xFFFFFFFFu};
  test::forEachHighwayTarget(bounceRandomTargets(), [&] {
    std::mt19937 rng(11);
    for (int i = 0; i < 40000; ++i) {
      const bool sobol = i % 2 == 0;
      const uvec2 pixel =
          i < 4096 ? uvec2(edge[i % 8], edge[(i / 8) % 8]) : uvec2(rng() % 4096u, rng() % 4096u);
      const uint sampleIndex = i < 4096 ? edge[(i / 64) % 8] : uint(rng());
      const uint dim = i < 4096 ? kDimFirstBounce + kDimsPerBounce * uint(i % 13) : uint(rng());
      const uint seed = i < 4096 ? edge[(i / 512) % 8] : uint(rng());
      const BounceRandom a = bounceRandom(sobol, pixel, sampleIndex, dim, seed);
      const BounceRandom b = bounceRandomSimd(sobol, pixel, sampleIndex, dim, seed);
      const float expected[8] = {a.lightChoose.x, a.lightChoose.y, a.lightPoint.x, a.lightPoint.y,
                                 a.bsdf.x,        a.bsdf.y,        a.roulette.x,   a.roulette.y};
      const float actual[8] = {b.lightChoose.x, b.lightChoose.y, b.lightPoint.x, b.lightPoint.y,
                               b.bsdf.x,        b.bsdf.y,        b.roulette.x,   b.roulette.y};
      for (int k = 0; k < 8; ++k) {
        ASSERT_EQ(std::bit_cast<uint32_t>(actual[k]), std::bit_cast<uint32_t>(expected[k]))
            << "number " << k << " of sobol=" << sobol << " pixel (" << pixel.x << ", " << pixel.y
            << ") sample " << sampleIndex << " dim " << dim << " seed " << seed;
      }
    }
  });
}

TEST(SobolSampler, EveryAlignedPowerOfTwoBlockIsANet) {
  for (uvec2 pixel : {uvec2(0, 0), uvec2(17, 3), uvec2(255, 255)}) {
    for (uint dimension : {0u, 1u, 9u}) {
      for (int k = 0; k <= 10; ++k) {
        expectNet(pixel, dimension, 0u, 0u, k);       // the first 2^k samples
        expectNet(pixel, dimension, 7u, 1u << k, k);  // the next 2^k (another seed)
      }
    }
  }
}

TEST(SobolSampler, PixelsAndDimensionsAreDecorrelated) {
  // Neighbouring pixels and successive dimensions get different scrambles and orders: the
  // sample-by-sample correlation between them is what independent numbers would show.
  constexpr int kN = 4096;
  auto correlation = [](auto a, auto b) {
    double sa = 0, sb = 0, sab = 0, saa = 0, sbb = 0;
    for (uint i = 0; i < kN; ++i) {
      const double x = a(i), y = b(i);
      sa += x, sb += y, sab += x * y, saa += x * x, sbb += y * y;
    }
    const double cov = sab / kN - sa / kN * sb / kN;
    return cov / std::sqrt((saa / kN - sa / kN * sa / kN) * (sbb / kN - sb / kN * sb / kN));
  };
  const uvec2 p(10, 20);
  const double bound = 4.0 / std::sqrt(double(kN));  // four standard deviations
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT(std::abs(correlation([&](uint i) { return sobolRandom2(p, i, 3, 0)[c]; },
                                   [&](uint i) { return sobolRandom2(p, i, 4, 0)[c]; })),
              bound);
    EXPECT_LT(
        std::abs(correlation([&](uint i) { return sobolRandom2(p, i, 3, 0)[c]; },
                             [&](uint i) { return sobolRandom2(p + uvec2(1, 0), i, 3, 0)[c]; })),
        bound);
    EXPECT_LT(std::abs(correlation([&](uint i) { return sobolRandom2(p, i, 3, 0)[c]; },
                                   [&](uint i) { return sobolRandom2(p, i, 3, 1)[c]; })),
              bound);
  }
}

// Estimates of the integral of f over the unit square from `n` points in each of 1024
// pixels: their mean squared error against `exact`, and the mean estimate's standard error.
struct Integration {
  double mse, mean, standardError;
};
template <class F, class Sampler>
Integration integrateWith(F f, double exact, int n, Sampler sampler) {
  constexpr int kPixels = 1024;
  double se = 0, sum = 0, sq = 0;
  for (uint p = 0; p < kPixels; ++p) {
    double estimate = 0;
    for (int i = 0; i < n; ++i) estimate += f(sampler(uvec2(p % 32, p / 32), uint(i)));
    estimate /= n;
    se += (estimate - exact) * (estimate - exact);
    sum += estimate;
    sq += estimate * estimate;
  }
  const double mean = sum / kPixels;
  return {se / kPixels, mean, std::sqrt((sq / kPixels - mean * mean) / (kPixels - 1))};
}

TEST(SobolSampler, UnbiasedAndMoreAccurateThanIndependentNumbers) {
  auto sobol = [](uvec2 p, uint i) { return sobolRandom2(p, i, 5, 0); };
  auto independent = [](uvec2 p, uint i) { return independentRandom2(p, i, 5, 0); };
  // A discontinuous integrand, like a light's edge: the quarter disc, area pi / 4.
  auto disc = [](vec2 u) { return double(u.x * u.x + u.y * u.y < 1.0f); };
  // A smooth one, like the cosine falloff of direct light.
  auto smooth = [](vec2 u) { return std::exp(-double(u.x) * double(u.y)); };
  const double discArea = kPi / 4.0;
  double smoothExact = 0;  // integral of exp(-xy) = sum over k of (-1)^k / (k! (k+1)^2)
  for (int k = 0, fact = 1; k < 12; ++k, fact *= std::max(k, 1)) {
    smoothExact += (k % 2 ? -1.0 : 1.0) / (double(fact) * (k + 1) * (k + 1));
  }
  for (int n : {16, 256}) {
    SCOPED_TRACE(std::to_string(n) + " samples");
    const Integration sd = integrateWith(disc, discArea, n, sobol);
    const Integration id = integrateWith(disc, discArea, n, independent);
    EXPECT_NEAR(sd.mean, discArea, 4.0 * sd.standardError);  // unbiased
    EXPECT_NEAR(id.mean, discArea, 4.0 * id.standardError);
    // Owen-scrambled nets: variance about n^-1.5 instead of n^-1 for the disc's edge, and
    // n^-3 for smooth integrands. Asked for with a margin: half and 1/n of those gains.
    EXPECT_LT(sd.mse, id.mse / (0.5 * std::sqrt(double(n))));
    const Integration ss = integrateWith(smooth, smoothExact, n, sobol);
    const Integration is = integrateWith(smooth, smoothExact, n, independent);
    // (Numbers are truncated to 24 bits, which moves the mean by about 3e-8: allowed for.)
    EXPECT_NEAR(ss.mean, smoothExact, 4.0 * ss.standardError + 1e-7);
    EXPECT_LT(ss.mse, is.mse / double(n));
  }
}

}  // namespace
}  // namespace pt
