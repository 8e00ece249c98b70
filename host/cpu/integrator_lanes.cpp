// sampleRadiance (integrator.cpp) for several pixels at once, one path per vector lane.
// Compiled once per x86 instruction set that Highway targets here (foreach_target.h includes
// this file once for each) and dispatched at run time, like the wide traversal.
//
// The loop below is the reference's, step for step; every comment names the step of
// sampleRadiance it transcribes. What differs is only how the steps are carried out:
//  - arithmetic runs in all lanes at once, each lane doing the reference's operations in
//    their order. glm's max(a, b) is (a < b) ? b : a, spelled here as that selection
//    (Highway's Max leaves a NaN's side open);
//  - a branch of the reference becomes a lane mask: both sides are computed where any lane
//    takes them and each lane keeps its own side's result; a lane whose path ended leaves
//    the mask `live` and keeps its radiance;
//  - what reads memory by index (the hit triangle, its material, the emitter table) runs
//    lane by lane, and so does traversal, through the wide BVH's own queries; the rays'
//    set-up and root-box test before it run in lanes (setUpRays). The random numbers are
//    random2's vector form (random_lanes-inl.h).
#include <bit>
#include <cstdint>
#include <optional>
#include <vector>

#ifndef HWY_DISABLED_TARGETS  // AVX-512 as in the traversal (wide_traverse.cpp)
#define HWY_DISABLED_TARGETS (HWY_AVX3_DL)
#endif
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "cpu/integrator_lanes.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "bsdf.h"
#include "bvh/wide_bvh.h"
#include "bvh/wide_traverse-inl.h"
#include "cpu/integrator.h"
#include "cpu/integrator_lanes.h"
#include "cpu/random_lanes-inl.h"
#include "filter.h"

