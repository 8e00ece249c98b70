// An environment image's texels and sampling distribution, as shaders/environment.h reads them
// on both backends.
#pragma once

#include <vector>

#include "common/shared.h"
#include "environment.h"
#include "image/image.h"

namespace pt {

// Whether light sampling in MIS renders draws from pbrt-v4's "compensated" distribution (the
// image's weights less their mean, clamped at 0: directions BSDF sampling already finds well
// are left to it) rather than the image's own. Measured (environment_test.cpp's
// MeasureCompensation: diffuse plane and cube, a rough conductor sphere, 48 x 48, MIS at 16 spp,
// relMSE against 4096 spp, mean of 8 runs): a sky with a small sun 0.0264 without, 0.0156 with;
// a smooth sky 0.0080 without, 0.0058 with. Renders with light sampling alone always take the
// complete distribution (the compensated one has no density where the image is dim, which only
// BSDF sampling would then reach).
inline constexpr bool kEnvironmentCompensationDefault = true;

// The texels of PT_BINDING_ENVIRONMENT for `radiance` (W x H, row 0 at the top) mapped by
// `mapping` (kEnvironment*): each pixel's radiance and its conditional CDF end, then the
// marginal CDF over the rows and the CDFs' guide tables, four to a texel (environment.h
// describes the layout). The weight
// of a pixel is the mean of its channels (pbrt-v4's GetSamplingDistribution), times sin theta
// of its row's centre for a lat-long map (the solid angle its texels cover); `compensated`
// subtracts the weights' mean and clamps at 0 (pbrt-v4's compensatedDistribution; all ones if
// nothing is left). Sums in double; a row (or the whole) of weight 0 is uniform, as pbrt-v4's
// PiecewiseConstant1D makes it.
std::vector<vec4> buildEnvironmentTexels(const Image& radiance, uint mapping, bool compensated);

// The number of texels buildEnvironmentTexels gives for a W x H image.
inline size_t environmentTexelCount(int width, int height) {
  return (size_t(environmentGuideStart(uint(width), uint(height), height)) + 3) / 4;
}

// The mean radiance over the sphere of directions (each texel weighed by its solid angle).
vec3 environmentMeanRadiance(const Image& radiance, uint mapping);

// The view of RenderParams' environment fields and the texels that environment.h reads.
inline EnvironmentMap environmentMapOf(const RenderParams& params,
                                       const std::vector<vec4>& texels) {
  return EnvironmentMap{params.environmentX,
                        params.environmentY,
                        params.environmentZ,
                        params.environmentWidth,
                        params.environmentHeight,
                        params.environmentMapping,
                        texels.data()};
}

}  // namespace pt
