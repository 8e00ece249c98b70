// sampling.h's random2 on vector lanes, each lane with its own pixel and dimension: the
// same 32-bit integer arithmetic (it wraps alike) and the same exact conversion to float, so
// every lane's numbers are random2's bits. For any lane count, in Highway's per-target
// style: a file compiled once per instruction set (foreach_target.h) includes this once per
// set. Used by bounce_random.cpp (the four dimensions of one event in four lanes) and
// integrator_lanes.cpp (one dimension of eight paths). Not for Highway's scalar target:
// those files call the scalar definition there.

// Include guard per target (Highway's convention for "-inl.h" files).
#if defined(PT_CPU_RANDOM_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PT_CPU_RANDOM_LANES_INL_H_
#undef PT_CPU_RANDOM_LANES_INL_H_
#else
#define PT_CPU_RANDOM_LANES_INL_H_
#endif

#include <hwy/highway.h>

#include "common/shared.h"

HWY_BEFORE_NAMESPACE();
namespace pt {
namespace HWY_NAMESPACE {
namespace random_lanes {
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET != HWY_SCALAR

template <class V>
HWY_INLINE V mulAdd(V a, uint32_t m, uint32_t c) {
  const hn::DFromV<V> d;
  return hn::Add(hn::Mul(a, hn::Set(d, m)), hn::Set(d, c));
}

// pcg4d on one input per lane: lane k of x, y, z and w holds input k's components.
template <class V>
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

// bitfieldReverse of each lane: its bytes swapped, then each byte's bits reversed by looking
// up each of its nibbles in a table of their reversals (byte lookups work within each 128-bit
// block, so the tables repeat).
template <class V>
HWY_INLINE V reverseBits(V v) {
  const hn::DFromV<V> d;
  const hn::Repartition<uint8_t, decltype(d)> d8;
  const hn::Repartition<uint16_t, decltype(d)> d16;
  alignas(32) static constexpr uint8_t kByteSwap[32] = {3, 2,  1,  0,  7,  6, 5,  4,  11, 10, 9,
                                                        8, 15, 14, 13, 12, 3, 2,  1,  0,  7,  6,
                                                        5, 4,  11, 10, 9,  8, 15, 14, 13, 12};
  // Nibble n reversed, in a byte's low half (kLow) and its high half (kHigh).
  alignas(32) static constexpr uint8_t kLow[32] = {
      0x0, 0x8, 0x4, 0xC, 0x2, 0xA, 0x6, 0xE, 0x1, 0x9, 0x5, 0xD, 0x3, 0xB, 0x7, 0xF,
      0x0, 0x8, 0x4, 0xC, 0x2, 0xA, 0x6, 0xE, 0x1, 0x9, 0x5, 0xD, 0x3, 0xB, 0x7, 0xF};
  alignas(32) static constexpr uint8_t kHigh[32] = {0x00, 0x80, 0x40, 0xC0, 0x20, 0xA0, 0x60, 0xE0,
                                                    0x10, 0x90, 0x50, 0xD0, 0x30, 0xB0, 0x70, 0xF0,
                                                    0x00, 0x80, 0x40, 0xC0, 0x20, 0xA0, 0x60, 0xE0,
                                                    0x10, 0x90, 0x50, 0xD0, 0x30, 0xB0, 0x70, 0xF0};
  static_assert(hn::MaxLanes(d8) <= 32);
  const auto bytes = hn::TableLookupBytes(hn::BitCast(d8, v), hn::Load(d8, kByteSwap));
  const auto nibble = hn::Set(d8, uint8_t{0x0F});
  const auto low = hn::And(bytes, nibble);
  const auto high = hn::And(hn::BitCast(d8, hn::ShiftRight<4>(hn::BitCast(d16, bytes))), nibble);
  // The low nibble reversed becomes the high one, and the other way round.
  return hn::BitCast(d, hn::Or(hn::TableLookupBytes(hn::Load(d8, kHigh), low),
                               hn::TableLookupBytes(hn::Load(d8, kLow), high)));
}

template <class V>
HWY_INLINE V laineKarrasPermutation(V x, V seed) {
  const hn::DFromV<V> d;
  x = hn::Add(x, seed);
  x = hn::Xor(x, hn::Mul(x, hn::Set(d, 0x6C50B47Cu)));
  x = hn::Xor(x, hn::Mul(x, hn::Set(d, 0xB82F1E52u)));
  x = hn::Xor(x, hn::Mul(x, hn::Set(d, 0xC7AFE638u)));
  return hn::Xor(x, hn::Mul(x, hn::Set(d, 0x8D22F6E6u)));
}

template <class V>
HWY_INLINE V sobolSecondDimensionReversed(V y) {
  const hn::DFromV<V> d;
  y = hn::Xor(y, hn::And(hn::ShiftRight<1>(y), hn::Set(d, 0x55555555u)));
  y = hn::Xor(y, hn::And(hn::ShiftRight<2>(y), hn::Set(d, 0x33333333u)));
  y = hn::Xor(y, hn::And(hn::ShiftRight<4>(y), hn::Set(d, 0x0F0F0F0Fu)));
  y = hn::Xor(y, hn::And(hn::ShiftRight<8>(y), hn::Set(d, 0x00FF00FFu)));
  return hn::Xor(y, hn::And(hn::ShiftRight<16>(y), hn::Set(d, 0x0000FFFFu)));
}

// random2(sobol, (pixelX, pixelY), sampleIndex, dimension, seed) of each lane, as floats:
// ux gets the numbers' .x, uy their .y.
template <class V, class VF>
HWY_INLINE void random2(bool sobol, V pixelX, V pixelY, uint sampleIndex, V dimension, uint seed,
                        VF& ux, VF& uy) {
  const hn::DFromV<V> d;
  V x = pixelX, y = pixelY, z, w;
  V hx, hy;  // the 32-bit words whose top 24 bits become the two numbers
  if (sobol) {
    // sobolRandom2: lanes hash (pixel, dimension, seed).
    z = dimension;
    w = hn::Set(d, seed * 0x9E3779B9u + 0x7F4A7C15u);
    pcg4d(x, y, z, w);
    const V i = reverseBits(laineKarrasPermutation(hn::Set(d, bitfieldReverse(sampleIndex)), x));
    hx = reverseBits(laineKarrasPermutation(i, y));
    hy = reverseBits(laineKarrasPermutation(sobolSecondDimensionReversed(i), z));
  } else {
    // independentRandom2: lanes hash (pixel, sample, dimension + seed).
    z = hn::Set(d, sampleIndex);
    w = hn::Add(dimension, hn::Set(d, seed * 0x9E3779B9u));
    pcg4d(x, y, z, w);
    hx = x;
    hy = y;
  }
  // The top 24 bits, converted exactly and scaled by 2^-24.
  const hn::RebindToSigned<decltype(d)> di;
  const hn::Rebind<float, decltype(d)> df;
  const auto toUnit = [&](V v) {
    return hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(v))),
                   hn::Set(df, 1.0f / 16777216.0f));
  };
  ux = toUnit(hx);
  uy = toUnit(hy);
}

#endif  // HWY_TARGET != HWY_SCALAR

}  // namespace random_lanes
}  // namespace HWY_NAMESPACE
}  // namespace pt
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
