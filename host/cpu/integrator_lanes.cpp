// sampleRadiance (integrator.cpp) for several pixels at once, one path per lane of the vector
// registers. Compiled once per x86 instruction set that Highway targets here (foreach_target.h
// includes this file once for each) and dispatched at run time, like the wide traversal.
//
// The loop below is the reference's, step for step, and calls the same steps of
// path_vertex.h, lane by lane. What it does differently is only the scheduling: each step runs
// for every lane with a path under way before the next step starts, a lane whose path ends
// takes the next pixel's at once, and what vectorizes well runs in all lanes at once: the
// random numbers (random2's vector form, random_lanes-inl.h) and the rays' set-up and root-box
// test before traversal (setUpRays), for the paths' rays and the shadow rays alike. Traversal
// is the wide BVH's own queries, a lane at a time.
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

#include "bvh/wide_bvh.h"
#include "bvh/wide_traverse-inl.h"
#include "cpu/integrator.h"
#include "cpu/integrator_lanes.h"
#include "cpu/random_lanes-inl.h"
#include "cpu/volpath.h"
#include "filter.h"
#include "path_vertex.h"

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
HWY_INLINE V3 operator-(V3 a, V3 b) {
  return V3{hn::Sub(a.x, b.x), hn::Sub(a.y, b.y), hn::Sub(a.z, b.z)};
}
HWY_INLINE V3 operator*(V3 a, V3 b) {
  return V3{hn::Mul(a.x, b.x), hn::Mul(a.y, b.y), hn::Mul(a.z, b.z)};
}
HWY_INLINE V splat(float x) {
  return hn::Set(D(), x);
}
// glm's max(a, b) is (a < b) ? b : a, spelled here as that selection (Highway's Max leaves a
// NaN's side open); min likewise.
HWY_INLINE V glmMax(V a, V b) {
  return hn::IfThenElse(hn::Lt(a, b), b, a);
}
HWY_INLINE V glmMin(V a, V b) {
  return hn::IfThenElse(hn::Lt(b, a), b, a);
}

// Lane masks as bits (lane i: bit i) for the lane-by-lane loops.
HWY_INLINE uint32_t bits(M m) {
  uint8_t b = 0;
  hn::StoreMaskBits(D(), m, &b);
  return b;
}
template <class F>
HWY_INLINE void forEachLane(uint32_t lanes, F&& f) {
  for (; lanes != 0; lanes &= lanes - 1u) f(size_t(std::countr_zero(lanes)));
}

