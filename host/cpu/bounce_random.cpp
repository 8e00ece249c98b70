// sampling.h's bounceRandom with the four dimensions in the lanes of one 128-bit vector.
// Compiled once per x86 instruction set that Highway targets here (foreach_target.h includes
// this file once for each) and dispatched at run time, like the wide BVH's traversal. Lane k
// computes, operation for operation, what random2 computes for dimension dim + k: 32-bit
// integer arithmetic that wraps, then an exact conversion to float, so the bits are the
// scalar code's (BounceRandomSimd.EqualsTheScalarDefinition checks every target).
#include <cstdint>
#include <vector>

#ifndef HWY_DISABLED_TARGETS  // AVX-512 would only repeat AVX2's 128-bit code
#define HWY_DISABLED_TARGETS (HWY_AVX3 | HWY_AVX3_DL)
#endif
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "cpu/bounce_random.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "cpu/bounce_random.h"
#include "cpu/random_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pt {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lanes are the dimensions in the order of BounceRandom's members.
static_assert(kDimLightChoose == 0u && kDimLightPoint == 1u && kDimBsdf == 2u &&
              kDimRoulette == 3u && kDimsPerBounce == 4u);

#if HWY_TARGET == HWY_SCALAR

// Highway's one-lane fallback, for CPUs without SSSE3: the scalar definition itself.
BounceRandom bounceRandomLanes(bool sobol, uvec2 pixel, uint sampleIndex, uint dim, uint seed) {
  return bounceRandom(sobol, pixel, sampleIndex, dim, seed);
}

#else  // vector instructions

using D = hn::FixedTag<uint32_t, 4>;
using V = hn::Vec<D>;

BounceRandom bounceRandomLanes(bool sobol, uvec2 pixel, uint sampleIndex, uint dim, uint seed) {
  const D d;
  const hn::Rebind<float, D> df;
  hn::Vec<decltype(df)> ux, uy;
  random_lanes::random2(sobol, hn::Set(d, pixel.x), hn::Set(d, pixel.y), sampleIndex,
                        hn::Iota(d, dim), seed, ux, uy);
  alignas(16) float fx[4], fy[4];
  hn::Store(ux, df, fx);
  hn::Store(uy, df, fy);
  BounceRandom u;
  u.lightChoose = vec2(fx[0], fy[0]);
  u.lightPoint = vec2(fx[1], fy[1]);
  u.bsdf = vec2(fx[2], fy[2]);
  u.roulette = vec2(fx[3], fy[3]);
  return u;
}

#endif  // HWY_TARGET == HWY_SCALAR

}  // namespace HWY_NAMESPACE
}  // namespace pt
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace pt {

HWY_EXPORT(bounceRandomLanes);

BounceRandom bounceRandomSimd(bool sobol, uvec2 pixel, uint sampleIndex, uint dim, uint seed) {
  return HWY_DYNAMIC_DISPATCH(bounceRandomLanes)(sobol, pixel, sampleIndex, dim, seed);
}

std::vector<int64_t> bounceRandomTargets() {
  return hwy::SupportedAndGeneratedTargets();
}

}  // namespace pt
#endif  // HWY_ONCE
