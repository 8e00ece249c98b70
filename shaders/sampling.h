// Random numbers and sampling routines shared by the CPU reference and the shader, so that
// both draw the same numbers and map them to the same points and directions.
// Only pure functions of their arguments live here; the integrators are written separately.
#ifndef PT_SAMPLING_H
#define PT_SAMPLING_H

#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

PT_CONST float kPi = 3.14159265358979323846f;
PT_CONST float kInvPi = 0.31830988618379067154f;

// ---- Counter-based random numbers ------------------------------------------------------

// pcg4d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020): a 4D -> 4D
// integer hash built from LCG steps and xorshifts. All arithmetic is 32-bit unsigned and
// wraps, so C++ and GLSL compute identical bits.
PT_INLINE uvec4 pcg4d(uvec4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  v ^= v >> 16u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  return v;
}

// Two uniform numbers in [0, 1) for (pixel, sample, dimension, seed). The top 24 bits of a
// hash word convert to float exactly, so both sides get the same bits. The seed is spread
// by an odd constant (the golden ratio in 32-bit fixed point) so that neighbouring seeds do
// not share dimensions.
PT_INLINE vec2 random2(uvec2 pixel, uint sampleIndex, uint dimension, uint seed) {
  uvec4 h = pcg4d(uvec4(pixel.x, pixel.y, sampleIndex, dimension + seed * 0x9E3779B9u));
  return vec2(float(h.x >> 8u), float(h.y >> 8u)) * (1.0f / 16777216.0f);
}

PT_INLINE float random1(uvec2 pixel, uint sampleIndex, uint dimension, uint seed) {
  return random2(pixel, sampleIndex, dimension, seed).x;
}

// ---- Directions and points -------------------------------------------------------------

// Maps a direction given in the frame (t, b, n) of unit vector n to world space, with the
// branch-free orthonormal basis of Duff et al., "Building an Orthonormal Basis, Revisited"
// (JCGT 2017).
PT_INLINE vec3 localToWorld(vec3 local, vec3 n) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float b = n.x * n.y * a;
  vec3 t = vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
  return local.x * t + local.y * bt + local.z * n;
}

// Cosine-weighted direction about +z (Malley's method); pdf = cos(theta) / pi.
PT_INLINE vec3 sampleCosineHemisphere(vec2 u) {
  float r = sqrt(u.x);
  float phi = 2.0f * kPi * u.y;
  return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0f, 1.0f - u.x)));
}

// Uniformly distributed point on triangle (v0, v1, v2), as barycentric weights of v1, v2.
PT_INLINE vec2 sampleTriangleBarycentrics(vec2 u) {
  float su = sqrt(u.x);
  return vec2(su * (1.0f - u.y), su * u.y);
}

// Power heuristic with beta = 2 (Veach 1997) for the sample of the strategy with pdf a.
PT_INLINE float powerHeuristic(float a, float b) {
  float a2 = a * a;
  float b2 = b * b;
  return a2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

// ---- Ray origins -----------------------------------------------------------------------

// Moves a ray origin p off the surface along n (the side the new ray leaves from) by an
// amount that scales with |p|: a fixed number of float ulps, or a small absolute step near
// the origin where ulps vanish. Wächter and Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems (2019), chapter 6.
PT_CONST float kOffsetOrigin = 1.0f / 32.0f;
PT_CONST float kOffsetFloatScale = 1.0f / 65536.0f;
PT_CONST float kOffsetIntScale = 256.0f;

PT_INLINE float offsetComponent(float p, float n) {
  int ulps = int(kOffsetIntScale * n);
  float moved = intBitsToFloat(floatBitsToInt(p) + (p < 0.0f ? -ulps : ulps));
  return abs(p) < kOffsetOrigin ? p + kOffsetFloatScale * n : moved;
}

PT_INLINE vec3 offsetRayOrigin(vec3 p, vec3 n) {
  return vec3(offsetComponent(p.x, n.x), offsetComponent(p.y, n.y), offsetComponent(p.z, n.z));
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_SAMPLING_H
