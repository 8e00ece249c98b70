// Perlin's improved noise as pbrt-v4 defines it (its util/noise.cpp: Noise and DNoise), written
// once for the CPU reference and the shader (C++ through GLM, GLSL through #include). Ken
// Perlin's permutation of 0-255 ("Improving Noise", SIGGRAPH 2002), repeated so that two
// lookups can be summed without wrapping; gradients from the low four bits of the hash.
//
// The permutation is read from the media's grid buffer (noise_permutation.h's 512 values, as
// integers' bits, from float `table`), through mediumGridWord, which the includer defines
// (medium.h in C++): as a constant array in the shader, lavapipe's compiler ran for over 50
// minutes and 9.5 GB on the volume variant (24 lookups per noise, 13 noises per density, all
// inlined) and was stopped.
#ifndef PT_NOISE_H
#define PT_NOISE_H

#include "noise_permutation.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

PT_INLINE int noisePermutation(PT_SCENE_PARAM uint table, int i) {
  return int(mediumGridWord(PT_SCENE_ARG table + uint(i)));
}

// The gradient term of lattice point (x, y, z) (each in [0, 256]) at offset (dx, dy, dz).
PT_INLINE float noiseGradient(PT_SCENE_PARAM uint table, int x, int y, int z, float dx, float dy,
                              float dz) {
  int h =
      noisePermutation(
          PT_SCENE_ARG table,
          noisePermutation(PT_SCENE_ARG table, noisePermutation(PT_SCENE_ARG table, x) + y) + z) &
      15;
  float u = h < 8 || h == 12 || h == 13 ? dx : dy;
  float v = h < 4 || h == 12 || h == 13 ? dy : dz;
  return ((h & 1) != 0 ? -u : u) + ((h & 2) != 0 ? -v : v);
}

// 6 t^5 - 15 t^4 + 10 t^3.
PT_INLINE float noiseWeight(float t) {
  float t3 = t * t * t;
  return 6.0f * t3 * t * t - 15.0f * t3 * t + 10.0f * t3;
}

// x with its whole multiples of 2^30 taken off towards zero (C's fmod by 2^30: GLSL's mod
// rounds down, which would move negative coordinates).
PT_INLINE float noiseWrap(float x) {
  const float period = 1073741824.0f;
  return x - trunc(x / period) * period;
}

// pbrt-v4's Noise(p): zero at the lattice points, within [-1, 1].
PT_INLINE float perlinNoise(PT_SCENE_PARAM uint table, vec3 p) {
  float x = noiseWrap(p.x);
  float y = noiseWrap(p.y);
  float z = noiseWrap(p.z);
  float fx = floor(x);
  float fy = floor(y);
  float fz = floor(z);
  float dx = x - fx;
  float dy = y - fy;
  float dz = z - fz;
  int ix = int(fx) & 255;
  int iy = int(fy) & 255;
  int iz = int(fz) & 255;
  float w000 = noiseGradient(PT_SCENE_ARG table, ix, iy, iz, dx, dy, dz);
  float w100 = noiseGradient(PT_SCENE_ARG table, ix + 1, iy, iz, dx - 1.0f, dy, dz);
  float w010 = noiseGradient(PT_SCENE_ARG table, ix, iy + 1, iz, dx, dy - 1.0f, dz);
  float w110 = noiseGradient(PT_SCENE_ARG table, ix + 1, iy + 1, iz, dx - 1.0f, dy - 1.0f, dz);
  float w001 = noiseGradient(PT_SCENE_ARG table, ix, iy, iz + 1, dx, dy, dz - 1.0f);
  float w101 = noiseGradient(PT_SCENE_ARG table, ix + 1, iy, iz + 1, dx - 1.0f, dy, dz - 1.0f);
  float w011 = noiseGradient(PT_SCENE_ARG table, ix, iy + 1, iz + 1, dx, dy - 1.0f, dz - 1.0f);
  float w111 =
      noiseGradient(PT_SCENE_ARG table, ix + 1, iy + 1, iz + 1, dx - 1.0f, dy - 1.0f, dz - 1.0f);
  float wx = noiseWeight(dx);
  float wy = noiseWeight(dy);
  float wz = noiseWeight(dz);
  float x00 = w000 + wx * (w100 - w000);
  float x10 = w010 + wx * (w110 - w010);
  float x01 = w001 + wx * (w101 - w001);
  float x11 = w011 + wx * (w111 - w011);
  float y0 = x00 + wy * (x10 - x00);
  float y1 = x01 + wy * (x11 - x01);
  return y0 + wz * (y1 - y0);
}

// pbrt-v4's DNoise(p): the noise's gradient by forward differences of 0.01.
PT_INLINE vec3 perlinNoiseGradient(PT_SCENE_PARAM uint table, vec3 p) {
  const float delta = 0.01f;
  float n = perlinNoise(PT_SCENE_ARG table, p);
  return vec3(perlinNoise(PT_SCENE_ARG table, p + vec3(delta, 0.0f, 0.0f)) - n,
              perlinNoise(PT_SCENE_ARG table, p + vec3(0.0f, delta, 0.0f)) - n,
              perlinNoise(PT_SCENE_ARG table, p + vec3(0.0f, 0.0f, delta)) - n) /
         delta;
}

// pbrt-v4's CloudMedium::Density at point p of the medium's space, in [0, 1]: five octaves of
// noise at `frequency`, the lookup point perturbed by two octaves of the noise's gradient
// scaled by `wispiness`, thinning with height y and filled below y = 0.5.
PT_INLINE float cloudDensity(PT_SCENE_PARAM uint table, vec3 p, float density, float wispiness,
                             float frequency) {
  vec3 pp = frequency * p;
  if (wispiness > 0.0f) {
    float vomega = 0.05f * wispiness;
    float vlambda = 10.0f;
    for (int i = 0; i < 2; ++i) {
      pp += vomega * perlinNoiseGradient(PT_SCENE_ARG table, vlambda * pp);
      vomega *= 0.5f;
      vlambda *= 1.99f;
    }
  }
  float d = 0.0f;
  float omega = 0.5f;
  float lambda = 1.0f;
  for (int i = 0; i < 5; ++i) {
    d += omega * perlinNoise(PT_SCENE_ARG table, lambda * pp);
    omega *= 0.5f;
    lambda *= 1.99f;
  }
  d = clamp((1.0f - p.y) * 4.5f * density * d, 0.0f, 1.0f);
  d += 2.0f * max(0.0f, 0.5f - p.y);
  return clamp(d, 0.0f, 1.0f);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_NOISE_H
