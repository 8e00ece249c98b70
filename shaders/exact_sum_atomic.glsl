// The exact sum of floats on the device, by 64-bit integer atomics: host/image/exact_sum.h's
// 320-bit fixed point (five little-endian limbs in units of 2^-149, two's complement), each
// float added to the one or two limbs its bits fall in and the carry (or borrow) passed up by
// further atomics. Every limb's overflow passes exactly one carry to the next, whatever order
// the invocations' atomics run in, so the limbs end as the exact sum of all floats added: the
// same bits on every run, and the host's ExactSum of the same floats. PT_EXACT_SUM_LIMBS names
// the uint64_t array the limbs live in.
#ifndef PT_EXACT_SUM_ATOMIC_GLSL
#define PT_EXACT_SUM_ATOMIC_GLSL

PT_CONST uint kExactSumLimbs = 5u;

// Adds finite float x to the sum whose limbs are PT_EXACT_SUM_LIMBS[base .. base + 4].
void exactSumAtomicAdd(uint base, float x) {
  uint bits = floatBitsToUint(x);
  uint biased = (bits >> 23u) & 0xFFu;
  uint m = bits & 0x7FFFFFu;
  if (m == 0u && biased == 0u) return;  // +0 and -0
  int p = 0;                            // position of m's lowest bit, in units of 2^-149
  if (biased != 0u) {
    m |= 0x800000u;
    p = int(biased) - 1;
  }
  uint q = uint(p >> 6);
  int r = p & 63;
  uint64_t lo = uint64_t(m) << r;
  uint64_t hi = r > 40 ? uint64_t(m) >> (64 - r) : 0ul;  // m has 24 bits: none cross for r <= 40
  if ((bits >> 31u) == 0u) {
    uint64_t before = atomicAdd(PT_EXACT_SUM_LIMBS[base + q], lo);
    uint64_t carry = (before + lo < before ? 1ul : 0ul) + hi;  // hi < 2^23: no overflow
    for (uint i = q + 1u; i < kExactSumLimbs && carry != 0ul; ++i) {
      PT_LOOP_TICK();
      before = atomicAdd(PT_EXACT_SUM_LIMBS[base + i], carry);
      carry = before + carry < before ? 1ul : 0ul;
    }
  } else {
    uint64_t before = atomicAdd(PT_EXACT_SUM_LIMBS[base + q], 0ul - lo);
    uint64_t borrow = (before < lo ? 1ul : 0ul) + hi;
    for (uint i = q + 1u; i < kExactSumLimbs && borrow != 0ul; ++i) {
      PT_LOOP_TICK();
      before = atomicAdd(PT_EXACT_SUM_LIMBS[base + i], 0ul - borrow);
      borrow = before < borrow ? 1ul : 0ul;
    }
  }
}

#endif  // PT_EXACT_SUM_ATOMIC_GLSL
