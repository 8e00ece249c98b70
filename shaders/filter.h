// The camera's samples: pixel filters by filter importance sampling, a thin lens, and the ray
// they give. Shared by the CPU reference and the shader (like sampling.h), so that both put a
// sample at the same film point and lens point and weigh it alike. The host's side (the
// filters' constants, the crop, the screen window) is makeCamera in host/scene/scene.cpp.
//
// Filter importance sampling (pbrt-v4, book section 8.8): a pixel's value is the filter-
// weighted mean of the radiance about its centre, I = integral(f L) / integral(f). pbrt-v4
// draws each sample's film offset p from a tabulated density close to |f| and weighs it by
// w = f(p) / pdf(p); its film divides the sum of w L by the sum of w. Here the density is
// exactly |f| / integral(|f|), so that every weight is the constant
//   w = sign(f(p)) integral(|f|) / integral(f)
// (divided by integral(f), so that it estimates I by itself): 1 for box, triangle and gaussian
// (never negative), and +-(integral |f| / integral f) for mitchell, which is negative in
// places (for pbrt-v4's B = C = 1/3, where 8/7 < |t| < 2, t = 2x / radius). The film divides the
// sum of w L by the number of samples: the mean of w is 1, so both films tend to the same I
// (pbrt-v4's ratio is biased at finite counts for mitchell, this one is not).
//
// All of pbrt-v4's filters are separable, f(x, y) = f1(x) f1(y), and so is |f|: each axis is
// sampled on its own by inverting the CDF of |f1|, in closed form for box and triangle, by
// bisection on a closed-form CDF for gaussian and mitchell. Bisection takes the same fixed
// number of steps everywhere (no loop whose count depends on the data: lavapipe caps loop
// iterations), and only +, -, *, / and comparisons: no transcendental built-in, whose
// precision Vulkan leaves loose, so both backends find the same point up to rounding.
#ifndef PT_FILTER_H
#define PT_FILTER_H

#include "sampling.h"
#include "shared_types.h"

// The shader counts its loop iterations (lavapipe's cap); C++ has nothing to count.
#ifndef PT_FILTER_LOOP_TICK
#define PT_FILTER_LOOP_TICK()
#endif
// Defined by a shader variant for box filters and pinholes only (pathtrace.comp's base
// variant, which the host picks for such cameras): the other filters and the lens are left
// out, which lavapipe would otherwise compile for every scene.

