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

HWY_INLINE V mulAdd(V a, uint32_t m, uint32_t c) {
  const D d;
  return hn::Add(hn::Mul(a, hn::Set(d, m)), hn::Set(d, c));
}

// pcg4d on four inputs at once: lane k of x, y, z and w holds input k's components.
HWY_INLINE void pcg4d(V& x, V& y, V& z, V& w) {
  x = mulAdd(x, 1664525u, 1013904223u);
  y = mulAdd(y, 1664525u, 1013904223u);
  z = mulAdd(z, 1664525u, 1013904223u);
  w = mulAdd(w, 1664525u, 1013904223u);
  x = hn::Add(x, hn::Mul(y, w));
  y = hn::Add(y, hn::Mul(z, x));
  z = hn::Add(z, hn::Mul(x, y));
  w = hn::Add(w, hn::Mul(y, z));
  x = hn::Xor(x, hn::ShiftRight<16>(x));
  y = hn::Xor(y, hn::ShiftRight<16>(y));
  z = hn::Xor(z, hn::ShiftRight<16>(z));
  w = hn::Xor(w, hn::ShiftRight<16>(w));
  x = hn::Add(x, hn::Mul(y, w));
  y = hn::Add(y, hn::Mul(z, x));
  z = hn::Add(z, hn::Mul(x, y));
  // (pcg4d's last step updates w, which no caller reads.)
}

// bitfieldReverse of each lane: a byte swap by table lookup, then the nibbles, pairs and
// bits within each byte, as shared_types.h's C++ version does.
HWY_INLINE V reverseBits(V v) {
  const D d;
  const hn::Repartition<uint8_t, D> d8;
  alignas(16) static constexpr uint8_t kByteSwap[16] = {3,  2,  1, 0, 7,  6,  5,  4,
                                                        11, 10, 9, 8, 15, 14, 13, 12};
  v = hn::BitCast(d, hn::TableLookupBytes(hn::BitCast(d8, v), hn::Load(d8, kByteSwap)));
  const V m4 = hn::Set(d, 0x0F0F0F0Fu), m2 = hn::Set(d, 0x33333333u), m1 = hn::Set(d, 0x55555555u);
  v = hn::Or(hn::ShiftLeft<4>(hn::And(v, m4)), hn::And(hn::ShiftRight<4>(v), m4));
  v = hn::Or(hn::ShiftLeft<2>(hn::And(v, m2)), hn::And(hn::ShiftRight<2>(v), m2));
  return hn::Or(hn::ShiftLeft<1>(hn::And(v, m1)), hn::And(hn::ShiftRight<1>(v), m1));
}

HWY_INLINE V laineKarrasPermutation(V x, V seed) {
  const D d;
  x = hn::Add(x, seed);
  x = hn::Xor(x, hn::Mul(x, hn::Set(d, 0x6C50B47Cu)));
  x = hn::Xor(x, hn::Mul(x, hn::Set(d, 0xB82F1E52u)));
  x = hn::Xor(x, hn::Mul(x, hn::Set(d, 0xC7AFE638u)));
  return hn::Xor(x, hn::Mul(x, hn::Set(d, 0x8D22F6E6u)));
}

HWY_INLINE V sobolSecondDimensionReversed(V y) {
  const D d;
  y = hn::Xor(y, hn::And(hn::ShiftRight<1>(y), hn::Set(d, 0x55555555u)));
  y = hn::Xor(y, hn::And(hn::ShiftRight<2>(y), hn::Set(d, 0x33333333u)));
  y = hn::Xor(y, hn::And(hn::ShiftRight<4>(y), hn::Set(d, 0x0F0F0F0Fu)));
  y = hn::Xor(y, hn::And(hn::ShiftRight<8>(y), hn::Set(d, 0x00FF00FFu)));
  return hn::Xor(y, hn::And(hn::ShiftRight<16>(y), hn::Set(d, 0x0000FFFFu)));
}

BounceRandom bounceRandomLanes(bool sobol, uvec2 pixel, uint sampleIndex, uint dim, uint seed) {
  const D d;
  V x = hn::Set(d, pixel.x), y = hn::Set(d, pixel.y), z, w;
  V ux, uy;  // the 32-bit words whose top 24 bits become the two numbers
  if (sobol) {
    // sobolRandom2: lanes hash (pixel, dimension, seed).
    z = hn::Iota(d, dim);
    w = hn::Set(d, seed * 0x9E3779B9u + 0x7F4A7C15u);
    pcg4d(x, y, z, w);
    const V i = reverseBits(laineKarrasPermutation(hn::Set(d, bitfieldReverse(sampleIndex)), x));
    ux = reverseBits(laineKarrasPermutation(i, y));
    uy = reverseBits(laineKarrasPermutation(sobolSecondDimensionReversed(i), z));
  } else {
    // independentRandom2: lanes hash (pixel, sample, dimension + seed).
    z = hn::Set(d, sampleIndex);
    w = hn::Iota(d, dim + seed * 0x9E3779B9u);
    pcg4d(x, y, z, w);
    ux = x;
    uy = y;
  }
  // The top 24 bits, converted exactly and scaled by 2^-24.
  const hn::RebindToSigned<D> di;
  const hn::Rebind<float, D> df;
  const auto toUnit = [&](V v) {
    return hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(v))),
                   hn::Set(df, 1.0f / 16777216.0f));
  };
  alignas(16) float fx[4], fy[4];
  hn::Store(toUnit(ux), df, fx);
  hn::Store(toUnit(uy), df, fy);
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
