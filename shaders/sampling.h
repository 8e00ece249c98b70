// Random numbers and sampling routines shared by the CPU reference and the shader, so that
// both draw the same numbers and map them to the same points and directions.
// Only pure functions of their arguments live here; what a path does with them is
// path_vertex.h's.
#ifndef PT_SAMPLING_H
#define PT_SAMPLING_H

#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

PT_CONST float kPi = 3.14159265358979323846f;
PT_CONST float kInvPi = 0.31830988618379067154f;
PT_CONST float kInv4Pi = 0.07957747154594766788f;

// ---- Counter-based random numbers ------------------------------------------------------

// pcg4d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020): a 4D -> 4D
// integer hash built from LCG steps and xorshifts. All arithmetic is 32-bit unsigned and
// wraps, so C++ and GLSL compute identical bits.
PT_HOT_INLINE uvec4 pcg4d(uvec4 v) {
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

// Two uniform numbers in [0, 1) for (pixel, sample, dimension, seed), independent of every
// other pair. The top 24 bits of a hash word convert to float exactly, so both sides get the
// same bits. The seed is spread by an odd constant (the golden ratio in 32-bit fixed point)
// so that neighbouring seeds do not share dimensions.
PT_HOT_INLINE vec2 independentRandom2(uvec2 pixel, uint sampleIndex, uint dimension, uint seed) {
  uvec4 h = pcg4d(uvec4(pixel.x, pixel.y, sampleIndex, dimension + seed * 0x9E3779B9u));
  return vec2(float(h.x >> 8u), float(h.y >> 8u)) * (1.0f / 16777216.0f);
}

// ---- Low-discrepancy numbers: Owen-scrambled Sobol points ------------------------------
// Each dimension (a pair of numbers) of a pixel takes the first two dimensions of the Sobol
// sequence, a (0,2)-sequence: any 2^k consecutive points from an aligned start fill every
// elementary interval of area 2^-k once. Following Burley ("Practical Hash-based Owen
// Scrambling", JCGT 2020), the points are Owen-scrambled by a hash, so that the pixel's
// error is unbiased and decorrelated from its neighbours', and their order is shuffled per
// pixel and dimension (a nested scramble of the index keeps aligned power-of-two blocks
// together, so the first 2^k samples are still such a net), which decorrelates the
// dimensions of one path from each other. All of it is loop-free 32-bit integer arithmetic.

// Sobol's second dimension, bit-reversed: bit m of the result is the XOR of the index bits k
// whose binomial coefficient C(k, m) is odd, that is (Lucas) the bits k that contain m as a
// submask. Five shift-XOR steps sum every superset.
PT_HOT_INLINE uint sobolSecondDimensionReversed(uint index) {
  uint y = index;
  y ^= (y >> 1u) & 0x55555555u;
  y ^= (y >> 2u) & 0x33333333u;
  y ^= (y >> 4u) & 0x0F0F0F0Fu;
  y ^= (y >> 8u) & 0x00FF00FFu;
  y ^= (y >> 16u) & 0x0000FFFFu;
  return y;
}

// Sobol's second dimension: the reversal puts bit m at 31 - m.
PT_INLINE uint sobolSecondDimension(uint index) {
  return bitfieldReverse(sobolSecondDimensionReversed(index));
}

// The multiply-XOR steps of Laine and Karras (2011, with their constants), which flip each
// bit by a hash of the seed and of the bits below it.
PT_HOT_INLINE uint laineKarrasPermutation(uint x, uint seed) {
  x += seed;
  x ^= x * 0x6C50B47Cu;
  x ^= x * 0xB82F1E52u;
  x ^= x * 0xC7AFE638u;
  x ^= x * 0x8D22F6E6u;
  return x;
}

// Nested uniform scramble of the bits of x, most significant first: each bit is flipped by
// a hash of the seed and of the bits above it; hence the reversals around the permutation.
PT_HOT_INLINE uint nestedUniformScramble(uint x, uint seed) {
  return bitfieldReverse(laineKarrasPermutation(bitfieldReverse(x), seed));
}

PT_HOT_INLINE vec2 sobolRandom2(uvec2 pixel, uint sampleIndex, uint dimension, uint seed) {
  // Per pixel and dimension: a shuffle of the sample order and a scramble per coordinate.
  uvec4 h = pcg4d(uvec4(pixel.x, pixel.y, dimension, seed * 0x9E3779B9u + 0x7F4A7C15u));
  uint i = nestedUniformScramble(sampleIndex, h.x);
  // Sobol's first dimension is i reversed, and so its nested scramble,
  // nestedUniformScramble(bitfieldReverse(i), h.y), reverses it back first: the two
  // reversals are left out, here and in the second dimension.
  uint x = bitfieldReverse(laineKarrasPermutation(i, h.y));
  uint y = bitfieldReverse(laineKarrasPermutation(sobolSecondDimensionReversed(i), h.z));
  return vec2(float(x >> 8u), float(y >> 8u)) * (1.0f / 16777216.0f);
}

// The integrators' source of random numbers: two numbers in [0, 1) for one dimension of one
// path sample, from the chosen sampler (kSamplerIndependent or kSamplerSobol).
PT_HOT_INLINE vec2 random2(bool sobol, uvec2 pixel, uint sampleIndex, uint dimension, uint seed) {
  return sobol ? sobolRandom2(pixel, sampleIndex, dimension, seed)
               : independentRandom2(pixel, sampleIndex, dimension, seed);
}

PT_HOT_INLINE float random1(bool sobol, uvec2 pixel, uint sampleIndex, uint dimension, uint seed) {
  return random2(sobol, pixel, sampleIndex, dimension, seed).x;
}

// The random numbers of one scattering event: the kDimsPerBounce dimensions from `dim`
// (kDimFirstBounce + kDimsPerBounce * bounce), in the order of their offsets. The CPU
// reference draws them together, four hashes in one vector (host/cpu/bounce_random.h: the
// same bits); the shader draws each where it is used.
struct BounceRandom {
  vec2 lightChoose;  // dim + kDimLightChoose
  vec2 lightPoint;   // dim + kDimLightPoint
  vec2 bsdf;         // dim + kDimBsdf
  vec2 roulette;     // dim + kDimRoulette (.x only)
};

PT_INLINE BounceRandom bounceRandom(bool sobol, uvec2 pixel, uint sampleIndex, uint dim,
                                    uint seed) {
  BounceRandom u;
  u.lightChoose = random2(sobol, pixel, sampleIndex, dim + kDimLightChoose, seed);
  u.lightPoint = random2(sobol, pixel, sampleIndex, dim + kDimLightPoint, seed);
  u.bsdf = random2(sobol, pixel, sampleIndex, dim + kDimBsdf, seed);
  u.roulette = random2(sobol, pixel, sampleIndex, dim + kDimRoulette, seed);
  return u;
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

// (cos(2 pi u), sin(2 pi u)) for u in [0, 1], from plain arithmetic instead of the GPU's
// cos and sin, whose precision Vulkan leaves loose (about 1e-3 absolute is allowed): with
// them, CPU and GPU paths would drift apart. Reduces to the quadrant nearest u, where the
// angle x lies in [-pi/4, pi/4], and sums Taylor series to x^9 / x^10 (error < 3e-9).
PT_INLINE vec2 cosSinTwoPi(float u) {
  float quadrant = floor(4.0f * u + 0.5f);
  float x = (2.0f * kPi) * (u - 0.25f * quadrant);
  float x2 = x * x;
  float s =
      x * (1.0f + x2 * (-1.0f / 6.0f +
                        x2 * (1.0f / 120.0f + x2 * (-1.0f / 5040.0f + x2 * (1.0f / 362880.0f)))));
  float c = 1.0f + x2 * (-0.5f + x2 * (1.0f / 24.0f +
                                       x2 * (-1.0f / 720.0f +
                                             x2 * (1.0f / 40320.0f + x2 * (-1.0f / 3628800.0f)))));
  // Rotate by quadrant * 90 degrees.
  int q = int(quadrant) & 3;
  if (q == 1) return vec2(-s, c);
  if (q == 2) return vec2(-c, -s);
  if (q == 3) return vec2(s, -c);
  return vec2(c, s);
}

// Cosine-weighted direction about +z (Malley's method); pdf = cos(theta) / pi.
PT_INLINE vec3 sampleCosineHemisphere(vec2 u) {
  float r = sqrt(u.x);
  vec2 cs = cosSinTwoPi(u.y);
  return vec3(r * cs.x, r * cs.y, sqrt(max(0.0f, 1.0f - u.x)));
}

// Uniformly distributed point on triangle (v0, v1, v2), as barycentric weights of v1, v2.
PT_INLINE vec2 sampleTriangleBarycentrics(vec2 u) {
  float su = sqrt(u.x);
  return vec2(su * (1.0f - u.y), su * u.y);
}

// Choosing an emitter from the alias table (struct Emitter, shared_types.h) with two uniform
// numbers: u.x picks one of `count` slots uniformly, u.y keeps the slot with probability
// aliasThreshold and otherwise takes its alias. Returns the chosen emitter's index.
PT_INLINE uint aliasTableSlot(float u, uint count) {
  return min(uint(u * float(count)), count - 1u);
}
PT_INLINE uint aliasTablePick(uint slot, Emitter entry, float u) {
  return u < entry.aliasThreshold ? slot : entry.alias;
}

// Power heuristic with beta = 2 (Veach 1997) for the sample of the strategy with pdf a.
PT_INLINE float powerHeuristic(float a, float b) {
  float a2 = a * a;
  float b2 = b * b;
  return a2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

// ---- Rays ------------------------------------------------------------------------------

// Largest component (path throughput tests, Russian roulette).
PT_INLINE float maxComponent(vec3 v) {
  return max(v.x, max(v.y, v.z));
}

// The point of the screen window (on the plane at unit distance along forward, relative to
// the camera's position) that film point (x, y) in [0, filmWidth) x [0, filmHeight), row 0 at
// the top, maps to (see struct Camera).
PT_INLINE vec3 cameraFilmVector(PT_IN(Camera) cam, vec2 filmPoint) {
  float u = 2.0f * filmPoint.x / float(cam.filmWidth) - 1.0f;
  float v = 1.0f - 2.0f * filmPoint.y / float(cam.filmHeight);
  return cam.windowCenter + (u * cam.tanHalfFovY * cam.aspect) * cam.right +
         (v * cam.tanHalfFovY) * cam.up;
}

// Unit direction of the pinhole's ray through film point (x, y) (cameraFilmVector).
PT_INLINE vec3 cameraDirection(PT_IN(Camera) cam, vec2 filmPoint) {
  return normalize(cameraFilmVector(cam, filmPoint));
}

// Traversal constants of both BVH traversals (host/bvh/traverse.cpp, shaders/bvh.glsl).
// Smallest |direction| component used for 1/direction: keeps 1/d finite, so the slab
// products (lo - o) * (1/d) are never 0 * inf = NaN, and a ray lying in a box's face plane
// counts as inside that slab. Components this small only arise as exact zeros in practice.
PT_CONST float kMinDirection = 1e-30f;
// gamma(3) of Pharr et al. (a 3-ulp relative error bound, 2^-24 the unit roundoff); Ize 2013
// widens the slab test's far distance by 1 + 2 gamma(3) so that rounding never loses a hit.
PT_CONST float kGamma3 = 3.0f * 5.9604644775390625e-8f / (1.0f - 3.0f * 5.9604644775390625e-8f);
PT_CONST float kFarScale = 1.0f + 2.0f * kGamma3;

// Which hit a closest-hit query reports, in every traversal (host/bvh/traverse.cpp, the wide
// tree's host/bvh/wide_traverse-inl.h, shaders/bvh.glsl): of the triangles hit with
// 0 < t < tMax, the one with the smallest t as the triangle test reports it, and of those at
// the same t the one listed first in the scene (the smallest Triangle::primitive). The rule
// names one hit of the set whatever order the triangles are tested in, so the answer does
// not depend on the tree (builder, leaf size, binary or wide) or on the order a traversal
// visits it in: a ray through an edge shared by two triangles reports the same one on every
// backend. `t`, `primitive`: a hit; `bestT`, `bestPrimitive`: the closest so far (tMax and
// kNoPrimitive before the first).
PT_CONST uint kNoPrimitive = 0xFFFFFFFFu;
PT_HOT_INLINE bool isCloserHit(float t, uint primitive, float bestT, uint bestPrimitive) {
  return t < bestT || (t == bestT && primitive < bestPrimitive);
}

// The range to test boxes and triangles against once the closest hit so far is at `closest`.
// The triangle tests compare t * det with range * det and report t * det times 1 / det, so
// a triangle whose reported t equals `closest` (a tie that isCloserHit may still prefer) can
// fail a test against `closest` itself; widened by kFarScale (1 + 2 gamma(3), more than the
// three roundings between them) none is lost. Never beyond the query's tMax, which stays
// exact: what lies at tMax or beyond is not hit.
PT_HOT_INLINE float searchRange(float closest, float tMax) {
  return min(closest * kFarScale, tMax);
}

// ---- Ray origins -----------------------------------------------------------------------

// Moves a ray origin p off its surface along n (unit, on the side the new ray leaves from)
// by a fixed fraction of `magnitude`, the largest absolute coordinate of p and of the
// triangle's vertices. Why that scale: the watertight test's rounding, and so the distance
// at which a ray can re-hit its own triangle, grows with the coordinates of the vertices
// relative to the origin, all three axes mixed by the shear. Wächter and Binder (Ray Tracing
// Gems, 2019, ch. 6) offset each axis by ulps of that axis alone; on a plane through the
// origin (the Cornell box's green wall is x = 0) that leaves an offset of 1e-5 where the
// test rounds at 1e-4 (coordinates ~500), and shadow rays hit their own wall. 2^-16 of the
// magnitude is 64 to 128 float ulps of the largest coordinate: far above that rounding,
// scale-invariant, and (0.009 in the Cornell box) below its 0.01 light-to-ceiling gap.
PT_CONST float kOffsetScale = 1.0f / 65536.0f;

PT_INLINE float triangleMagnitude(vec3 v0, vec3 v1, vec3 v2) {
  vec3 m = max(abs(v0), max(abs(v1), abs(v2)));
  return max(m.x, max(m.y, m.z));
}

PT_INLINE vec3 offsetRayOrigin(vec3 p, vec3 n, float magnitude) {
  return p + (magnitude * kOffsetScale) * n;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_SAMPLING_H