#ifdef __cplusplus
namespace pt {
#endif

// Bisection steps of the gaussian's and mitchell's inversion: the bracket, 2 radii (or 4 in
// mitchell's t), shrinks to 2^-24 of it, about the float spacing at the radius.
PT_CONST uint kFilterBisectionSteps = 24u;

// ---- Box and triangle ------------------------------------------------------------------

// The box's sample: uniform over [-r, r] about the pixel centre, as a point relative to the
// pixel's corner: 0.5 + (2u - 1) r, computed as (0.5 - r) + 2r u. For pbrt-v4's default
// radius 0.5 that is 0 + 1 u = u exactly: the uniform jitter in the pixel of the renderer
// before filters, bit for bit.
PT_INLINE vec2 sampleBoxFilter(vec2 u, vec2 radius) {
  return (0.5f - radius) + (2.0f * radius) * u;
}

// The tent r - |x| on [-r, r]: its CDF is (x + r)^2 / (2 r^2) left of 0 and
// 1 - (r - x)^2 / (2 r^2) right of it, inverted.
PT_INLINE float sampleTent(float u, float r) {
  return u < 0.5f ? r * sqrt(2.0f * u) - r : r - r * sqrt(2.0f - 2.0f * u);
}

// ---- Gaussian --------------------------------------------------------------------------

// erf(x) by Abramowitz and Stegun's 7.1.28, 1 - 1 / (1 + a1 x + ... + a6 x^6)^16 for x >= 0:
// absolute error below 3e-7, from arithmetic alone. (Beyond 6 erf is 1 in float; the clamp
// keeps the sixteenth power finite.)
PT_INLINE float filterErf(float x) {
  float a = min(abs(x), 6.0f);
  float p = 1.0f + a * (0.0705230784f +
                        a * (0.0422820123f +
                             a * (0.0092705272f +
                                  a * (0.0001520143f + a * (0.0002765672f + a * 0.0000430638f)))));
  p = p * p;
  p = p * p;
  p = p * p;
  p = p * p;
  float e = 1.0f - 1.0f / p;
  return x < 0.0f ? -e : e;
}

// The integral of pbrt-v4's gaussian exp(-(kx)^2) - exp(-(kr)^2), k = 1 / (sigma sqrt 2), from
// -r to x, times 2k / sqrt(pi): erf(kx) + erf(kr) - e (x + r), where e = exp(-(kr)^2) 2k /
// sqrt(pi) (Camera::filterExpX/Y, from the host) and erfRadius = erf(kr).
PT_INLINE float gaussianFilterCdf(float x, float radius, float k, float e, float erfRadius) {
  return filterErf(k * x) + erfRadius - e * (x + radius);
}

// ---- Mitchell --------------------------------------------------------------------------
// pbrt-v4's Mitchell1D(t), t = 2x / radius in [-2, 2], times 6: on |t| <= 1 the cubic
// (12 - 9B - 6C) t^3 + (-18 + 12B + 6C) t^2 + (6 - 2B), on 1 < |t| <= 2 the cubic
// (-B - 6C) t^3 + (6B + 30C) t^2 + (-12B - 48C) t + (8B + 24C). Each cubic keeps its sign
// between the roots the host found (Camera::filterRootsNear, filterRootsFar), so on each of
// the eight segments they bound, the integral of |f| is |Q(b) - Q(a)| with Q the cubic's
// antiderivative: the CDF of |f| in closed form.

// The antiderivatives' coefficients, highest power first: near t^4, t^3, (t^2: 0), t; far
// t^4, t^3, t^2, t.
PT_INLINE vec4 mitchellNearQ(float b, float c) {
  return vec4((12.0f - 9.0f * b - 6.0f * c) * 0.25f, (-18.0f + 12.0f * b + 6.0f * c) / 3.0f, 0.0f,
              6.0f - 2.0f * b);
}
PT_INLINE vec4 mitchellFarQ(float b, float c) {
  return vec4((-b - 6.0f * c) * 0.25f, (6.0f * b + 30.0f * c) / 3.0f,
              (-12.0f * b - 48.0f * c) * 0.5f, 8.0f * b + 24.0f * c);
}

// The eight segments of |t| in [0, 2] (four in each piece), the antiderivative at their
// starts, and the integral of |f| over each and before each: the CDF of |f| in closed form.
struct MitchellCdf {
  vec4 nearQ, farQ;          // mitchellNearQ, mitchellFarQ
  vec4 nearLo, nearHi;       // the near segments [nearLo[i], nearHi[i]]
  vec4 farLo, farHi;         // the far ones
  vec4 nearAt, farAt;        // Q at each segment's start
  vec4 nearStart, farStart;  // the integral of |f| over t in [0, the segment's start]
  float halfIntegral;        // the integral of |f| over t in [0, 2]
};

PT_INLINE vec4 mitchellEvalNearQ(vec4 q, vec4 t) {
  return t * (q.w + t * t * (q.y + t * q.x));
}
PT_INLINE vec4 mitchellEvalFarQ(vec4 q, vec4 t) {
  return t * (q.w + t * (q.z + t * (q.y + t * q.x)));
}
PT_INLINE float mitchellEvalQ(vec4 q, float t) {
  return t * (q.w + t * (q.z + t * (q.y + t * q.x)));
}

PT_INLINE MitchellCdf makeMitchellCdf(PT_IN(Camera) cam) {
  MitchellCdf m;
  m.nearQ = mitchellNearQ(cam.filterB, cam.filterC);
  m.farQ = mitchellFarQ(cam.filterB, cam.filterC);
  vec3 a = cam.filterRootsNear;
  vec3 c = cam.filterRootsFar;
  m.nearLo = vec4(0.0f, a.x, a.y, a.z);
  m.nearHi = vec4(a.x, a.y, a.z, 1.0f);
  m.farLo = vec4(1.0f, c.x, c.y, c.z);
  m.farHi = vec4(c.x, c.y, c.z, 2.0f);
  m.nearAt = mitchellEvalNearQ(m.nearQ, m.nearLo);
  m.farAt = mitchellEvalFarQ(m.farQ, m.farLo);
  vec4 nearParts = abs(mitchellEvalNearQ(m.nearQ, m.nearHi) - m.nearAt);
  vec4 farParts = abs(mitchellEvalFarQ(m.farQ, m.farHi) - m.farAt);
  m.nearStart.x = 0.0f;
  m.nearStart.y = nearParts.x;
  m.nearStart.z = m.nearStart.y + nearParts.y;
  m.nearStart.w = m.nearStart.z + nearParts.z;
  m.farStart.x = m.nearStart.w + nearParts.w;
  m.farStart.y = m.farStart.x + farParts.x;
  m.farStart.z = m.farStart.y + farParts.y;
  m.farStart.w = m.farStart.z + farParts.z;
  m.halfIntegral = m.farStart.w + farParts.w;
  return m;
}

// One axis's t in [-2, 2] for u by the CDF of |f| over t, inverted in three steps: the side
// from u (|f| is even: u < 1/2 the negative side, mirrored, so that the map stays monotone),
// the segment whose share of the integral holds the rest, then the point within it by
// bisection, where f keeps its sign and the integral is +-(Q(t) - Q(start)).
struct MitchellAxis {
  float target;  // the integral of |f| still to cover from the segment's start
  float lo, hi;  // the bracket, in the segment
  vec4 q;        // the segment's antiderivative
  float at;      // Q at its start
  float sign;    // +1 where the cubic is positive there, else -1
  bool negative;
};

PT_INLINE MitchellAxis startMitchellAxis(MitchellCdf m, float u) {
  MitchellAxis a;
  a.negative = u < 0.5f;
  float v = a.negative ? 1.0f - 2.0f * u : 2.0f * u - 1.0f;
  float target = v * m.halfIntegral;
  // The last segment whose start is at or before the target (empty ones included: they
  // change nothing).
  uint k = 0u;
  k += m.nearStart.y <= target ? 1u : 0u;
  k += m.nearStart.z <= target ? 1u : 0u;
  k += m.nearStart.w <= target ? 1u : 0u;
  k += m.farStart.x <= target ? 1u : 0u;
  k += m.farStart.y <= target ? 1u : 0u;
  k += m.farStart.z <= target ? 1u : 0u;
  k += m.farStart.w <= target ? 1u : 0u;
  bool inNear = k < 4u;
  uint i = k & 3u;
  a.lo = inNear ? m.nearLo[i] : m.farLo[i];
  a.hi = inNear ? m.nearHi[i] : m.farHi[i];
  a.q = inNear ? m.nearQ : m.farQ;
  a.at = inNear ? m.nearAt[i] : m.farAt[i];
  a.target = target - (inNear ? m.nearStart[i] : m.farStart[i]);
  a.sign = mitchellEvalQ(a.q, a.hi) - a.at < 0.0f ? -1.0f : 1.0f;
  return a;
}

PT_INLINE MitchellAxis stepMitchellAxis(MitchellAxis a) {
  float mid = 0.5f * (a.lo + a.hi);
  if (a.sign * (mitchellEvalQ(a.q, mid) - a.at) < a.target) {
    a.lo = mid;
  } else {
    a.hi = mid;
  }
  return a;
}

PT_INLINE float finishMitchellAxis(MitchellAxis a) {
  float t = 0.5f * (a.lo + a.hi);
  return a.negative ? -t : t;
}

// Mitchell1D(t) times 6, for |t| <= 2.
PT_INLINE float mitchellValue6(PT_IN(Camera) cam, float t) {
  float a = abs(t);
  float b = cam.filterB;
  float c = cam.filterC;
  float nearValue = ((12.0f - 9.0f * b - 6.0f * c) * a + (-18.0f + 12.0f * b + 6.0f * c)) * a * a +
                    (6.0f - 2.0f * b);
  float farValue =
      (((-b - 6.0f * c) * a + (6.0f * b + 30.0f * c)) * a + (-12.0f * b - 48.0f * c)) * a +
      (8.0f * b + 24.0f * c);
  return a <= 1.0f ? nearValue : farValue;
}

// The sign of Mitchell1D at t (its value times 6, whose sign it is).
PT_INLINE float mitchellSign(PT_IN(Camera) cam, float t) {
  return mitchellValue6(cam, t) < 0.0f ? -1.0f : 1.0f;
}

// ---- The filter's value ----------------------------------------------------------------

// The value of pixel filter `cam.filterType` at `offset` from a pixel's centre (pbrt-v4's
// Filter::Evaluate), each filter times a constant of its own: box 1 on [-r, r]^2; triangle
// (rx - |x|)(ry - |y|); gaussian per axis (2k / sqrt(pi)) exp(-(kx)^2) less its value at the
// radius (the derivative of gaussianFilterCdf); mitchell 6 Mitchell1D(2x / r) per axis. 0
// beyond the radius. Where a bidirectional method splats light at a film point, each pixel
// takes it weighed by this at (point - the pixel's centre) over the filter's integral in the
// same scale (filterIntegral, host/scene/camera_filter.h), as pbrt-v4's RGBFilm::AddSplat and
// GetPixelRGB do; the camera's own samples need only sampleFilm.
PT_INLINE float filterValue(PT_IN(Camera) cam, vec2 offset) {
  vec2 radius = vec2(cam.filterRadiusX, cam.filterRadiusY);
  vec2 a = abs(offset);
  if (a.x > radius.x || a.y > radius.y) return 0.0f;
  if (cam.filterType == kFilterTriangle) return (radius.x - a.x) * (radius.y - a.y);
  if (cam.filterType == kFilterGaussian) {
    float k = cam.filterScale;
    float peak = 2.0f * k / sqrt(kPi);
    vec2 g = vec2(peak * exp(-(k * a.x) * (k * a.x)) - cam.filterExpX,
                  peak * exp(-(k * a.y) * (k * a.y)) - cam.filterExpY);
    return max(g.x, 0.0f) * max(g.y, 0.0f);
  }
  if (cam.filterType == kFilterMitchell) {
    return mitchellValue6(cam, 2.0f * a.x / radius.x) * mitchellValue6(cam, 2.0f * a.y / radius.y);
  }
  return 1.0f;
}

// ---- The filter's sample ---------------------------------------------------------------

struct FilmSample {
  vec2 point;    // relative to the pixel's corner: its centre is (0.5, 0.5)
  float weight;  // the sample's weight (above): multiplies its radiance
};

// A film point for pixel filter `cam.filterType` from two uniform numbers: distributed in
// proportion to |f| about the pixel's centre, with its weight.
PT_INLINE FilmSample sampleFilm(PT_IN(Camera) cam, vec2 u) {
  vec2 radius = vec2(cam.filterRadiusX, cam.filterRadiusY);
  FilmSample s;
  s.point = sampleBoxFilter(u, radius);
  s.weight = 1.0f;
#ifndef PT_FILTER_BOX_PINHOLE
  if (cam.filterType == kFilterTriangle) {
    s.point = vec2(0.5f + sampleTent(u.x, radius.x), 0.5f + sampleTent(u.y, radius.y));
  }
  if (cam.filterType == kFilterGaussian) {
    // Bisection for x in [-r, r] with CDF(x) = u CDF(r), both axes at once.
    float k = cam.filterScale;
    vec2 erfRadius = vec2(filterErf(k * radius.x), filterErf(k * radius.y));
    vec2 target = u * vec2(gaussianFilterCdf(radius.x, radius.x, k, cam.filterExpX, erfRadius.x),
                           gaussianFilterCdf(radius.y, radius.y, k, cam.filterExpY, erfRadius.y));
    vec2 lo = -radius;
    vec2 hi = radius;
    for (uint i = 0u; i < kFilterBisectionSteps; ++i) {
      PT_FILTER_LOOP_TICK();
      vec2 mid = 0.5f * (lo + hi);
      if (gaussianFilterCdf(mid.x, radius.x, k, cam.filterExpX, erfRadius.x) < target.x) {
        lo.x = mid.x;
      } else {
        hi.x = mid.x;
      }
      if (gaussianFilterCdf(mid.y, radius.y, k, cam.filterExpY, erfRadius.y) < target.y) {
        lo.y = mid.y;
      } else {
        hi.y = mid.y;
      }
    }
    s.point = 0.5f + 0.5f * (lo + hi);
  }
  if (cam.filterType == kFilterMitchell) {
    MitchellCdf m = makeMitchellCdf(cam);
    MitchellAxis ax = startMitchellAxis(m, u.x);
    MitchellAxis ay = startMitchellAxis(m, u.y);
    for (uint i = 0u; i < kFilterBisectionSteps; ++i) {
      PT_FILTER_LOOP_TICK();
      ax = stepMitchellAxis(ax);
      ay = stepMitchellAxis(ay);
    }
    vec2 t = vec2(finishMitchellAxis(ax), finishMitchellAxis(ay));
    s.point = 0.5f + t * (0.5f * radius);  // x = t r / 2
    s.weight = cam.filterWeight * mitchellSign(cam, t.x) * mitchellSign(cam, t.y);
  }
#endif
  return s;
}

// ---- The lens and the ray --------------------------------------------------------------

// A uniform point on the unit disk by Shirley and Chiu's concentric mapping (pbrt-v4's
// SampleUniformDiskConcentric): squares about the centre of [-1, 1]^2 go to circles, so that
// neighbouring numbers stay neighbouring points. The angle pi/4 (y/x), or pi/2 - pi/4 (x/y), is
// cosSinTwoPi's fraction of a turn (y/x) / 8, or 1/4 - (x/y) / 8.
PT_INLINE vec2 sampleConcentricDisk(vec2 u) {
  vec2 o = 2.0f * u - 1.0f;
  if (o.x == 0.0f && o.y == 0.0f) return vec2(0.0f);
  bool xMajor = abs(o.x) > abs(o.y);
  float r = xMajor ? o.x : o.y;
  float turns = xMajor ? 0.125f * (o.y / o.x) : 0.25f - 0.125f * (o.x / o.y);
  return r * cosSinTwoPi(turns);
}

// A camera ray: where it starts, its unit direction, and the weight of its radiance; the film
// point and the lens point (offset from the camera's position) it was made of.
struct CameraSample {
  vec3 origin;
  vec3 direction;
  float weight;
  vec2 filmPoint;
  vec3 lensOffset;
};

// The ray of one sample of film pixel `filmPixel` (the film's, not the crop's: see Camera):
// uFilter places it in the filter about the pixel (sampleFilm), uLens on the lens. A pinhole
// (lensRadius 0) ignores uLens. A thin lens as pbrt-v4's PerspectiveCamera, in camera space:
// the pinhole's ray through the film point meets the plane in focus, at focalDistance along
// forward, at focalDistance times its screen-window point (whose forward component is 1); the
// ray leaves from a uniform point of the lens's disk (radius lensRadius, in the plane of right
// and up) towards that point. So everything on the plane in focus is sharp.
PT_INLINE CameraSample generateCameraRay(PT_IN(Camera) cam, uvec2 filmPixel, vec2 uFilter,
                                         vec2 uLens) {
  FilmSample film = sampleFilm(cam, uFilter);
  vec3 w = cameraFilmVector(cam, vec2(filmPixel) + film.point);
  CameraSample s;
  s.origin = cam.position;
  s.direction = normalize(w);
  s.weight = film.weight;
  s.filmPoint = vec2(filmPixel) + film.point;
  s.lensOffset = vec3(0.0f);
#ifndef PT_FILTER_BOX_PINHOLE
  if (cam.lensRadius > 0.0f) {
    vec2 lens = cam.lensRadius * sampleConcentricDisk(uLens);
    vec3 offset = lens.x * cam.right + lens.y * cam.up;
    s.lensOffset = offset;
    s.origin = cam.position + offset;
    s.direction = normalize(cam.focalDistance * w - offset);
  }
#endif
  return s;
}

// The camera ray of a path sample: sample sampleIndex of film pixel filmPixel, its numbers
// from dimension kDimPixel (the filter) and, for a thin lens only, kDimLens (a pinhole draws
// nothing for it, so that its paths are those of the renderer before lenses).
PT_INLINE CameraSample cameraSampleOf(PT_IN(Camera) cam, bool sobol, uvec2 filmPixel,
                                      uint sampleIndex, uint seed) {
  vec2 uLens =
      cam.lensRadius > 0.0f ? random2(sobol, filmPixel, sampleIndex, kDimLens, seed) : vec2(0.0f);
  return generateCameraRay(cam, filmPixel, random2(sobol, filmPixel, sampleIndex, kDimPixel, seed),
                           uLens);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_FILTER_H