// The Lambertian lobe's sampling (sampling.h's sampleCosineHemisphere and localToWorld, as
// path_vertex.h's sampleBsdfAt calls them) for all lanes at once, operation for operation: the
// one step of a path vertex that the lanes vectorize, as it was most of a diffuse vertex's
// arithmetic (CpuLanes.EqualsTheReferenceBitForBit holds it to the scalar definition).
HWY_INLINE V3 operator+(V3 a, V3 b) {
  return V3{hn::Add(a.x, b.x), hn::Add(a.y, b.y), hn::Add(a.z, b.z)};
}
HWY_INLINE V3 operator*(V s, V3 a) {
  return V3{hn::Mul(s, a.x), hn::Mul(s, a.y), hn::Mul(s, a.z)};
}
HWY_INLINE V dot(V3 a, V3 b) {
  return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
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

// The pinhole's ray direction through film points (x, y) for all lanes at once (sampling.h's
// cameraDirection, operation for operation; glm's normalize(v) is v * (1 / sqrt(dot(v, v)))).
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

// The pixel filters' film points (filter.h's sampleFilm for the box, the triangle and the
// gaussian, whose weights are 1) for all lanes at once, operation for operation: the offset
// from the pixel's corner along one axis of radius r for uniform numbers u.
HWY_INLINE V sampleBoxLanes(V u, float r) {
  return hn::Add(splat(0.5f - r), hn::Mul(splat(2.0f * r), u));
}
HWY_INLINE V sampleTentLanes(V u, float r) {
  const V rv = splat(r);
  const V left = hn::Sub(hn::Mul(rv, hn::Sqrt(hn::Mul(splat(2.0f), u))), rv);
  const V right = hn::Sub(rv, hn::Mul(rv, hn::Sqrt(hn::Sub(splat(2.0f), hn::Mul(splat(2.0f), u)))));
  return hn::Add(splat(0.5f), hn::IfThenElse(hn::Lt(u, splat(0.5f)), left, right));
}
HWY_INLINE V filterErfLanes(V x) {
  const V a = glmMin(hn::Abs(x), splat(6.0f));
  V p = hn::Mul(a, splat(0.0000430638f));
  p = hn::Mul(a, hn::Add(splat(0.0002765672f), p));
  p = hn::Mul(a, hn::Add(splat(0.0001520143f), p));
  p = hn::Mul(a, hn::Add(splat(0.0092705272f), p));
  p = hn::Mul(a, hn::Add(splat(0.0422820123f), p));
  p = hn::Add(splat(1.0f), hn::Mul(a, hn::Add(splat(0.0705230784f), p)));
  p = hn::Mul(p, p);
  p = hn::Mul(p, p);
  p = hn::Mul(p, p);
  p = hn::Mul(p, p);
  const V e = hn::Sub(splat(1.0f), hn::Div(splat(1.0f), p));
  return hn::IfThenElse(hn::Lt(x, hn::Zero(D())), hn::Neg(e), e);
}
// The gaussian's bisection (filter.h's sampleFilm) on one axis: radius r, the camera's k and
// e (filterScale, filterExpX or Y).
HWY_INLINE V sampleGaussianLanes(V u, float r, float k, float e) {
  const float erfRadius = filterErf(k * r);
  const auto cdf = [&](V x) {
    return hn::Sub(hn::Add(filterErfLanes(hn::Mul(splat(k), x)), splat(erfRadius)),
                   hn::Mul(splat(e), hn::Add(x, splat(r))));
  };
  const V target = hn::Mul(u, splat(gaussianFilterCdf(r, r, k, e, erfRadius)));
  V lo = splat(-r);
  V hi = splat(r);
  for (uint i = 0u; i < kFilterBisectionSteps; ++i) {
    const V mid = hn::Mul(splat(0.5f), hn::Add(lo, hi));
    const M below = hn::Lt(cdf(mid), target);
    lo = hn::IfThenElse(below, mid, lo);
    hi = hn::IfThenElse(below, hi, mid);
  }
  return hn::Add(splat(0.5f), hn::Mul(splat(0.5f), hn::Add(lo, hi)));
}
// sampleFilm's point for the lanes' camera (a pinhole with one of the three filters).
HWY_INLINE V sampleFilmAxisLanes(const Camera& cam, V u, float r, float e) {
  if (cam.filterType == kFilterTriangle) return sampleTentLanes(u, r);
  if (cam.filterType == kFilterGaussian) return sampleGaussianLanes(u, r, cam.filterScale, e);
  return sampleBoxLanes(u, r);
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
  alignas(32) uint32_t dim[kMaxLanes] = {};  // the scattering event's first dimension
  uint32_t depth[kMaxLanes] = {};
  Lanes3 origin, direction;  // `ray`
  PathState state[kMaxLanes];
  float weight[kMaxLanes] = {};  // the camera sample's weight (filter.h): multiplies L at the end
};

// random2 of each lane in `lanes`: its pixel, the sample, dimension dim[i] + offset (for a
// lane outside `lanes`, numbers of no use); .x into ux, .y into uy.
HWY_INLINE void drawRandom2(bool sobol, const Paths& path, uint sampleIndex, uint offset, uint seed,
                            uint32_t lanes, Lanes& ux, Lanes& uy) {
#if HWY_TARGET == HWY_SCALAR
  forEachLane(lanes, [&](size_t i) {
    const vec2 u = random2(sobol, uvec2(path.pixelX[i], path.pixelY[i]), sampleIndex,
                           path.dim[i] + offset, seed);
    ux.v[i] = u.x;
    uy.v[i] = u.y;
  });
#else
  (void)lanes;
  const hn::RebindToUnsigned<D> du;
  V x, y;
  random_lanes::random2(sobol, hn::Load(du, path.pixelX), hn::Load(du, path.pixelY), sampleIndex,
                        hn::Add(hn::Load(du, path.dim), hn::Set(du, offset)), seed, x, y);
  ux.store(x);
  uy.store(y);
#endif
}

void sampleRadianceLanesImpl(const SceneData& scene, const uvec2* pixels, size_t count,
                             uint32_t sampleIndex, vec3* out, uint64_t& raysTraced) {
  // Counted here and added once at the end: the caller's counter may share a cache line with
  // what another thread reads, and a store to it per ray moved that line between cores.
  uint64_t rays = 0;
  const size_t lanes = hn::Lanes(D());
  const RenderParams& params = scene.params;
  const PathScene ps = scene.pathScene();
  const CpuSceneCopies& copies = scene.cpuCopies();
  const uint seed = params.seed;
  const bool sobol = params.samplerType == kSamplerSobol;
  const Intersection intersection =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  const bool alpha = scene.effects.alphaCutouts;
  const bool footprints = footprintsOn(ps);
  const Camera& camera = params.camera;

  Paths path;
  size_t nextPixel = 0;
  uint32_t active = 0;  // lanes with a path under way
  for (size_t i = 0; i < kMaxLanes; ++i) path.slot[i] = -1;

  // Per step, per lane: the hit, the shading point, the random numbers, the light sample.
  SurfacePoint surface[kMaxLanes];
  VertexKey key[kMaxLanes];
  struct Lanes2 {
    Lanes x, y;
    vec2 get(size_t i) const { return vec2(x.v[i], y.v[i]); }
  } uLightChoose, uLight, uBsdf, uRoulette;
  Lanes3 normal, wiLambertian;  // a Lambertian lane's n, and its sampled direction
  Lanes pdfLambertian;
  LightSample light[kMaxLanes];
  Lanes3 shadowFrom, shadowDir;
  RayPrecomputed prepared[kMaxLanes];
  Hit laneHit[kMaxLanes];
  // The ray's closest hit with cut-outs passed by, where the scene has them (integrator.cpp's
  // closestSurface and occluded).
  auto closest = [&](size_t i, bool degenerate, bool enters, Hit& found) {
    AlphaCutouts cutouts{};
    HitFilter filter{};
    if (alpha) {
      cutouts = AlphaCutouts::ofPathRay(scene, uvec2(path.pixelX[i], path.pixelY[i]), sampleIndex,
                                        path.depth[i]);
      filter = cutouts.filter();
    }
    const HitFilter* f = alpha ? &filter : nullptr;
    if (degenerate) {
      const std::optional<Hit> hit = closestHit(
          copies.wide, Ray{path.origin.get(i), path.direction.get(i)}, INFINITY, intersection, f);
      if (hit) found = *hit;
      return hit.has_value();
    }
    return enters && wide_traversal::closestHitFromRoot(copies.wide, prepared[i], INFINITY,
                                                        intersection, found, f);
  };
  auto blocked = [&](size_t i, bool degenerate, bool enters) {
    AlphaCutouts cutouts{};
    HitFilter filter{};
    if (alpha) {
      cutouts = AlphaCutouts::ofShadowRay(scene, uLight.get(i));
      filter = cutouts.filter();
    }
    const HitFilter* f = alpha ? &filter : nullptr;
    if (degenerate) {
      return anyHit(copies.wide, Ray{shadowFrom.get(i), shadowDir.get(i)}, 1.0f, intersection, f);
    }
    return enters &&
           wide_traversal::anyHitFromRoot(copies.wide, prepared[i], 1.0f, intersection, f);
  };

  // A pinhole with the box, triangle or gaussian filter (whose samples weigh 1): the camera
  // rays are set up in lanes (sampleFilmAxisLanes). Mitchell's filter and the thin lens take
  // filter.h's generateCameraRay lane by lane.
  const bool cameraInLanes =
      (camera.filterType == kFilterBox || camera.filterType == kFilterTriangle ||
       camera.filterType == kFilterGaussian) &&
      !(camera.lensRadius > 0.0f);
  Lanes filmX, filmY;

  for (;;) {
    // Free lanes start the next pixels' paths: the camera ray through a point of the pixel's
    // filter (and lens).
    uint32_t starting = 0;
    for (size_t i = 0; i < lanes && nextPixel < count; ++i) {
      if (active >> i & 1u) continue;
      const uvec2 pixel = pixels[nextPixel];
      path.slot[i] = int32_t(nextPixel++);
      // The film's pixel (the crop's corner added), which the random numbers are of.
      const uvec2 filmPixel = pixel + uvec2(camera.cropX, camera.cropY);
      path.pixelX[i] = filmPixel.x;
      path.pixelY[i] = filmPixel.y;
      path.depth[i] = 0;
      path.dim[i] = 0;
      path.state[i] = startPathState();
      starting |= 1u << i;
      if (cameraInLanes) continue;
      const vec2 uLens = camera.lensRadius > 0.0f
                             ? random2(sobol, filmPixel, sampleIndex, kDimLens, seed)
                             : vec2(0.0f);
      const CameraSample ray = generateCameraRay(
          camera, filmPixel, random2(sobol, filmPixel, sampleIndex, kDimPixel, seed), uLens);
      path.state[i] = cameraPathState(ps, ray);
      path.origin.set(i, ray.origin);
      path.direction.set(i, ray.direction);
      path.weight[i] = ray.weight;
    }
    if (starting != 0 && cameraInLanes) {
      drawRandom2(sobol, path, sampleIndex, kDimPixel, seed, starting, filmX, filmY);
      const hn::RebindToSigned<D> di;
      const hn::RebindToUnsigned<D> du;
      const V x = hn::Add(
          hn::ConvertTo(D(), hn::BitCast(di, hn::Load(du, path.pixelX))),
          sampleFilmAxisLanes(camera, filmX.load(), camera.filterRadiusX, camera.filterExpX));
      const V y = hn::Add(
          hn::ConvertTo(D(), hn::BitCast(di, hn::Load(du, path.pixelY))),
          sampleFilmAxisLanes(camera, filmY.load(), camera.filterRadiusY, camera.filterExpY));
      Lanes3 direction;
      store(direction, cameraDirection(camera, x, y));
      Lanes filmPointX, filmPointY;
      filmPointX.store(x);
      filmPointY.store(y);
      forEachLane(starting, [&](size_t i) {
        path.origin.set(i, camera.position);
        path.direction.set(i, direction.get(i));
        path.weight[i] = 1.0f;
        if (footprints) {
          CameraSample c;
          c.origin = camera.position;
          c.direction = direction.get(i);
          c.weight = 1.0f;
          c.filmPoint = vec2(filmPointX.v[i], filmPointY.v[i]);
          c.lensOffset = vec3(0.0f);
          path.state[i] = cameraPathState(ps, c);
        }
      });
    }
    active |= starting;
    if (active == 0) break;

    // Find the closest surface along each ray; a lane whose ray leaves the scene is done. The
    // others: the shading point, and the emission their ray found.
    uint32_t live = 0;  // lanes whose path goes on through this step
    uint32_t degenerate = 0;
    const uint32_t enters =
        setUpRays(copies.wide, path.origin, path.direction, INFINITY, active, prepared, degenerate);
    // Every lane's hit first, its records asked of the cache at once (prefetchHitRecords), so
    // that the lanes' cache misses overlap; then their shading points.
    uint32_t hits = 0;
    forEachLane(active, [&](size_t i) {
      ++rays;
      if (!closest(i, (degenerate >> i & 1u) != 0u, (enters >> i & 1u) != 0u, laneHit[i])) {
        // The ray leaves the scene: the infinite light's radiance, weighed as an emitter's.
        addEnvironmentFound(ps, path.state[i], path.direction.get(i));
        return;
      }
      prefetchHitRecords(scene, laneHit[i]);
      hits |= 1u << i;
    });
    forEachLane(hits, [&](size_t i) {
      const Hit& hit = laneHit[i];
      const Triangle& tri = scene.bvh.triangles[hit.triangle];
      surface[i] = surfacePointAt(ps, hit.triangle, tri, hit.barycentrics, -path.direction.get(i),
                                  path.state[i].rd);
      addEmissionFound(ps, path.state[i], tri, surface[i], hit.t, path.origin.get(i));
      // Stop after maxDepth scattering events.
      if (path.depth[i] == params.maxDepth) return;
      path.dim[i] = kDimFirstBounce + kDimsPerBounce * path.depth[i];
      key[i] = VertexKey{uvec2(path.pixelX[i], path.pixelY[i]), sampleIndex, path.dim[i]};
      ++path.depth[i];
      live |= 1u << i;
    });

    // This event's random numbers (bounceRandom: four dimensions from dim, each for all lanes
    // at once).
    drawRandom2(sobol, path, sampleIndex, kDimLightChoose, seed, live, uLightChoose.x,
                uLightChoose.y);
    drawRandom2(sobol, path, sampleIndex, kDimLightPoint, seed, live, uLight.x, uLight.y);
    drawRandom2(sobol, path, sampleIndex, kDimBsdf, seed, live, uBsdf.x, uBsdf.y);
    drawRandom2(sobol, path, sampleIndex, kDimRoulette, seed, live, uRoulette.x, uRoulette.y);

    // Sample direct illumination from an emitter (next-event estimation): the light samples,
    // then their shadow rays, then the contributions of those found clear.
    uint32_t shadow = 0;  // lanes with a shadow ray to trace
    forEachLane(live, [&](size_t i) {
      if (!samplesLightAt(ps, surface[i])) return;
      light[i] = sampleLightAt(ps, surface[i], key[i], uLightChoose.get(i), uLight.get(i));
      if (!light[i].found) return;
      shadowFrom.set(i, light[i].from);
      shadowDir.set(i, light[i].to - light[i].from);
      shadow |= 1u << i;
    });
    if (shadow != 0) {
      uint32_t shadowDegenerate = 0;
      const uint32_t shadowEnters =
          setUpRays(copies.wide, shadowFrom, shadowDir, 1.0f, shadow, prepared, shadowDegenerate);
      forEachLane(shadow, [&](size_t i) {
        ++rays;
        if (blocked(i, (shadowDegenerate >> i & 1u) != 0u, (shadowEnters >> i & 1u) != 0u)) return;
        float weight;
        path.state[i].L +=
            lightSampleContribution(ps, surface[i], key[i], light[i], path.state[i].beta, weight);
      });
    }

    // Sample the BSDF for the next direction (Lambertian lanes all at once), possibly terminate
    // the path with Russian roulette, and leave the surface on the side of the new direction.
    uint32_t lambertian = 0;
    forEachLane(live, [&](size_t i) {
      if (surface[i].scatter != kScatterLambertian) return;
      normal.set(i, surface[i].n);
      lambertian |= 1u << i;
    });
    if (lambertian != 0) {
      const V3 n = load(normal);
      const V3 wi = localToWorld(sampleCosineHemisphere(uBsdf.x.load(), uBsdf.y.load()), n);
      store(wiLambertian, wi);
      pdfLambertian.store(hn::Mul(dot(wi, n), splat(kInvPi)));
    }
    forEachLane(live, [&](size_t i) {
      PathState& state = path.state[i];
      vec3 wi;
      bool scattered;
      if (lambertian >> i & 1u) {
        // sampleBsdfAt's Lambertian lobe, its direction and density from the lanes above.
        wi = wiLambertian.get(i);
        scattered = continueLambertian(surface[i], state, pdfLambertian.v[i]);
      } else {
        scattered = sampleBsdfAt(ps, surface[i], key[i], state, uRoulette.y.v[i], uBsdf.get(i), wi);
      }
      if (!scattered || maxComponent(state.beta) <= 0.0f ||
          !survivesRoulette(ps, state, path.depth[i], uRoulette.x.v[i])) {
        live &= ~(1u << i);
        return;
      }
      path.origin.set(i, nextRayOrigin(surface[i], wi));
      path.direction.set(i, wi);
    });

    // Paths that ended: their radiance goes out, their lanes are free.
    forEachLane(active & ~live, [&](size_t i) {
      out[path.slot[i]] = path.state[i].L * path.weight[i];
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
  // Scenes with media: the volume integrator, path by path.
  if (scene.params.mediaPresent != 0u) {
    for (size_t i = 0; i < count; ++i) {
      out[i] = sampleRadianceVolume(scene, pixels[i], sampleIndex, rays);
    }
    return;
  }
  HWY_DYNAMIC_DISPATCH(sampleRadianceLanesImpl)(scene, pixels, count, sampleIndex, out, rays);
}

std::vector<int64_t> radianceLanesTargets() {
  return hwy::SupportedAndGeneratedTargets();
}

}  // namespace pt
#endif  // HWY_ONCE
