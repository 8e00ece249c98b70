// An infinite light whose radiance is an image over the directions (pbrt-v4's
// ImageInfiniteLight): the radiance a direction sees, the light samples drawn from the image's
// piecewise-constant distribution, and their density. Shared by the CPU reference and the
// shader, so that both see and sample the same texels.
//
// The image is a square of (u, v) in [0, 1]^2, u across and v down (row 0 at the top), mapped to
// the directions of its frame (RenderParams::environmentX/Y/Z, the light's rotation) by
// pbrt-v4's equal-area octahedral map (its EqualAreaSquareToSphere, +z in the middle) or by the
// equirectangular (lat-long) map: theta = pi v from +y, phi = 2 pi u, the direction
// (-sin theta sin phi, cos theta, sin theta cos phi), so that the image's centre looks along -z
// and u grows to the right of a viewer facing it with +y up.
//
// The data, W x H texels of four floats (PT_BINDING_ENVIRONMENT on the GPU, a vector of vec4 on
// the CPU), in the order buildEnvironmentTexels (host/render/environment_map.h) writes them:
//   texel y W + x (x < W, y < H): the radiance of pixel (x, y) in rgb, and in w the end of its
//       bin in row y's conditional CDF (the sum of the row's weights up to and including x over
//       the row's sum; 1 at x = W - 1);
//   texel W H + y / 4, component y % 4: the end of row y's bin in the marginal CDF over rows;
//   then, four to a texel from float W H * 4 + ceil(H / 4) * 4 on: the marginal's guide table,
//       then row 0's, row 1's, ... (environmentGuideEntry below).
// A bin's probability is its CDF end minus its start (the previous end, 0 for the first): the
// sampler draws each bin with exactly that probability, and the density of a direction is read
// from the same two numbers, so that the sampled pdf and the pdf of a direction agree bit for
// bit. The includer provides the texels: in C++ EnvironmentMap::texels points at them; GLSL has
// no pointers, so the shader defines `vec4 environmentTexel(uint i)` before including this.
#ifndef PT_ENVIRONMENT_H
#define PT_ENVIRONMENT_H

#include "lights.h"
#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#define PT_ENVIRONMENT_TEXEL(env, i) ((env).texels[i])
#else
#define PT_ENVIRONMENT_TEXEL(env, i) environmentTexel(i)
#endif
// Counts the binary searches' iterations (lavapipe's loop cap, pathtrace.comp).
#ifndef PT_ENVIRONMENT_LOOP_TICK
#define PT_ENVIRONMENT_LOOP_TICK()
#endif

// What the functions below read besides the texels: RenderParams' environment fields.
struct EnvironmentMap {
  vec3 toWorldX;  // the image frame's axes in world space
  vec3 toWorldY;
  vec3 toWorldZ;
  uint width;
  uint height;
  uint mapping;  // kEnvironmentOctahedral or kEnvironmentLatLong
#ifdef __cplusplus
  const vec4* texels;
#endif
};

// pbrt-v4's equal-area map of the square onto the sphere (Clarberg's octahedral map): the
// square's centre is +z, its corners -z, the diamond between the edges' midpoints the upper
// hemisphere. Equal area: a uniform point of the square is a uniform direction.
PT_INLINE vec3 equalAreaSquareToSphere(vec2 p) {
  float u = 2.0f * p.x - 1.0f;
  float v = 2.0f * p.y - 1.0f;
  float au = abs(u);
  float av = abs(v);
  // The signed distance from the diagonal |u| + |v| = 1 (the equator): r is the distance from
  // the nearer pole in the square's L1 metric.
  float signedDistance = 1.0f - (au + av);
  float r = 1.0f - abs(signedDistance);
  float phi = (r == 0.0f ? 1.0f : (av - au) / r + 1.0f) * (kPi / 4.0f);
  float z = 1.0f - r * r;
  if (signedDistance < 0.0f) z = -z;
  float cosPhi = abs(cos(phi));
  float sinPhi = abs(sin(phi));
  if (u < 0.0f) cosPhi = -cosPhi;
  if (v < 0.0f) sinPhi = -sinPhi;
  float s = r * sqrt(max(0.0f, 2.0f - r * r));
  return vec3(cosPhi * s, sinPhi * s, z);
}

