// The film's crop and the pixel filter's constants, from a scene's CameraDesc: the readers
// check the file's film and filter with them; render/camera.h builds the GPU camera from them.
#pragma once

#include <array>
#include <string>

#include "common/shared.h"
#include "scene/scene.h"

namespace pt {

// The pixels a crop window or pixel bounds select of a width x height film, as pbrt-v4's film
// computes them: [x0, x1) x [y0, y1], in {x0, x1, y0, y1}; the whole film without either.
std::array<int, 4> cropPixels(const CameraDesc& desc, int width, int height);

// pbrt-v4's filter of type `type` (kFilter*) with its defaults: radius 0.5 for box, 2 for
// triangle, 1.5 and sigma 0.5 for gaussian, 2 and B = C = 1/3 for mitchell.
PixelFilterDesc defaultFilter(uint type);

// The constants of a filter that makeCamera puts in the Camera (filter.h reads them):
// filterWeight, filterScale, filterB, filterC, filterRootsNear/Far, filterExpX/Y. Throws
// InputError (naming `where`) for parameters no sampler can follow. Exposed for tests.
void setFilterConstants(Camera& camera, const PixelFilterDesc& filter, const std::string& where);

// The integral over the plane of filter.h's filterValue for the camera's filter, in closed
// form from its constants: box 4 rx ry, triangle rx^2 ry^2, gaussian per axis
// 2 erf(k r) - 2 r filterExp, mitchell 9 rx ry (Mitchell1D integrates to 1 over [-2, 2]
// whatever B and C; times 6, over x = t r / 2). Splats are divided by it (pbrt-v4's
// filterIntegral).
double filterIntegral(const Camera& camera);

}  // namespace pt
