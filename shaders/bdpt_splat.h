// Where a light-tracing splat lands on the film (pbrt-v4's RGBFilm::AddSplat and GetPixelRGB),
// written once for the CPU reference (host/cpu/bdpt.h's BdptSplatter) and the shader
// (shaders/bdpt.glsl): every pixel whose filter reaches the film point takes the splat, weighed
// by the filter's value at (point - the pixel's centre) over the filter's integral (filter.h's
// filterValue; the integral is host/scene/camera_filter.h's, handed in as its inverse). The box
// keeps the half-open square [c - r, c + r) about each centre c, so that a point on the border
// between pixels lands in one of them, with the weight 1 / (4 rx ry).
#ifndef PT_BDPT_SPLAT_H
#define PT_BDPT_SPLAT_H

#include "filter.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// The film pixels (the whole film's coordinates, inclusive) whose filter may reach filmPoint.
struct BdptSplatPixels {
  ivec2 low;
  ivec2 high;
};

PT_INLINE BdptSplatPixels bdptSplatPixels(PT_IN(Camera) cam, vec2 filmPoint) {
  vec2 r = vec2(cam.filterRadiusX, cam.filterRadiusY);
  BdptSplatPixels p;
  if (cam.filterType == kFilterBox) {
    p.low =
        ivec2(int(floor(filmPoint.x - r.x - 0.5f)) + 1, int(floor(filmPoint.y - r.y - 0.5f)) + 1);
  } else {
    p.low = ivec2(int(ceil(filmPoint.x - r.x - 0.5f)), int(ceil(filmPoint.y - r.y - 0.5f)));
  }
  p.high = ivec2(int(floor(filmPoint.x + r.x - 0.5f)), int(floor(filmPoint.y + r.y - 0.5f)));
  return p;
}

// The scale of a splat's weights: the box's 1 / (4 rx ry), else 1 / the filter's integral
// (inverseIntegral).
PT_INLINE float bdptSplatScale(PT_IN(Camera) cam, float inverseIntegral) {
  if (cam.filterType == kFilterBox) return 1.0f / (4.0f * cam.filterRadiusX * cam.filterRadiusY);
  return inverseIntegral;
}

// The weight with which film pixel (x, y) of bdptSplatPixels takes a splat at filmPoint; scale:
// bdptSplatScale's.
PT_INLINE float bdptSplatWeight(PT_IN(Camera) cam, float scale, vec2 filmPoint, int x, int y) {
  if (cam.filterType == kFilterBox) return scale;
  return filterValue(cam, filmPoint - vec2(float(x) + 0.5f, float(y) + 0.5f)) * scale;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_BDPT_SPLAT_H