// Its inverse (pbrt-v4's EqualAreaSphereToSquare), for a unit direction d.
PT_INLINE vec2 equalAreaSphereToSquare(vec3 d) {
  vec3 a = abs(d);
  float r = sqrt(max(0.0f, 1.0f - a.z));
  float greater = max(a.x, a.y);
  float lesser = min(a.x, a.y);
  float ratio = greater == 0.0f ? 0.0f : lesser / greater;
  // The angle within the quadrant as a fraction of a right angle (pbrt-v4 approximates atan by
  // a polynomial; the exact one keeps the round trip tight).
  float phi = atan(ratio) * (2.0f / kPi);
  if (a.x < a.y) phi = 1.0f - phi;
  float v = phi * r;
  float u = r - v;
  if (d.z < 0.0f) {
    // The lower hemisphere: the triangle beyond the diagonal, mirrored.
    float t = u;
    u = 1.0f - v;
    v = 1.0f - t;
  }
  if (d.x < 0.0f) u = -u;
  if (d.y < 0.0f) v = -v;
  return vec2(0.5f * (u + 1.0f), 0.5f * (v + 1.0f));
}

// The direction of image point uv in the image's frame.
PT_INLINE vec3 environmentUvToDirection(EnvironmentMap env, vec2 uv) {
  if (env.mapping == kEnvironmentOctahedral) return equalAreaSquareToSphere(uv);
  float theta = kPi * uv.y;
  vec2 cs = cosSinTwoPi(uv.x);
  float sinTheta = sin(theta);
  return vec3(-sinTheta * cs.y, cos(theta), sinTheta * cs.x);
}

// The image point of unit direction d of the image's frame.
PT_INLINE vec2 environmentDirectionToUv(EnvironmentMap env, vec3 d) {
  if (env.mapping == kEnvironmentOctahedral) return equalAreaSphereToSquare(d);
  float phi = atan(-d.x, d.z);
  if (phi < 0.0f) phi += 2.0f * kPi;
  // theta by atan rather than acos, which loses the digits near the poles.
  return vec2(phi * (0.5f / kPi), atan(sqrt(d.x * d.x + d.z * d.z), d.y) * kInvPi);
}

// The texel nearest uv (pbrt-v4's LookupNearest): octahedral maps take pbrt-v4's
// OctahedralSphere wrap where uv reaches the square's far edges (the sphere continues across
// them mirrored); lat-long maps wrap around in u and clamp in v.
PT_INLINE uvec2 environmentTexelOf(EnvironmentMap env, vec2 uv) {
  int w = int(env.width);
  int h = int(env.height);
  int x = int(uv.x * float(w));
  int y = int(uv.y * float(h));
  if (env.mapping == kEnvironmentOctahedral) {
    if (x < 0) {
      x = -x;
      y = h - 1 - y;
    } else if (x >= w) {
      x = 2 * w - 1 - x;
      y = h - 1 - y;
    }
    if (y < 0) {
      x = w - 1 - x;
      y = -y;
    } else if (y >= h) {
      x = w - 1 - x;
      y = 2 * h - 1 - y;
    }
  } else {
    if (x >= w) x -= w;
    if (x < 0) x += w;
  }
  return uvec2(uint(clamp(x, 0, w - 1)), uint(clamp(y, 0, h - 1)));
}

