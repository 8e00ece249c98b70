// The CPU reference's paths several at a time: sampleRadiance (integrator.h) for up to eight
// pixels in the lanes of x86 vector registers. Each lane performs the reference's float
// operations in its order (no fused multiply-adds, IEEE division and square root, its
// comparisons and its selections), so each pixel's radiance is the reference's bit for bit
// (CpuLanes.EqualsTheReferenceBitForBit); traversal stays the wide BVH's queries, called lane
// by lane. renderCpu traces with this; the reference, sampleRadiance, stays the readable
// definition and serves --debug-pixel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/prepare.h"

namespace pt {

// out[i] = sampleRadiance(scene, pixels[i], sampleIndex, rays) for i < count; `rays` is
// incremented by the rays traced. A lane whose path ends takes the next pixel, so the lanes
// stay busy until the last paths. The instruction set is chosen at run time (AVX2: eight
// lanes; SSE4 or SSSE3: four; otherwise one).
void sampleRadianceLanes(const SceneData& scene, const uvec2* pixels, size_t count,
                         uint32_t sampleIndex, vec3* out, uint64_t& rays);

// The instruction sets (Highway target bits) compiled and runnable here, for tests.
std::vector<int64_t> radianceLanesTargets();

}  // namespace pt