HWY_BEFORE_NAMESPACE();
namespace pt {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<float, 8>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;
constexpr size_t kMaxLanes = 8;

// A value per lane, in memory: what lane-by-lane code writes and vector code loads.
struct alignas(32) Lanes {
  float v[kMaxLanes] = {};
  V load() const { return hn::Load(D(), v); }
  void store(V x) { hn::Store(x, D(), v); }
};
struct Lanes3 {
  Lanes x, y, z;
  void set(size_t i, vec3 a) {
    x.v[i] = a.x;
    y.v[i] = a.y;
    z.v[i] = a.z;
  }
  vec3 get(size_t i) const { return vec3(x.v[i], y.v[i], z.v[i]); }
};

// A triangle per lane with its shading constants: the one hit, or the light sample's.
struct TriangleLanes {
  Lanes3 v0, v1, v2, normal;
  Lanes magnitude, area;
  void set(size_t i, const Triangle& tri, const TriangleShading& shading) {
    v0.set(i, tri.v0);
    v1.set(i, tri.v1);
    v2.set(i, tri.v2);
    normal.set(i, shading.normal);
    magnitude.v[i] = shading.magnitude;
    area.v[i] = shading.area;
  }
};

// vec3 arithmetic of glm, lane by lane, in glm's order.
struct V3 {
  V x, y, z;
};
HWY_INLINE V3 load(const Lanes3& a) {
  return V3{a.x.load(), a.y.load(), a.z.load()};
}
HWY_INLINE void store(Lanes3& a, V3 b) {
  a.x.store(b.x);
  a.y.store(b.y);
  a.z.store(b.z);
}
HWY_INLINE V3 operator+(V3 a, V3 b) {
  return V3{hn::Add(a.x, b.x), hn::Add(a.y, b.y), hn::Add(a.z, b.z)};
}
HWY_INLINE V3 operator-(V3 a, V3 b) {
  return V3{hn::Sub(a.x, b.x), hn::Sub(a.y, b.y), hn::Sub(a.z, b.z)};
}
HWY_INLINE V3 operator-(V3 a) {
  return V3{hn::Neg(a.x), hn::Neg(a.y), hn::Neg(a.z)};
}
HWY_INLINE V3 operator*(V3 a, V3 b) {
  return V3{hn::Mul(a.x, b.x), hn::Mul(a.y, b.y), hn::Mul(a.z, b.z)};
}
HWY_INLINE V3 operator*(V s, V3 a) {
  return V3{hn::Mul(s, a.x), hn::Mul(s, a.y), hn::Mul(s, a.z)};
}
HWY_INLINE V3 operator/(V3 a, V s) {
  return V3{hn::Div(a.x, s), hn::Div(a.y, s), hn::Div(a.z, s)};
}
HWY_INLINE V dot(V3 a, V3 b) {
  return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
}
HWY_INLINE V3 select(M m, V3 a, V3 b) {
  return V3{hn::IfThenElse(m, a.x, b.x), hn::IfThenElse(m, a.y, b.y), hn::IfThenElse(m, a.z, b.z)};
}
HWY_INLINE V glmMax(V a, V b) {
  return hn::IfThenElse(hn::Lt(a, b), b, a);
}
HWY_INLINE V maxComponent(V3 a) {
  return glmMax(a.x, glmMax(a.y, a.z));
}
HWY_INLINE V splat(float x) {
  return hn::Set(D(), x);
}

// Lane masks as bits (lane i: bit i) for the lane-by-lane loops, and back.
HWY_INLINE uint32_t bits(M m) {
  uint8_t b = 0;
  hn::StoreMaskBits(D(), m, &b);
  return b;
}
HWY_INLINE M mask(uint32_t b) {
  const uint8_t b8 = uint8_t(b);
  return hn::LoadMaskBits(D(), &b8);
}
template <class F>
HWY_INLINE void forEachLane(uint32_t lanes, F&& f) {
  for (; lanes != 0; lanes &= lanes - 1u) f(size_t(std::countr_zero(lanes)));
}

// sampling.h's functions on lanes, operation for operation.
HWY_INLINE V powerHeuristic(V a, V b) {
  const V a2 = hn::Mul(a, a);
  const V b2 = hn::Mul(b, b);
  return hn::IfThenElse(hn::Gt(a2, hn::Zero(D())), hn::Div(a2, hn::Add(a2, b2)), hn::Zero(D()));
}

HWY_INLINE V3 localToWorld(V3 local, V3 n) {
  const V one = splat(1.0f);
  const V s = hn::IfThenElse(hn::Ge(n.z, hn::Zero(D())), one, splat(-1.0f));
  const V a = hn::Div(splat(-1.0f), hn::Add(s, n.z));
  const V b = hn::Mul(hn::Mul(n.x, n.y), a);
  const V3 t{hn::Add(one, hn::Mul(hn::Mul(hn::Mul(s, n.x), n.x), a)), hn::Mul(s, b),
             hn::Mul(hn::Neg(s), n.x)};
  const V3 bt{b, hn::Add(s, hn::Mul(hn::Mul(n.y, n.y), a)), hn::Neg(n.y)};
  return (local.x * t + local.y * bt) + local.z * n;
}

HWY_INLINE void cosSinTwoPi(V u, V& c, V& s) {
  const D d;
  const V quadrant = hn::Floor(hn::Add(hn::Mul(splat(4.0f), u), splat(0.5f)));
  const V x = hn::Mul(splat(2.0f * kPi), hn::Sub(u, hn::Mul(splat(0.25f), quadrant)));
  const V x2 = hn::Mul(x, x);
  const V sinX = hn::Mul(
      x,
      hn::Add(
          splat(1.0f),
          hn::Mul(
              x2,
              hn::Add(splat(-1.0f / 6.0f),
                      hn::Mul(x2, hn::Add(splat(1.0f / 120.0f),
                                          hn::Mul(x2, hn::Add(splat(-1.0f / 5040.0f),
                                                              hn::Mul(x2, splat(1.0f /
                                                                                362880.0f))))))))));
  const V cosX = hn::Add(
      splat(1.0f),
      hn::Mul(
          x2,
          hn::Add(
              splat(-0.5f),
              hn::Mul(
                  x2,
                  hn::Add(
                      splat(1.0f / 24.0f),
                      hn::Mul(x2,
                              hn::Add(splat(-1.0f / 720.0f),
                                      hn::Mul(x2, hn::Add(splat(1.0f / 40320.0f),
                                                          hn::Mul(x2, splat(-1.0f /
                                                                            3628800.0f)))))))))));
  // Rotate by quadrant * 90 degrees: q = int(quadrant) & 3.
  const hn::RebindToSigned<D> di;
  const auto q = hn::And(hn::ConvertTo(di, quadrant), hn::Set(di, 3));
  const M q1 = hn::RebindMask(d, hn::Eq(q, hn::Set(di, 1)));
  const M q2 = hn::RebindMask(d, hn::Eq(q, hn::Set(di, 2)));
  const M q3 = hn::RebindMask(d, hn::Eq(q, hn::Set(di, 3)));
  c = hn::IfThenElse(q1, hn::Neg(sinX),
                     hn::IfThenElse(q2, hn::Neg(cosX), hn::IfThenElse(q3, sinX, cosX)));
  s = hn::IfThenElse(q1, cosX,
                     hn::IfThenElse(q2, hn::Neg(sinX), hn::IfThenElse(q3, hn::Neg(cosX), sinX)));
}

HWY_INLINE V3 sampleCosineHemisphere(V ux, V uy) {
  const V r = hn::Sqrt(ux);
  V c, s;
  cosSinTwoPi(uy, c, s);
  return V3{hn::Mul(r, c), hn::Mul(r, s),
            hn::Sqrt(glmMax(hn::Zero(D()), hn::Sub(splat(1.0f), ux)))};
}

// cameraDirection: normalize(v) is v * (1 / sqrt(dot(v, v))) in glm.
HWY_INLINE V3 cameraDirection(const Camera& cam, V filmX, V filmY) {
  const V u =
      hn::Sub(hn::Div(hn::Mul(splat(2.0f), filmX), splat(float(cam.filmWidth))), splat(1.0f));
  const V v =
      hn::Sub(splat(1.0f), hn::Div(hn::Mul(splat(2.0f), filmY), splat(float(cam.filmHeight))));
  auto broadcast = [](vec3 a) { return V3{splat(a.x), splat(a.y), splat(a.z)}; };
  const V3 w =
      (broadcast(cam.windowCenter) +
       hn::Mul(hn::Mul(u, splat(cam.tanHalfFovY)), splat(cam.aspect)) * broadcast(cam.right)) +
      hn::Mul(v, splat(cam.tanHalfFovY)) * broadcast(cam.up);
  return hn::Div(splat(1.0f), hn::Sqrt(dot(w, w))) * w;
}

HWY_INLINE V3 offsetRayOrigin(V3 p, V3 n, V magnitude) {
  return p + hn::Mul(magnitude, splat(kOffsetScale)) * n;
}

HWY_INLINE V glmMin(V a, V b) {
  return hn::IfThenElse(hn::Lt(b, a), b, a);
}

// The wide traversal's first steps for the rays of several lanes at once: RayPrecomputed
// (traverse.cpp; its six divisions become six vector divisions) and intersectBox against the
// root's box. Returns the lanes whose ray enters it, their `prepared` filled in for
// wide_traversal::closestHitFromRoot or anyHitFromRoot; a lane whose ray misses it misses every
// triangle. Degenerate rays (wide_bvh.h) are neither: they go to `degenerate`, for the ordinary
// queries.
HWY_INLINE uint32_t setUpRays(const WideBvh& bvh, const Lanes3& originLanes,
                              const Lanes3& directionLanes, float tMax, uint32_t lanes,
                              RayPrecomputed* prepared, uint32_t& degenerate) {
  const D d;
  const V zero = hn::Zero(d);
  const V3 o = load(originLanes);
  const V3 dir = load(directionLanes);
  // Degenerate, as wide_detail::degenerateRay (wide_bvh.h) tests it: not finite (x - x is 0 for a
  // number, NaN otherwise), or no direction.
  const V minDirection = splat(kMinDirection);
  const V finite = hn::Add(
      hn::Add(hn::Add(hn::Add(hn::Add(hn::Sub(o.x, o.x), hn::Sub(o.y, o.y)), hn::Sub(o.z, o.z)),
                      hn::Sub(dir.x, dir.x)),
              hn::Sub(dir.y, dir.y)),
      hn::Sub(dir.z, dir.z));
  const M noDirection =
      hn::And(hn::And(hn::Lt(hn::Abs(dir.x), minDirection), hn::Lt(hn::Abs(dir.y), minDirection)),
              hn::Lt(hn::Abs(dir.z), minDirection));
  degenerate = lanes & bits(hn::Or(hn::Not(hn::Eq(finite, zero)), noDirection));
  const uint32_t regular = lanes & ~degenerate;
  if (regular == 0) return 0;
  // 1 / direction, with |direction| clamped away from 0 (safeInverse).
  auto safeInverse = [&](V x) {
    return hn::Div(splat(1.0f), hn::IfThenElse(hn::Lt(hn::Abs(x), minDirection),
                                               hn::CopySign(minDirection, x), x));
  };
  const V3 inv{safeInverse(dir.x), safeInverse(dir.y), safeInverse(dir.z)};
  // kz, the axis of the largest |direction|: x if a.x > a.y and a.x > a.z, y if not a.x >
  // a.y but a.y > a.z, else z; kx and ky the next ones, swapped when direction[kz] < 0.
  const V3 a{hn::Abs(dir.x), hn::Abs(dir.y), hn::Abs(dir.z)};
  const M xOverY = hn::Gt(a.x, a.y);
  const M zIsX = hn::And(xOverY, hn::Gt(a.x, a.z));
  const M zIsY = hn::AndNot(xOverY, hn::Gt(a.y, a.z));
  const V dz = hn::IfThenElse(zIsX, dir.x, hn::IfThenElse(zIsY, dir.y, dir.z));
  const V dx = hn::IfThenElse(zIsX, dir.y, hn::IfThenElse(zIsY, dir.z, dir.x));
  const V dy = hn::IfThenElse(zIsX, dir.z, hn::IfThenElse(zIsY, dir.x, dir.y));
  const M swap = hn::Lt(dz, zero);
  Lanes sx, sy, sz;
  sx.store(hn::Div(hn::IfThenElse(swap, dy, dx), dz));
  sy.store(hn::Div(hn::IfThenElse(swap, dx, dy), dz));
  sz.store(hn::Div(splat(1.0f), dz));
  // The root's box (intersectBox).
  const V3 lo{splat(bvh.rootMin.x), splat(bvh.rootMin.y), splat(bvh.rootMin.z)};
  const V3 hi{splat(bvh.rootMax.x), splat(bvh.rootMax.y), splat(bvh.rootMax.z)};
  const V3 t0 = (lo - o) * inv;
  const V3 t1 = (hi - o) * inv;
  const V3 tMin{glmMin(t0.x, t1.x), glmMin(t0.y, t1.y), glmMin(t0.z, t1.z)};
  const V3 tMaxV{glmMax(t0.x, t1.x), glmMax(t0.y, t1.y), glmMax(t0.z, t1.z)};
  const V enter = glmMax(glmMax(tMin.x, tMin.y), glmMax(tMin.z, zero));
  const V exit =
      hn::Mul(glmMin(glmMin(tMaxV.x, tMaxV.y), glmMin(tMaxV.z, splat(tMax))), splat(kFarScale));
  const uint32_t enters = regular & bits(hn::Le(enter, exit));
  Lanes3 invLanes;
  store(invLanes, inv);
  const uint32_t xBits = bits(zIsX), yBits = bits(zIsY), swapBits = bits(swap);
  forEachLane(enters, [&](size_t i) {
    RayPrecomputed& r = prepared[i];
    r.origin = originLanes.get(i);
    r.direction = directionLanes.get(i);
    r.invDirection = invLanes.get(i);
    // kz as above (zIsX and zIsY exclude each other); kx = (kz + 1) % 3 and ky = (kx + 1) % 3,
    // swapped: by table, as the signs of directions would make branches unpredictable.
    static constexpr int kNext[2][3] = {{1, 2, 0}, {2, 0, 1}};
    const int swapped = int(swapBits >> i & 1u);
    r.kz = 2 - 2 * int(xBits >> i & 1u) - int(yBits >> i & 1u);
    r.kx = kNext[swapped][r.kz];
    r.ky = kNext[1 - swapped][r.kz];
    r.sx = sx.v[i];
    r.sy = sy.v[i];
    r.sz = sz.v[i];
  });
  return enters;
}

// The state of one path per lane: what sampleRadiance keeps across its loop.
struct Paths {
  int32_t slot[kMaxLanes];  // index into the caller's pixels, -1: the lane is free
  alignas(32) uint32_t pixelX[kMaxLanes] = {}, pixelY[kMaxLanes] = {};
  alignas(32) uint32_t depth[kMaxLanes] = {};
  alignas(32) uint32_t dim[kMaxLanes] = {};  // the scattering event's first dimension
  Lanes3 origin, direction;                  // `ray`
  Lanes3 L, beta;
  Lanes bsdfPdf;
  Lanes etaScale;         // squared relative indices refracted through (bsdf.h's materials)
  Lanes weight;           // the camera sample's weight (filter.h): multiplies L at the end
  uint32_t specular = 0;  // bits: specularBounce
};

// random2 of each lane in `lanes`: its pixel, the sample, dimension dim[i] + offset (for a
// lane outside `lanes`, numbers of no use); .x into ux, .y into uy where given.
HWY_INLINE void drawRandom2(bool sobol, const Paths& path, uint sampleIndex, uint offset, uint seed,
                            uint32_t lanes, Lanes& ux, Lanes* uy) {
#if HWY_TARGET == HWY_SCALAR
  forEachLane(lanes, [&](size_t i) {
    const vec2 u = random2(sobol, uvec2(path.pixelX[i], path.pixelY[i]), sampleIndex,
                           path.dim[i] + offset, seed);
    ux.v[i] = u.x;
    if (uy) uy->v[i] = u.y;
  });
#else
  (void)lanes;
  const hn::RebindToUnsigned<D> du;
  V x, y;
  random_lanes::random2(sobol, hn::Load(du, path.pixelX), hn::Load(du, path.pixelY), sampleIndex,
                        hn::Add(hn::Load(du, path.dim), hn::Set(du, offset)), seed, x, y);
  ux.store(x);
  if (uy) uy->store(y);
#endif
}

void sampleRadianceLanesImpl(const SceneData& scene, const uvec2* pixels, size_t count,
                             uint32_t sampleIndex, vec3* out, uint64_t& raysTraced) {
  // Counted here and added once at the end: the caller's counter may share a cache line with
  // what another thread reads, and a store to it per ray moved that line between cores.
  uint64_t rays = 0;
  const D d;
  const hn::RebindToUnsigned<D> du;
  const size_t lanes = hn::Lanes(d);
  const RenderParams& params = scene.params;
  const Bvh& bvh = scene.bvh;
  const CpuSceneCopies& copies = scene.cpuCopies();
  const uint seed = params.seed;
  const bool sobol = params.samplerType == kSamplerSobol;
  const bool misOn = params.strategy == kStrategyMis;
  const bool neeOn = params.strategy != kStrategyBsdf && params.emitterCount > 0;
  const bool bsdfEmissionOn = params.strategy != kStrategyNee;
  const bool environment = params.environmentEmitter != kNoEmitter;  // an infinite light
  const bool shadingNormals = !scene.normals.empty();  // vertex normals: shade about them
  const Intersection intersection =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  const V zero = hn::Zero(d);

  Paths path;
  size_t nextPixel = 0;
  uint32_t active = 0;  // lanes with a path under way
  for (size_t i = 0; i < kMaxLanes; ++i) path.slot[i] = -1;

  // Per step: what the hit and the scattering event read by index, gathered lane by lane.
  Lanes t, hitEmitterPmf;
  Lanes3 bary, reflectance, emission;
  TriangleLanes hitTriangle, lightTriangle;
  Lanes uLightChooseX, uLightChooseY, uLightX, uLightY, uBsdfX, uBsdfY, uRoulette, uRouletteY;
  uint32_t hitIndex[kMaxLanes] = {};  // the hit triangle (Bvh::triangles)
  Lanes3 shadingPoint, shadingNormal, hitNs, wiOther, sideOther;
  Lanes3 lightEmission, shadowFrom, shadowDir;
  const Emitter* analyticEmitter[kMaxLanes] = {};  // a lane's light of lights.h, if it chose one
  Lanes lightPmf;
  RayPrecomputed prepared[kMaxLanes];
  Lanes filmX, filmY;
  const Camera& camera = params.camera;
  // The box filter of one pixel and a pinhole: the uniform jitter in the pixel, in lanes. Other
  // filters and the thin lens take filter.h's generateCameraRay lane by lane (the same bits
  // as the reference, by definition; a camera ray is a small part of a path).
  const bool jitterInLanes = camera.filterType == kFilterBox && camera.filterRadiusX == 0.5f &&
                             camera.filterRadiusY == 0.5f && !(camera.lensRadius > 0.0f);

  for (;;) {
    // Free lanes start the next pixels' paths: the camera ray through a point of the pixel's
    // filter, radiance 0, throughput 1, the camera ray counting as specular.
    uint32_t starting = 0;
    for (size_t i = 0; i < lanes && nextPixel < count; ++i) {
      if (active >> i & 1u) continue;
      const uvec2 pixel = pixels[nextPixel];
      path.slot[i] = int32_t(nextPixel++);
      // The film's pixel (the crop's corner added), which the random numbers are of.
      path.pixelX[i] = pixel.x + camera.cropX;
      path.pixelY[i] = pixel.y + camera.cropY;
      path.depth[i] = 0;
      path.dim[i] = 0;
      path.origin.set(i, camera.position);
      path.L.set(i, vec3(0.0f));
      path.beta.set(i, vec3(1.0f));
      path.bsdfPdf.v[i] = 0.0f;
      path.etaScale.v[i] = 1.0f;
      path.weight.v[i] = 1.0f;
      path.specular |= 1u << i;
      starting |= 1u << i;
    }
    if (starting != 0 && !jitterInLanes) {
      forEachLane(starting, [&](size_t i) {
        const uvec2 filmPixel(path.pixelX[i], path.pixelY[i]);
        const vec2 uLens = camera.lensRadius > 0.0f
                               ? random2(sobol, filmPixel, sampleIndex, kDimLens, seed)
                               : vec2(0.0f);
        const CameraSample ray = generateCameraRay(
            camera, filmPixel, random2(sobol, filmPixel, sampleIndex, kDimPixel, seed), uLens);
        path.origin.set(i, ray.origin);
        path.direction.set(i, ray.direction);
        path.weight.v[i] = ray.weight;
      });
      active |= starting;
    } else if (starting != 0) {
      // Through a uniformly jittered point of the pixel: vec2(pixel) + random2(.., kDimPixel).
      drawRandom2(sobol, path, sampleIndex, kDimPixel, seed, starting, filmX, &filmY);
      const hn::RebindToSigned<D> di;
      const V filmPointX =
          hn::Add(hn::ConvertTo(d, hn::BitCast(di, hn::Load(du, path.pixelX))), filmX.load());
      const V filmPointY =
          hn::Add(hn::ConvertTo(d, hn::BitCast(di, hn::Load(du, path.pixelY))), filmY.load());
      const V3 direction = cameraDirection(camera, filmPointX, filmPointY);
      store(path.direction, select(mask(starting), direction, load(path.direction)));
      active |= starting;
    }
    if (active == 0) break;

    // Find the closest surface along each ray; a lane whose ray leaves the scene is done.
    uint32_t live = 0;      // lanes whose path goes on through this step
    uint32_t emitting = 0;  // hit lanes whose triangle is an emitter
    uint32_t mirror = 0;    // hit lanes on a mirror
    uint32_t other = 0;     // hit lanes on one of bsdf.h's materials
    uint32_t nonBlack = 0;  // hit lanes whose reflectance is not 0
    uint32_t degenerate = 0;
    const uint32_t enters =
        setUpRays(copies.wide, path.origin, path.direction, INFINITY, active, prepared, degenerate);
    forEachLane(active, [&](size_t i) {
      ++rays;
      std::optional<Hit> hit;
      if (degenerate >> i & 1u) {
        hit = closestHit(copies.wide, Ray{path.origin.get(i), path.direction.get(i)}, INFINITY,
                         intersection);
      } else if (enters >> i & 1u) {
        Hit found;
        if (wide_traversal::closestHitFromRoot(copies.wide, prepared[i], INFINITY, intersection,
                                               found)) {
          hit = found;
        }
      }
      if (!hit) {
        // The ray leaves the scene: the infinite light's radiance (environmentSeen, the
        // reference's own function).
        if (environment) {
          path.L.set(i, path.L.get(i) +
                            environmentSeen(scene, path.direction.get(i), path.beta.get(i),
                                            (path.specular >> i & 1u) != 0u, path.bsdfPdf.v[i]));
        }
        return;
      }
      live |= 1u << i;
      const Triangle& tri = bvh.triangles[hit->triangle];
      const Material& material = scene.materials[tri.material];
      const TriangleShading& shading = copies.shading[hit->triangle];
      t.v[i] = hit->t;
      bary.set(i, hit->barycentrics);
      hitTriangle.set(i, tri, shading);
      // The shading normal, as the reference interpolates it (bsdf.h's interpolatedNormal).
      if (shadingNormals) {
        hitNs.set(
            i, interpolatedNormal(scene.normals[tri.primitive], hit->barycentrics, shading.normal));
      }
      reflectance.set(i, material.reflectance);
      emission.set(i, material.emission);
      if (tri.emitter != kNoEmitter) {
        emitting |= 1u << i;
        hitEmitterPmf.v[i] = scene.emitters[tri.emitter].pmf;
      }
      hitIndex[i] = hit->triangle;
      mirror |= uint32_t(material.type == kMaterialMirror) << i;
      other |= uint32_t(material.type != kMaterialMirror && material.type != kMaterialDiffuse) << i;
      nonBlack |= uint32_t(material.reflectance != vec3(0.0f)) << i;
    });

    // Hit point from barycentrics; the geometric normal; the cosine towards the viewer.
    const V3 b = load(bary);
    const V3 p =
        (b.x * load(hitTriangle.v0) + b.y * load(hitTriangle.v1)) + b.z * load(hitTriangle.v2);
    const V3 ngv = load(hitTriangle.normal);
    const V3 dir = load(path.direction);
    const V3 wo = -dir;
    const V cosOut = dot(ngv, wo);
    V3 L = load(path.L);
    V3 beta = load(path.beta);

    // Add emitted light found by this ray: one-sided, on the geometric normal's side; at
    // full weight after a specular bounce, else weighed against light sampling (MIS).
    {
      const uint32_t front = emitting & live & bits(hn::Gt(cosOut, zero));
      const uint32_t full = front & path.specular;
      const uint32_t weighed = bsdfEmissionOn ? front & ~path.specular : 0u;
      if ((full | weighed) != 0) {
        const V3 Le = load(emission);
        V weight = splat(1.0f);
        if (misOn) {
          const V tv = t.load();
          const V lightPdf = hn::Div(hn::Mul(hn::Mul(hitEmitterPmf.load(), tv), tv),
                                     hn::Mul(cosOut, hitTriangle.area.load()));
          weight = powerHeuristic(path.bsdfPdf.load(), lightPdf);
        }
        const V3 fullL = L + beta * Le;
        const V3 weighedL = L + (weight * beta) * Le;
        L = select(mask(full), fullL, select(mask(weighed), weighedL, L));
      }
    }

    // Stop after maxDepth scattering events; the others draw this event's random numbers.
    {
      const auto depth = hn::Load(du, path.depth);
      live &= ~bits(hn::RebindMask(d, hn::Eq(depth, hn::Set(du, params.maxDepth))));
      hn::Store(hn::Add(hn::Set(du, kDimFirstBounce), hn::Mul(hn::Set(du, kDimsPerBounce), depth)),
                du, path.dim);
      hn::Store(
          hn::IfThenElse(hn::RebindMask(du, mask(live)), hn::Add(depth, hn::Set(du, 1u)), depth),
          du, path.depth);
    }
    // (bounceRandom: four dimensions from dim, each for all lanes at once.)
    drawRandom2(sobol, path, sampleIndex, kDimLightChoose, seed, live, uLightChooseX,
                &uLightChooseY);
    drawRandom2(sobol, path, sampleIndex, kDimLightPoint, seed, live, uLightX, &uLightY);
    drawRandom2(sobol, path, sampleIndex, kDimBsdf, seed, live, uBsdfX, &uBsdfY);
    drawRandom2(sobol, path, sampleIndex, kDimRoulette, seed, live, uRoulette, &uRouletteY);

    // Both materials are two-sided: shade with the normal facing the incoming ray (the shading
    // normal where the mesh has vertex normals).
    V3 n = select(hn::Ge(cosOut, zero), ngv, -ngv);
    if (shadingNormals) {
      const V3 ns = load(hitNs);
      n = select(hn::Ge(dot(ns, wo), zero), ns, -ns);
    }
    const V3 refl = load(reflectance);
    const V mag = hitTriangle.magnitude.load();
    const uint32_t diffuse = live & ~mirror & ~other;

    // Mirror: ideal reflection.
    const V3 wiMirror = dir - hn::Mul(splat(2.0f), dot(dir, n)) * n;

    // Diffuse: sample direct illumination from an emitter (next-event estimation).
    const uint32_t nee = neeOn ? diffuse & nonBlack : 0u;
    if (nee != 0) {
      // Pick an emitter from the alias table, then a uniform point on its triangle.
      uint32_t analytic = 0;  // lanes that chose a light of lights.h (taken lane by lane below)
      forEachLane(nee, [&](size_t i) {
        const uint slot = aliasTableSlot(uLightChooseX.v[i], params.emitterCount);
        const Emitter& emitter =
            scene.emitters[aliasTablePick(slot, scene.emitters[slot], uLightChooseY.v[i])];
        if ((emitter.triangle & kEmitterLight) != 0u) {
          analytic |= 1u << i;
          analyticEmitter[i] = &emitter;
          lightTriangle.set(i, bvh.triangles[0], copies.shading[0]);  // unused, but finite
          lightPmf.v[i] = 1.0f;
          lightEmission.set(i, vec3(0.0f));
          return;
        }
        const Triangle& light = bvh.triangles[emitter.triangle];
        const TriangleShading& lightShading = copies.shading[emitter.triangle];
        lightTriangle.set(i, light, lightShading);
        lightPmf.v[i] = emitter.pmf;
        lightEmission.set(i, scene.materials[light.material].emission);
      });
      const V uLx = uLightX.load();
      const V uLy = uLightY.load();
      const V su = hn::Sqrt(uLx);
      const V bx = hn::Mul(su, hn::Sub(splat(1.0f), uLy));
      const V by = hn::Mul(su, uLy);
      const V3 lightPoint = (hn::Sub(hn::Sub(splat(1.0f), bx), by) * load(lightTriangle.v0) +
                             bx * load(lightTriangle.v1)) +
                            by * load(lightTriangle.v2);
      const V3 lightN = load(lightTriangle.normal);
      const V3 toLight = lightPoint - p;
      const V dist2 = dot(toLight, toLight);
      const V3 wl = toLight / hn::Sqrt(dist2);
      const V cosLight = hn::Neg(dot(lightN, wl));
      const V cosSurface = dot(n, wl);
      const uint32_t facing =
          nee & ~analytic & bits(hn::And(hn::Gt(cosLight, zero), hn::Gt(cosSurface, zero)));
      // Shadow ray between the two offset points; t in [0, 1) spans the segment. It leaves
      // along n, or with shading normals on the side of the geometric normal the light is on.
      const V3 from = offsetRayOrigin(
          p, shadingNormals ? select(hn::Gt(dot(ngv, wl), zero), ngv, -ngv) : n, mag);
      const V3 to = offsetRayOrigin(lightPoint, lightN, lightTriangle.magnitude.load());
      store(shadowFrom, from);
      store(shadowDir, to - from);
      uint32_t shadowDegenerate = 0;
      const uint32_t shadowEnters =
          setUpRays(copies.wide, shadowFrom, shadowDir, 1.0f, facing, prepared, shadowDegenerate);
      uint32_t unoccluded = 0;
      forEachLane(facing, [&](size_t i) {
        ++rays;
        const bool occluded =
            (shadowDegenerate >> i & 1u)
                ? anyHit(copies.wide, Ray{shadowFrom.get(i), shadowDir.get(i)}, 1.0f, intersection)
                : (shadowEnters >> i & 1u) &&
                      wide_traversal::anyHitFromRoot(copies.wide, prepared[i], 1.0f, intersection);
        unoccluded |= uint32_t(!occluded) << i;
      });
      if (unoccluded != 0) {
        const V lightPdf =
            hn::Div(hn::Mul(lightPmf.load(), dist2), hn::Mul(cosLight, lightTriangle.area.load()));
        const V weight =
            misOn ? powerHeuristic(lightPdf, hn::Mul(cosSurface, splat(kInvPi))) : splat(1.0f);
        const V3 f = splat(kInvPi) * refl;
        const V3 contribution =
            hn::Div(hn::Mul(cosSurface, weight), lightPdf) * ((beta * f) * load(lightEmission));
        L = select(mask(unoccluded), L + contribution, L);
      }
      // Analytic lights: the reference's function, lane by lane (the same bits).
      if (analytic != 0) {
        store(path.L, L);
        store(shadingPoint, p);
        store(shadingNormal, n);
        store(path.beta, beta);
        forEachLane(analytic, [&](size_t i) {
          const vec3 ns = shadingNormal.get(i);
          path.L.set(
              i, path.L.get(i) + sampleAnalyticLightDiffuse(
                                     scene, *analyticEmitter[i], shadingPoint.get(i), ns,
                                     hitTriangle.normal.get(i), shadingNormals,
                                     hitTriangle.magnitude.v[i], path.beta.get(i),
                                     kInvPi * reflectance.get(i), vec2(uLightX.v[i], uLightY.v[i]),
                                     misOn, intersection, rays));
        });
        L = load(path.L);
      }
    }

    // bsdf.h's materials: the reference's scattering event (scatterAtBsdfVertex), lane by
    // lane, on the path state as the lanes hold it.
    uint32_t otherSpecular = 0;
    if ((live & other) != 0) {
      store(path.L, L);
      store(path.beta, beta);
      store(shadingPoint, p);
      forEachLane(live & other, [&](size_t i) {
        const Triangle& tri = bvh.triangles[hitIndex[i]];
        const vec3 ng = hitTriangle.normal.get(i);
        const BounceRandom u{vec2(uLightChooseX.v[i], uLightChooseY.v[i]),
                             vec2(uLightX.v[i], uLightY.v[i]), vec2(uBsdfX.v[i], uBsdfY.v[i]),
                             vec2(uRoulette.v[i], uRouletteY.v[i])};
        const BsdfVertex vertex{&tri,
                                &scene.materials[tri.material],
                                shadingPoint.get(i),
                                ng,
                                shadingNormals ? hitNs.get(i) : ng,
                                -path.direction.get(i),
                                hitTriangle.magnitude.v[i],
                                u,
                                uvec2(path.pixelX[i], path.pixelY[i]),
                                sampleIndex,
                                path.dim[i],
                                path.depth[i]};
        PathState state{path.L.get(i), path.beta.get(i), path.etaScale.v[i], path.bsdfPdf.v[i],
                        (path.specular >> i & 1u) != 0u};
        vec3 wi, side;
        if (!scatterAtBsdfVertex(scene, vertex, state, wi, side, rays, /*debugPrint=*/false)) {
          live &= ~(1u << i);
        }
        path.L.set(i, state.L);
        path.beta.set(i, state.beta);
        path.etaScale.v[i] = state.etaScale;
        path.bsdfPdf.v[i] = state.bsdfPdf;
        otherSpecular |= uint32_t(state.specularBounce) << i;
        wiOther.set(i, wi);
        sideOther.set(i, side);
      });
      L = load(path.L);
    }

    // Diffuse: sample the BSDF, cosine-weighted (f * cos / pdf = reflectance); a direction in
    // the tangent plane contributes nothing and ends the path.
    const V3 wiDiffuse = localToWorld(sampleCosineHemisphere(uBsdfX.load(), uBsdfY.load()), n);
    const V pdf = hn::Mul(dot(wiDiffuse, n), splat(kInvPi));
    live &= ~(diffuse & ~bits(hn::Gt(pdf, zero)));
    const M isMirror = mask(mirror);
    const M isOther = mask(other);
    const V3 wi = select(isOther, load(wiOther), select(isMirror, wiMirror, wiDiffuse));
    path.bsdfPdf.store(hn::IfThenElse(mask(mirror | other), path.bsdfPdf.load(), pdf));
    path.specular = mirror | otherSpecular;
    beta = select(isOther, load(path.beta), beta * refl);
    live &= ~bits(hn::Le(maxComponent(beta), zero));

    // Possibly terminate the path with Russian roulette (unbiased: survivors are scaled).
    if (params.russianRoulette != 0u) {
      const uint32_t roulette =  // lanes deep enough for it
          live & ~bits(hn::RebindMask(
                     d, hn::Lt(hn::Load(du, path.depth), hn::Set(du, params.rrStartDepth))));
      if (roulette != 0) {
        // beta * etaScale (etaScale is 1 but after refractions).
        const V q = glmMax(zero, hn::Sub(splat(1.0f), maxComponent(path.etaScale.load() * beta)));
        live &= ~(roulette & bits(hn::Lt(uRoulette.load(), q)));
        beta = select(mask(roulette), beta / hn::Sub(splat(1.0f), q), beta);
      }
    }

    // Leave the surface on the side of the new direction (of the geometric normal's sides,
    // with shading normals).
    const V3 side = shadingNormals ? select(hn::Gt(dot(ngv, wi), zero), ngv, -ngv) : n;
    store(path.origin, offsetRayOrigin(p, select(isOther, load(sideOther), side), mag));
    store(path.direction, wi);
    store(path.L, L);
    store(path.beta, beta);

    // Paths that ended: their radiance goes out, their lanes are free.
    forEachLane(active & ~live, [&](size_t i) {
      out[path.slot[i]] = path.L.get(i) * path.weight.v[i];
      path.slot[i] = -1;
    });
    active = live;
  }
  raysTraced += rays;
}

}  // namespace HWY_NAMESPACE
}  // namespace pt
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace pt {

HWY_EXPORT(sampleRadianceLanesImpl);

void sampleRadianceLanes(const SceneData& scene, const uvec2* pixels, size_t count,
                         uint32_t sampleIndex, vec3* out, uint64_t& rays) {
  // The lanes sample one-sided emissive triangles (and lights.h's point, spot, distant and
  // infinite lights) only, on untextured surfaces; a scene with two-sided or sphere lights, or
  // with textures, alpha cut-outs or bump maps, takes the reference path by path (the same
  // results by definition).
  if (scene.effects.twoSidedEmitters || scene.effects.sphereLights ||
      scene.params.texturesPresent != 0u) {
    for (size_t i = 0; i < count; ++i) out[i] = sampleRadiance(scene, pixels[i], sampleIndex, rays);
    return;
  }
  HWY_DYNAMIC_DISPATCH(sampleRadianceLanesImpl)(scene, pixels, count, sampleIndex, out, rays);
}

std::vector<int64_t> radianceLanesTargets() {
  return hwy::SupportedAndGeneratedTargets();
}

}  // namespace pt
#endif  // HWY_ONCE
