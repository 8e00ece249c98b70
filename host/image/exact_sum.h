// ExactSum: the exact sum of any number of floats, as a 320-bit fixed-point integer. The
// film keeps one per pixel and channel, so its sums do not depend on the order of additions:
// a render split across threads, passes, interruptions or machines sums to the same bits.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

namespace pt {

// Every finite float is m * 2^(p - 149) with an integer m < 2^24 and 0 <= p <= 253, so a
// two's-complement integer in units of 2^-149 (the smallest float) holds any sum of floats
// without rounding: 278 bits for one float, and the 42 bits left over absorb the carries of
// more than 2^41 additions of the largest float. Adding is exact, so it is associative and
// commutative; only toDouble() rounds, once.
struct ExactSum {
  static constexpr int kLimbs = 5;
  uint64_t limb[kLimbs] = {};  // little-endian: limb[0] holds the units of 2^-149

  // Adds a finite float (the caller keeps NaN and infinities out).
  void add(float x) {
    const uint32_t bits = std::bit_cast<uint32_t>(x);
    const uint32_t biased = (bits >> 23) & 0xFFu;
    uint64_t m = bits & 0x7FFFFFu;
    if (m == 0 && biased == 0) return;  // +0 and -0
    int p = 0;                          // position of m's lowest bit, in units of 2^-149
    if (biased != 0) {
      m |= 0x800000u;
      p = int(biased) - 1;
    }
    const int q = p >> 6, r = p & 63;
    const uint64_t lo = m << r;
    const uint64_t hi = r > 40 ? m >> (64 - r) : 0;  // m has 24 bits: none cross for r <= 40
    if (bits >> 31) {
      subtractAt(q, lo, hi);
    } else {
      addAt(q, lo, hi);
    }
  }

  void add(const ExactSum& other) {
    uint64_t carry = 0;
    for (int i = 0; i < kLimbs; ++i) {
      const uint64_t a = limb[i] + carry;
      const uint64_t b = a + other.limb[i];
      carry = uint64_t(a < carry) + uint64_t(b < a);
      limb[i] = b;
    }
  }

  bool operator==(const ExactSum&) const = default;

  // The sum rounded to the nearest double (ties to even): the same bits whatever order the
  // floats were added in.
  double toDouble() const {
    const bool negative = (limb[kLimbs - 1] >> 63) != 0;
    if (!negative) return magnitudeToDouble(limb);
    uint64_t mag[kLimbs];  // two's complement: magnitude = ~x + 1
    bool carry = true;
    for (int i = 0; i < kLimbs; ++i) {
      mag[i] = ~limb[i] + uint64_t(carry);
      carry = carry && mag[i] == 0;
    }
    return -magnitudeToDouble(mag);
  }

 private:
  static double magnitudeToDouble(const uint64_t (&mag)[kLimbs]) {
    int top = kLimbs - 1;
    while (top >= 0 && mag[top] == 0) --top;
    if (top < 0) return 0.0;
    // The 64 bits from the highest set bit down, with every bit below them folded into the
    // lowest one ("sticky"): converting that to double rounds exactly as rounding the whole
    // number would, since 64 bits leave more than two below the 53 kept.
    const int msb = 64 * top + 63 - std::countl_zero(mag[top]);
    uint64_t window = mag[0];
    int low = 0;  // bit position of window's lowest bit
    if (msb >= 64) {
      low = msb - 63;
      const int q = low >> 6, r = low & 63;
      window = r == 0 ? mag[q] : (mag[q] >> r) | (mag[q + 1] << (64 - r));
      bool sticky = r != 0 && (mag[q] << (64 - r)) != 0;
      for (int i = 0; i < q && !sticky; ++i) sticky = mag[i] != 0;
      window |= uint64_t(sticky);
    }
    // Times 2^(low - 149), a normal double for every low in [0, 256]: exact.
    const double scale = std::bit_cast<double>(uint64_t(1023 + low - 149) << 52);
    return double(window) * scale;
  }

  void addAt(int q, uint64_t lo, uint64_t hi) {
    limb[q] += lo;
    uint64_t carry = uint64_t(limb[q] < lo) + hi;  // hi < 2^23: no overflow
    for (int i = q + 1; i < kLimbs && carry != 0; ++i) {
      limb[i] += carry;
      carry = limb[i] < carry;
    }
  }

  void subtractAt(int q, uint64_t lo, uint64_t hi) {
    uint64_t borrow = limb[q] < lo;
    limb[q] -= lo;
    borrow += hi;
    for (int i = q + 1; i < kLimbs && borrow != 0; ++i) {
      const uint64_t before = limb[i];
      limb[i] -= borrow;
      borrow = before < borrow;
    }
  }
};

}  // namespace pt
