// The random numbers of one scattering event in x86 vector instructions: sampling.h's
// bounceRandom, the same bits, with the four dimensions' hashes and scrambles computed in
// the four lanes of one vector instead of one after another. The CPU reference calls it once
// per path vertex; the sampler's integer arithmetic was about a sixth of its time.
#pragma once

#include <cstdint>
#include <vector>

#include "common/shared.h"

namespace pt {

// bounceRandom(sobol, pixel, sampleIndex, dim, seed), with the instruction set chosen at run
// time (AVX2, SSE4 or SSSE3; on older CPUs the scalar code).
BounceRandom bounceRandomSimd(bool sobol, uvec2 pixel, uint sampleIndex, uint dim, uint seed);

// The instruction sets (Highway target bits) compiled and runnable here, for tests that
// check each against the scalar definition (hwy::SetSupportedTargetsForTest).
std::vector<int64_t> bounceRandomTargets();

}  // namespace pt