// The end of bin i of a CDF: of the marginal over rows when row < 0, else of row `row`'s
// conditional over its texels.
PT_INLINE float environmentCdfEnd(EnvironmentMap env, int row, uint i) {
  if (row < 0) {
    vec4 t = PT_ENVIRONMENT_TEXEL(env, env.width * env.height + i / 4u);
    uint c = i & 3u;
    return c == 0u ? t.x : c == 1u ? t.y : c == 2u ? t.z : t.w;
  }
  return PT_ENVIRONMENT_TEXEL(env, uint(row) * env.width + i).w;
}

// A bin's probability: its CDF end minus its start.
PT_INLINE float environmentBinProbability(EnvironmentMap env, int row, uint i) {
  float start = i == 0u ? 0.0f : environmentCdfEnd(env, row, i - 1u);
  return environmentCdfEnd(env, row, i) - start;
}

// Guide tables (Chen and Asau's cutpoint method) start the searches below near their answer:
// a CDF of n bins has G + 1 entries, G = environmentGuideSize(n) a power of two about n / 8;
// entry k is the first bin whose end exceeds k / G (n - 1 where none does). A u in
// [k / G, (k + 1) / G) has its bin between entries k and k + 1, and the search there finds the
// bin that searching all n finds, in about three steps instead of log2 n (each a cache miss
// on a large image). The entries are stored as floats (exact: below 2^24).
PT_INLINE uint environmentGuideSize(uint count) {
  uint n = (count + 7u) / 8u;
  return n <= 1u ? 1u : (2u << uint(findMSB(n - 1u)));
}

// Where the guide table of `row` (-1: the marginal's) of a W x H image starts, in floats from
// the first texel's; row H's start is the end of the last.
PT_INLINE uint environmentGuideStart(uint width, uint height, int row) {
  uint i = 4u * (width * height + (height + 3u) / 4u);
  if (row >= 0) {
    i += environmentGuideSize(height) + 1u + uint(row) * (environmentGuideSize(width) + 1u);
  }
  return i;
}

// Entry k of the guide table of `row` (-1: the marginal's).
PT_INLINE uint environmentGuideEntry(EnvironmentMap env, int row, uint k) {
  uint i = environmentGuideStart(env.width, env.height, row) + k;
  vec4 t = PT_ENVIRONMENT_TEXEL(env, i / 4u);
  uint c = i & 3u;
  return uint(c == 0u ? t.x : c == 1u ? t.y : c == 2u ? t.z : t.w);
}

// The first of `count` bins whose CDF end exceeds u: the bin the inversion method gives for u in
// [0, 1). A bin of probability 0 is never the answer (its end equals the previous one).
PT_INLINE uint environmentFindBin(EnvironmentMap env, int row, uint count, float u) {
  // u G is exact (G a power of two), so u lies in [k / G, (k + 1) / G).
  uint guideSize = environmentGuideSize(count);
  uint k = min(uint(u * float(guideSize)), guideSize - 1u);
  uint lo = environmentGuideEntry(env, row, k);
  uint hi = environmentGuideEntry(env, row, k + 1u);
  while (lo < hi) {
    PT_ENVIRONMENT_LOOP_TICK();
    uint mid = (lo + hi) / 2u;
    if (environmentCdfEnd(env, row, mid) > u) {
      hi = mid;
    } else {
      lo = mid + 1u;
    }
  }
  return lo;
}

// The density of (u, v) in the image's square at texel xy: the marginal's probability of its row
// times the row's of the texel, over the texel's area 1 / (W H).
PT_INLINE float environmentUvPdf(EnvironmentMap env, uvec2 xy) {
  return environmentBinProbability(env, -1, xy.y) * float(env.height) *
         (environmentBinProbability(env, int(xy.y), xy.x) * float(env.width));
}

