// The wide BVH's traversal (wide_bvh.h) for one Highway target: eight box tests and four
// triangle tests at a time, per x86 instruction set (AVX2 tests a node's eight boxes in one
// 256-bit vector, SSE4 and SSSE3 in two 128-bit halves; the four-lane triangle test uses
// 128-bit vectors everywhere). Included by wide_traverse.cpp, which dispatches to it at run
// time, and by integrator_lanes.cpp, whose per-target code calls it directly, without
// dispatching again for each ray.
//
// Exactness: each lane performs the operations of intersectBox and intersectTriangle
// (traverse.cpp) in their order, with the same comparisons, negated where the scalar code
// rejects (so that a NaN goes the same way). There are no fused multiply-adds: Highway's
// Mul and Add are separate instructions, and ptcore is compiled with -ffp-contract=off.

// Include guard per target (Highway's convention for "-inl.h" files).
#if defined(PT_BVH_WIDE_TRAVERSE_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PT_BVH_WIDE_TRAVERSE_INL_H_
#undef PT_BVH_WIDE_TRAVERSE_INL_H_
#else
#define PT_BVH_WIDE_TRAVERSE_INL_H_
#endif

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <hwy/highway.h>

#include "bvh/wide_bvh.h"

HWY_BEFORE_NAMESPACE();
namespace pt {
namespace HWY_NAMESPACE {
namespace wide_traversal {
namespace hn = hwy::HWY_NAMESPACE;

// A node of depth k below the root waits with at most seven siblings per level above it, and
// a wide node lies at least one binary level below its parent.
constexpr uint32_t kWideStackSize = 7 * kBvhStackSize;

// What a node's slab test gives the traversal.
struct ChildLanes {
  uint32_t hit;             // bit i: the ray enters child i's box within the range
  float enter[kWideLanes];  // entry distances (tNear of intersectBox)
};

#if HWY_TARGET == HWY_SCALAR

// Highway's one-lane fallback, for CPUs without SSSE3 (and in place of its four-lane
// emulation, which it disables under GCC < 12.3): the lanes one after another, with the
// same operations.

struct RayLanes {
  explicit RayLanes(const RayPrecomputed& r) : ray(r) {}
  const RayPrecomputed& ray;
};

inline ChildLanes intersectBoxes(const WideNode& node, const RayLanes& lanes, float tMax) {
  const RayPrecomputed& r = lanes.ray;
  ChildLanes box{};
  for (int i = 0; i < kWideLanes; ++i) {
    float tMin[3], tFar[3];
    for (int axis = 0; axis < 3; ++axis) {
      // The near plane's distance is min(t0, t1) of intersectBox for a box with lo <= hi
      // (see RayLanes below); an unused lane's inverted box never hits.
      const bool positive = r.invDirection[axis] > 0.0f;
      const float nearPlane = node.bounds[positive ? axis : axis + 3][i];
      const float farPlane = node.bounds[positive ? axis + 3 : axis][i];
      tMin[axis] = (nearPlane - r.origin[axis]) * r.invDirection[axis];
      tFar[axis] = (farPlane - r.origin[axis]) * r.invDirection[axis];
    }
    box.enter[i] = std::max(std::max(tMin[0], tMin[1]), std::max(tMin[2], 0.0f));
    const float exit = std::min(std::min(tFar[0], tFar[1]), std::min(tFar[2], tMax)) * kFarScale;
    if (box.enter[i] <= exit) box.hit |= 1u << i;
  }
  return box;
}

// RayPrecomputed(ray); false for a degenerate ray (see the vector version below).
inline bool precomputeRay(const Ray& ray, RayPrecomputed& r) {
  if (wide_detail::degenerateRay(ray)) return false;
  r = RayPrecomputed(ray);
  return true;
}

template <bool kAnyHit>
bool intersectLeafWatertight(const WideBvh& bvh, uint32_t firstPacket, uint32_t packetCount,
                             const RayLanes& lanes, HitSearch& search) {
  return wide_detail::intersectLeafLaneByLane<kAnyHit, /*kWatertight=*/true>(
      bvh, firstPacket, packetCount, lanes.ray, search);
}

#else  // vector instructions

// Boxes: eight lanes in one vector where the target has 256-bit vectors, else two halves.
constexpr int kBoxParts = HWY_MAX_BYTES >= 32 ? 1 : 2;
constexpr int kBoxPartLanes = kWideLanes / kBoxParts;
using DB = hn::FixedTag<float, kBoxPartLanes>;
using VB = hn::Vec<DB>;
// Triangles: four lanes.
using D = hn::FixedTag<float, kPacketLanes>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// Bit i: lane i of the mask (at most eight lanes).
template <class Tag>
HWY_INLINE uint32_t laneBits(Tag d, hn::Mask<Tag> m) {
  uint8_t bits = 0;
  hn::StoreMaskBits(d, m, &bits);
  return bits;
}

// Where a node's near and far planes lie for a ray, by its octant (bit a: 1/d[a] < 0): the
// slab distances min(t0, t1) and max(t0, t1) are the near and the far plane's, for a positive
// 1/d the lower plane's distance being the smaller (rounding is monotonic), for a negative one
// the upper's (1/d is never 0; its sign is the direction's). Offsets into WideNode::bounds,
// in floats: lo.x, lo.y, lo.z, hi.x, hi.y, hi.z rows of kWideLanes each.
struct SlabRows {
  uint32_t near[3], far[3];
};
constexpr SlabRows slabRows(int octant) {
  SlabRows rows{};
  for (int axis = 0; axis < 3; ++axis) {
    const bool negative = (octant >> axis & 1) != 0;
    rows.near[axis] = uint32_t(kWideLanes * (negative ? axis + 3 : axis));
    rows.far[axis] = uint32_t(kWideLanes * (negative ? axis : axis + 3));
  }
  return rows;
}
inline constexpr SlabRows kSlabRows[8] = {slabRows(0), slabRows(1), slabRows(2), slabRows(3),
                                          slabRows(4), slabRows(5), slabRows(6), slabRows(7)};

// The ray's constants, broadcast to every lane, and where the rows it reads lie. (Built from
// plain arrays and tables: glm's vec3 indexing by a variable is a switch, whose branches for
// random directions are mispredicted.)
struct RayLanes {
  explicit RayLanes(const RayPrecomputed& r) {
    const float o[3] = {r.origin.x, r.origin.y, r.origin.z};
    const float inv[3] = {r.invDirection.x, r.invDirection.y, r.invDirection.z};
    const int k[3] = {r.kx, r.ky, r.kz};
    const int octant = int(inv[0] < 0.0f) | int(inv[1] < 0.0f) << 1 | int(inv[2] < 0.0f) << 2;
    rows = &kSlabRows[octant];
    for (int axis = 0; axis < 3; ++axis) {
      origin[axis] = hn::Set(DB(), o[axis]);
      invDirection[axis] = hn::Set(DB(), inv[axis]);
      shearRow[axis] = uint32_t(kPacketLanes * k[axis]);
      shearOrigin[axis] = hn::Set(D(), o[k[axis]]);
    }
    sx = hn::Set(D(), r.sx);
    sy = hn::Set(D(), r.sy);
    sz = hn::Set(D(), r.sz);
  }
  VB origin[3], invDirection[3];
  const SlabRows* rows;  // the ray's octant's
  uint32_t shearRow[3];  // offsets of axes kx, ky, kz into a vertex of a packet, in floats
  V shearOrigin[3];      // origin[kx], origin[ky], origin[kz]
  V sx, sy, sz;
};

// The slab test of intersectBox on the eight children at once. Unused lanes hold an
// inverted box (lo = +inf, hi = -inf): its near planes are at +inf, so it never hits. (The
// short loops over parts and axes are unrolled by pragma: GCC at -O2 would otherwise keep
// the arrays of vectors in memory, which measured a third slower.)
HWY_INLINE ChildLanes intersectBoxes(const WideNode& node, const RayLanes& ray, float tMax) {
  const DB d;
  const VB zero = hn::Zero(d);
  ChildLanes box;
  box.hit = 0;
#pragma GCC unroll 2
  for (int p = 0; p < kBoxParts; ++p) {
    const float* bounds = node.bounds[0] + p * kBoxPartLanes;
    VB tMin[3], tFar[3];
#pragma GCC unroll 3
    for (int axis = 0; axis < 3; ++axis) {
      tMin[axis] = hn::Mul(hn::Sub(hn::Load(d, bounds + ray.rows->near[axis]), ray.origin[axis]),
                           ray.invDirection[axis]);
      tFar[axis] = hn::Mul(hn::Sub(hn::Load(d, bounds + ray.rows->far[axis]), ray.origin[axis]),
                           ray.invDirection[axis]);
    }
    const VB enter = hn::Max(hn::Max(tMin[0], tMin[1]), hn::Max(tMin[2], zero));
    const VB exit = hn::Mul(hn::Min(hn::Min(tFar[0], tFar[1]), hn::Min(tFar[2], hn::Set(d, tMax))),
                            hn::Set(d, kFarScale));
    box.hit |= laneBits(d, hn::Le(enter, exit)) << (p * kBoxPartLanes);
    hn::StoreU(enter, d, box.enter + p * kBoxPartLanes);
  }
  return box;
}

// RayPrecomputed(ray) (traverse.cpp), the same values bit for bit, in a few vector operations
// and without branches: for random directions, the constructor's branches on the largest axis
// and on the signs are mispredicted often enough to cost a sixth of a small scene's rays. The
// divisions are IEEE's in every lane, the constructor's six in two vectors. (The ray is read
// in place and built in registers: vectors assembled in memory from single floats would wait
// for those stores.) Returns false, and leaves `r` unset, for a degenerate ray (wide_bvh.h).
HWY_INLINE bool precomputeRay(const Ray& ray, RayPrecomputed& r) {
  static_assert(sizeof(Ray) == 6 * sizeof(float), "Ray: origin and direction, unpadded");
  const D d;
  const float* in = &ray.origin.x;
  const V o = hn::LoadU(d, in);  // origin; its fourth lane is direction.x, unused
  // (o.z, d.x, d.y, d.z) shifted down a lane: the direction, its fourth lane unused.
  const V dir = hn::CombineShiftRightBytes<4>(d, o, hn::LoadU(d, in + 2));
  const V zero = hn::Zero(d);
  const V minDirection = hn::Set(d, kMinDirection);
  const V a = hn::Abs(dir);
  const M tiny = hn::Lt(a, minDirection);
  // degenerateRay's tests: every coordinate a number (x - x == 0), and some direction.
  const M finite = hn::And(hn::Eq(hn::Sub(o, o), zero), hn::Eq(hn::Sub(dir, dir), zero));
  if ((laneBits(d, finite) & 7u) != 7u || (laneBits(d, tiny) & 7u) == 7u) return false;
  // 1 / direction, |direction| clamped away from 0 (safeInverse).
  const V inv =
      hn::Div(hn::Set(d, 1.0f), hn::IfThenElse(tiny, hn::CopySign(minDirection, dir), dir));
  // kz: x if a.x > a.y and a.x > a.z, y if not a.x > a.y but a.y > a.z, else z; then kx and
  // ky, the next axes, swapped where direction[kz] < 0: by arithmetic and a table, not
  // branches.
  const uint32_t nextAxis = laneBits(d, hn::Gt(a, hn::Shuffle0321(a)));   // x > y, y > z
  const uint32_t axisAfter = laneBits(d, hn::Gt(a, hn::Shuffle1032(a)));  // x > z
  const int xOverY = int(nextAxis & 1u), yOverZ = int(nextAxis >> 1 & 1u);
  const int kz = 2 - 2 * xOverY * int(axisAfter & 1u) - (1 - xOverY) * yOverZ;
  alignas(16) float d4[4];
  hn::Store(dir, d, d4);
  const int swapped = d4[kz] < 0.0f ? 1 : 0;
  // Lanes kx, ky, then the fourth lane (set to 1 below) twice, by kz and swap.
  alignas(16) static constexpr int32_t kShearLanes[3][2][4] = {
      {{1, 2, 3, 3}, {2, 1, 3, 3}}, {{2, 0, 3, 3}, {0, 2, 3, 3}}, {{0, 1, 3, 3}, {1, 0, 3, 3}}};
  const int32_t* lanes = kShearLanes[kz][swapped];
  // sx, sy, sz = d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz] in one division.
  const V dirOne = hn::IfThenElse(hn::FirstN(d, 3), dir, hn::Set(d, 1.0f));
  const V shear =
      hn::Div(hn::TableLookupLanes(dirOne, hn::SetTableIndices(d, lanes)), hn::Set(d, d4[kz]));
  alignas(16) float inv4[4], shear4[4];
  hn::Store(inv, d, inv4);
  hn::Store(shear, d, shear4);
  r.origin = ray.origin;
  r.direction = ray.direction;
  r.invDirection = vec3(inv4[0], inv4[1], inv4[2]);
  r.kx = lanes[0];
  r.ky = lanes[1];
  r.kz = kz;
  r.sx = shear4[0];
  r.sy = shear4[1];
  r.sz = shear4[2];
  return true;
}

// A packet's vertices relative to the ray's origin, sheared so that the ray becomes the +z
// axis: x and y of each, and z before the scaling by sz.
struct ShearedPacket {
  V akz, bkz, ckz, ax, ay, bx, by, cx, cy;
};

HWY_INLINE ShearedPacket shearPacket(const TrianglePacket& packet, const RayLanes& ray) {
  const D d;
  // Row `axis` of a vertex's coordinates, relative to the origin.
  auto relative = [&](const float* vertex, int axis) {
    return hn::Sub(hn::Load(d, vertex + ray.shearRow[axis]), ray.shearOrigin[axis]);
  };
  const float* v0 = packet.v[0][0];
  const float* v1 = packet.v[1][0];
  const float* v2 = packet.v[2][0];
  ShearedPacket s;
  s.akz = relative(v0, 2);
  s.bkz = relative(v1, 2);
  s.ckz = relative(v2, 2);
  s.ax = hn::Sub(relative(v0, 0), hn::Mul(ray.sx, s.akz));
  s.ay = hn::Sub(relative(v0, 1), hn::Mul(ray.sy, s.akz));
  s.bx = hn::Sub(relative(v1, 0), hn::Mul(ray.sx, s.bkz));
  s.by = hn::Sub(relative(v1, 1), hn::Mul(ray.sy, s.bkz));
  s.cx = hn::Sub(relative(v2, 0), hn::Mul(ray.sx, s.ckz));
  s.cy = hn::Sub(relative(v2, 1), hn::Mul(ray.sy, s.ckz));
  return s;
}

// Recomputes, in double precision as intersectTriangle does, the edge functions of the
// lanes where one came out exactly 0. Rare, so it shears the packet again rather than have
// the fast path keep the sheared vertices for it (which spilled them to memory).
struct EdgeFunctions {
  V u, v, w;
};
HWY_NOINLINE inline EdgeFunctions recomputeEdgesInDouble(const TrianglePacket& packet,
                                                         const RayLanes& ray, uint32_t lanes, V u,
                                                         V v, V w) {
  const D d;
  const ShearedPacket s = shearPacket(packet, ray);
  alignas(16) float a[2][kPacketLanes], b[2][kPacketLanes], c[2][kPacketLanes];
  alignas(16) float uu[kPacketLanes], vv[kPacketLanes], ww[kPacketLanes];
  hn::Store(s.ax, d, a[0]);
  hn::Store(s.ay, d, a[1]);
  hn::Store(s.bx, d, b[0]);
  hn::Store(s.by, d, b[1]);
  hn::Store(s.cx, d, c[0]);
  hn::Store(s.cy, d, c[1]);
  hn::Store(u, d, uu);
  hn::Store(v, d, vv);
  hn::Store(w, d, ww);
  for (int i = 0; i < kPacketLanes; ++i) {
    if (!(lanes >> i & 1u)) continue;
    uu[i] = float(double(c[0][i]) * double(b[1][i]) - double(c[1][i]) * double(b[0][i]));
    vv[i] = float(double(a[0][i]) * double(c[1][i]) - double(a[1][i]) * double(c[0][i]));
    ww[i] = float(double(b[0][i]) * double(a[1][i]) - double(b[1][i]) * double(a[0][i]));
  }
  return EdgeFunctions{hn::Load(d, uu), hn::Load(d, vv), hn::Load(d, ww)};
}

// The watertight test (intersectTriangle) on the triangles of one leaf, its packets in
// order, each packet's four lanes against the search range at once; the lanes it accepts are
// then offered to the search in lane order, as the scalar loop offers them. (The range only
// filters: a lane that the range of a hit taken in between would have rejected is not one
// that isCloserHit prefers to that hit.)
template <bool kAnyHit>
HWY_INLINE bool intersectLeafWatertight(const WideBvh& bvh, uint32_t firstPacket,
                                        uint32_t packetCount, const RayLanes& ray,
                                        HitSearch& search) {
  const D d;
  const V zero = hn::Zero(d);
  bool found = false;
  for (uint32_t p = firstPacket; p < firstPacket + packetCount; ++p) {
    const TrianglePacket& packet = bvh.packets[p];
    // Vertices relative to the origin, sheared so the ray becomes the +z axis.
    const ShearedPacket sh = shearPacket(packet, ray);
    // Scaled barycentrics: 2D edge functions of the projected edges against the origin.
    V u = hn::Sub(hn::Mul(sh.cx, sh.by), hn::Mul(sh.cy, sh.bx));
    V v = hn::Sub(hn::Mul(sh.ax, sh.cy), hn::Mul(sh.ay, sh.cx));
    V w = hn::Sub(hn::Mul(sh.bx, sh.ay), hn::Mul(sh.by, sh.ax));
    const uint32_t zeroEdge =
        laneBits(d, hn::Or(hn::Or(hn::Eq(u, zero), hn::Eq(v, zero)), hn::Eq(w, zero)));
    if (zeroEdge != 0) {
      const EdgeFunctions exact = recomputeEdgesInDouble(packet, ray, zeroEdge, u, v, w);
      u = exact.u;
      v = exact.v;
      w = exact.w;
    }
    // Rejections, as intersectTriangle makes them: mixed signs, det == 0, t out of range.
    const M negative = hn::Or(hn::Or(hn::Lt(u, zero), hn::Lt(v, zero)), hn::Lt(w, zero));
    const M positive = hn::Or(hn::Or(hn::Gt(u, zero), hn::Gt(v, zero)), hn::Gt(w, zero));
    const V det = hn::Add(hn::Add(u, v), w);
    // Scaled hit distance; compared against the range scaled by det.
    const V az = hn::Mul(ray.sz, sh.akz);
    const V bz = hn::Mul(ray.sz, sh.bkz);
    const V cz = hn::Mul(ray.sz, sh.ckz);
    const V t = hn::Add(hn::Add(hn::Mul(u, az), hn::Mul(v, bz)), hn::Mul(w, cz));
    const V range = hn::Mul(hn::Set(d, search.range), det);
    const M detPositive = hn::Gt(det, zero);
    const M outPositive = hn::Or(hn::Le(t, zero), hn::Ge(t, range));
    const M outNegative = hn::Or(hn::Ge(t, zero), hn::Le(t, range));
    const M reject =
        hn::Or(hn::Or(hn::And(negative, positive), hn::Eq(det, zero)),
               hn::Or(hn::And(detPositive, outPositive), hn::AndNot(detPositive, outNegative)));
    const uint32_t accepted = laneBits(d, hn::Not(reject)) & ((1u << packet.count) - 1u);
    if (accepted == 0) continue;
    // Any hit will do, unless a filter may drop it (then the hits are offered to it).
    if constexpr (kAnyHit) {
      if (search.filter == nullptr) return true;
    }
    alignas(16) float tl[kPacketLanes], dl[kPacketLanes], ul[kPacketLanes], vl[kPacketLanes],
        wl[kPacketLanes];
    hn::Store(t, d, tl);
    hn::Store(det, d, dl);
    hn::Store(u, d, ul);
    hn::Store(v, d, vl);
    hn::Store(w, d, wl);
    for (uint32_t rest = accepted; rest != 0; rest &= rest - 1u) {
      const int i = std::countr_zero(rest);
      const float invDet = 1.0f / dl[i];
      Hit hit;
      hit.t = tl[i] * invDet;
      hit.barycentrics = vec3(ul[i], vl[i], wl[i]) * invDet;
      if (search.offer(hit, packet.first + uint32_t(i), packet.primitive[i])) {
        if constexpr (kAnyHit) return true;
        found = true;
      }
    }
  }
  return found;
}

#endif  // HWY_TARGET == HWY_SCALAR

// Moller-Trumbore (intersectTriangleFast) lane by lane: only for measuring what the
// watertight test costs, so it is left scalar.
template <bool kAnyHit>
HWY_NOINLINE bool intersectLeafFast(const WideBvh& bvh, uint32_t firstPacket, uint32_t packetCount,
                                    const RayPrecomputed& ray, HitSearch& search) {
  return wide_detail::intersectLeafLaneByLane<kAnyHit, /*kWatertight=*/false>(
      bvh, firstPacket, packetCount, ray, search);
}

// The hit children of a node in the order to visit them, by entry distance (its low three
// bits replaced by the lane, so that keys differ): closest-hit queries nearest first, any-hit
// queries farthest first. byOrder[k] is the lane visited k-th; returns how many. (The order
// decides only how soon a query ends, never its answer: isCloserHit.)
// Farthest first for any hit: a shadow ray leaves a surface, and the children it enters
// first lie around its origin, which rarely blocks it. bunny-dragon's shadow rays visit 0.63
// leaves each, against 1.57 in lane order (the binary tree's depth-first order) and 1.59
// nearest first; ray_bench, 1 thread, against lane order: shadow rays on bunny-dragon 1.24x
// as fast, on the sphere 1.14x. (Embree's any-hit traversal takes the last lane first, which
// here visits 0.62 leaves: the lane order happens to run along these rays, which it need
// not on another scene; the distances do not depend on it.)
template <bool kAnyHit>
HWY_INLINE int visitOrder(const ChildLanes& box, uint8_t (&byOrder)[kWideLanes]) {
  const uint32_t hit = box.hit;
  if ((hit & (hit - 1u)) == 0) {
    byOrder[0] = uint8_t(std::countr_zero(hit));
    return 1;
  }
  auto key = [&](int i) {
    return (std::bit_cast<uint32_t>(box.enter[i]) & ~7u) | uint32_t(i);  // enter >= 0
  };
  const int first = std::countr_zero(hit);
  const uint32_t rest = hit & (hit - 1u);
  if ((rest & (rest - 1u)) == 0) {  // two: one comparison
    const int second = std::countr_zero(rest);
    const bool swap = kAnyHit ? key(second) > key(first) : key(second) < key(first);
    byOrder[0] = uint8_t(swap ? second : first);
    byOrder[1] = uint8_t(swap ? first : second);
    return 2;
  }
  // Three or more: each lane's rank is the number of hit lanes with smaller keys (any hit:
  // larger).
#if HWY_MAX_BYTES >= 32
  // All eight keys in one vector, each lane's rank from one comparison.
  const hn::RebindToSigned<DB> di;  // keys below 2^31: a signed comparison orders them
  const auto keys = hn::Or(hn::And(hn::BitCast(di, hn::LoadU(DB(), box.enter)), hn::Set(di, ~7)),
                           hn::Iota(di, 0));
  alignas(32) int32_t keyOf[kWideLanes];
  hn::Store(keys, di, keyOf);
  for (uint32_t lanes = hit; lanes != 0; lanes &= lanes - 1u) {
    const int i = std::countr_zero(lanes);
    const auto other = hn::Set(di, keyOf[i]);
    const int rank =
        std::popcount(laneBits(di, kAnyHit ? hn::Gt(keys, other) : hn::Lt(keys, other)) & hit);
    byOrder[rank] = uint8_t(i);
  }
#else
  uint32_t keyOf[kWideLanes];
  for (uint32_t lanes = hit; lanes != 0; lanes &= lanes - 1u) {
    keyOf[std::countr_zero(lanes)] = key(std::countr_zero(lanes));
  }
  for (uint32_t lanes = hit; lanes != 0; lanes &= lanes - 1u) {
    const int i = std::countr_zero(lanes);
    int rank = 0;
    for (uint32_t other = hit; other != 0; other &= other - 1u) {
      const uint32_t k = keyOf[std::countr_zero(other)];
      rank += (kAnyHit ? k > keyOf[i] : k < keyOf[i]) ? 1 : 0;
    }
    byOrder[rank] = uint8_t(i);
  }
#endif
  return std::popcount(hit);
}

// Asks for the memory of the children the ray enters, all at once, before the first is
// visited: their boxes or triangles are cache misses on large scenes, and the loads of the
// ones visited later then wait less or not at all (measured together with the area-driven
// collapse of wide_bvh.cpp: incoherent rays on the 1M-triangle scenes 14-30 % faster; two
// lines instead of four were 2-10 % slower). Four lines: an interior child's whole node; a
// leaf's first packet and a half.
HWY_INLINE void prefetchChildren(const WideBvh& bvh, const WideNode& node, uint32_t hit) {
  for (uint32_t rest = hit; rest != 0; rest &= rest - 1u) {
    const uint32_t c = node.child[std::countr_zero(rest)];
    const char* at = (c & kWideLeaf) ? reinterpret_cast<const char*>(&bvh.packets[c & ~kWideLeaf])
                                     : reinterpret_cast<const char*>(&bvh.nodes[c]);
    for (int line = 0; line < 4; ++line) __builtin_prefetch(at + 64 * line);
  }
}

// One loop for both query kinds, as in traverse.cpp, over references to nodes and leaves.
// The children that the ray enters go on the stack in visitOrder's order, the first on top,
// and the first is taken off at once; a lone child is visited without the stack. A child
// taken off the stack is skipped when its entry distance lies beyond the range, which has
// shrunk since its box was tested: a box test now would miss it.
// For a ray that enters the root's box (the caller has tested it).
template <bool kAnyHit, bool kWatertight>
bool traverseFromRoot(const WideBvh& bvh, const RayPrecomputed& r, float tMax, Hit& best,
                      const HitFilter* filter = nullptr) {
  const RayLanes lanes(r);
  struct Entry {
    uint32_t child, packetCount;
    float enter;
  };
  Entry stack[kWideStackSize];
  uint32_t stackSize = 0;
  HitSearch search(tMax, filter);
  float cull = tMax * kFarScale;  // entry distances beyond it: a box test would miss
  Entry next{0u, 0u, 0.0f};       // the root node (never on the stack: its entry unused)
  for (;;) {
    if (!(next.child & kWideLeaf)) {
      const WideNode& node = bvh.nodes[next.child];
      const ChildLanes box = intersectBoxes(node, lanes, search.range);
      if (box.hit != 0) {
        prefetchChildren(bvh, node, box.hit);
        uint8_t byOrder[kWideLanes];
        const int count = visitOrder<kAnyHit>(box, byOrder);
        // All but the first onto the stack, the last first; the first is next.
        for (int k = count - 1; k > 0; --k) {
          const int i = byOrder[k];
          stack[stackSize++] = Entry{node.child[i], node.packetCount[i], box.enter[i]};
        }
        const int i = byOrder[0];
        next = Entry{node.child[i], node.packetCount[i], box.enter[i]};
        continue;
      }
    } else {
      const uint32_t first = next.child & ~kWideLeaf;
      const bool hit =
          kWatertight
              ? intersectLeafWatertight<kAnyHit>(bvh, first, next.packetCount, lanes, search)
              : intersectLeafFast<kAnyHit>(bvh, first, next.packetCount, r, search);
      if (hit) {
        if constexpr (kAnyHit) {
          best = search.best;
          return true;
        }
        cull = search.range * kFarScale;
      }
    }
    // Take the next child off the stack.
    do {
      if (stackSize == 0) {
        best = search.best;
        return search.found;
      }
      next = stack[--stackSize];
    } while (!kAnyHit && next.enter > cull);
  }
}

// closestHit and anyHit (wide_bvh.h) after their first steps, for callers that take those
// steps for several rays at once (the lanes integrator): `ray` is RayPrecomputed of a ray
// that enters the root's box (intersectBox with rootMin, rootMax and tMax) and is not
// degenerate (no NaN or infinity in it, and a direction: wide_bvh.h; closestHit and anyHit
// take those elsewhere).
HWY_INLINE bool closestHitFromRoot(const WideBvh& bvh, const RayPrecomputed& ray, float tMax,
                                   Intersection test, Hit& hit, const HitFilter* filter = nullptr) {
  return test == Intersection::kWatertight
             ? traverseFromRoot<false, true>(bvh, ray, tMax, hit, filter)
             : traverseFromRoot<false, false>(bvh, ray, tMax, hit, filter);
}
HWY_INLINE bool anyHitFromRoot(const WideBvh& bvh, const RayPrecomputed& ray, float tMax,
                               Intersection test, const HitFilter* filter = nullptr) {
  Hit hit;
  return test == Intersection::kWatertight
             ? traverseFromRoot<true, true>(bvh, ray, tMax, hit, filter)
             : traverseFromRoot<true, false>(bvh, ray, tMax, hit, filter);
}

}  // namespace wide_traversal
}  // namespace HWY_NAMESPACE
}  // namespace pt
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
