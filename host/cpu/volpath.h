// The CPU reference's volume integrator: pbrt-v4's VolPathIntegrator (delta tracking, ratio
// tracking of shadow rays, spectral MIS over the channels), for scenes with media.
#pragma once

#include <cstdint>

#include "render/prepare.h"

namespace pt {

// Radiance along one path sample of image pixel (x, y), as sampleRadiance (integrator.h),
// which calls it for a scene with media.
vec3 sampleRadianceVolume(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex, uint64_t& rays,
                          bool debugPrint = false);

}  // namespace pt