// The solid-angle density of direction d (of the image's frame) whose (u, v) density is uvPdf:
// the octahedral map is equal-area (4 pi of solid angle over the unit square); the lat-long
// map's texels shrink by sin theta towards the poles (d omega = 2 pi^2 sin theta du dv), where
// the density is taken as 0 (a pole has no area). sin theta from d's components, not from v, so
// that a sample's direction and the same direction looked up agree near the poles too.
PT_INLINE float environmentSolidAnglePdf(EnvironmentMap env, vec3 d, float uvPdf) {
  if (env.mapping == kEnvironmentOctahedral) return uvPdf * kInv4Pi;
  float sinTheta = sqrt(d.x * d.x + d.z * d.z);
  return sinTheta > 0.0f ? uvPdf / (2.0f * kPi * kPi * sinTheta) : 0.0f;
}

PT_INLINE vec3 environmentToWorld(EnvironmentMap env, vec3 d) {
  return normalize(env.toWorldX * d.x + env.toWorldY * d.y + env.toWorldZ * d.z);
}

PT_INLINE vec3 environmentFromWorld(EnvironmentMap env, vec3 w) {
  return normalize(vec3(dot(env.toWorldX, w), dot(env.toWorldY, w), dot(env.toWorldZ, w)));
}

// What a ray leaving the scene along world direction w sees: the radiance, and the solid-angle
// density with which light sampling (the light once chosen) draws w.
struct EnvironmentLookup {
  vec3 Le;
  float pdf;
};
PT_INLINE EnvironmentLookup environmentLookup(EnvironmentMap env, vec3 w) {
  vec3 d = environmentFromWorld(env, w);
  uvec2 xy = environmentTexelOf(env, environmentDirectionToUv(env, d));
  EnvironmentLookup e;
  e.Le = vec3(PT_ENVIRONMENT_TEXEL(env, xy.y * env.width + xy.x));
  e.pdf = environmentSolidAnglePdf(env, d, environmentUvPdf(env, xy));
  return e;
}

// A light sample of the image from point p (pbrt-v4's ImageInfiniteLight::SampleLi): a row from
// the marginal with u.y, a texel of it from its conditional with u.x, a uniform point of the
// texel (the remainders of u rescaled), its direction, radiance and density. No sample (Li 0,
// pdf 0) at a lat-long pole. The shadow ray ends 2 sceneRadius away, as sampleAnalyticLight's.
PT_INLINE AnalyticLightSample sampleEnvironmentLight(EnvironmentMap env, vec3 p, vec2 u,
                                                     float sceneRadius) {
  uint y = environmentFindBin(env, -1, env.height, u.y);
  float yStart = y == 0u ? 0.0f : environmentCdfEnd(env, -1, y - 1u);
  float yProbability = environmentCdfEnd(env, -1, y) - yStart;
  uint x = environmentFindBin(env, int(y), env.width, u.x);
  float xStart = x == 0u ? 0.0f : environmentCdfEnd(env, int(y), x - 1u);
  float xProbability = environmentCdfEnd(env, int(y), x) - xStart;
  // Where in the texel: the remainders, kept below 1 so that the point stays in it. (A bin of
  // probability 0 comes only of u = 1, which the samplers never give: no sample then.)
  bool found = xProbability > 0.0f && yProbability > 0.0f;
  float dx = found ? min((u.x - xStart) / xProbability, 0.99999994f) : 0.0f;
  float dy = found ? min((u.y - yStart) / yProbability, 0.99999994f) : 0.0f;
  vec2 uv = vec2((float(x) + max(dx, 0.0f)) / float(env.width),
                 (float(y) + max(dy, 0.0f)) / float(env.height));
  AnalyticLightSample s;
  s.delta = false;
  vec3 d = environmentUvToDirection(env, uv);
  s.wi = environmentToWorld(env, d);
  s.target = p + s.wi * (2.0f * sceneRadius);
  float uvPdf = yProbability * float(env.height) * (xProbability * float(env.width));
  s.pdf = found ? environmentSolidAnglePdf(env, d, uvPdf) : 0.0f;
  s.Li = s.pdf > 0.0f ? vec3(PT_ENVIRONMENT_TEXEL(env, y * env.width + x)) : vec3(0.0f);
  return s;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_ENVIRONMENT_H
