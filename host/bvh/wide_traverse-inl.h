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

// The ray's constants, broadcast to every lane, and where the rows it reads lie.
struct RayLanes {
  explicit RayLanes(const RayPrecomputed& r) {
    const int k[3] = {r.kx, r.ky, r.kz};
    for (int axis = 0; axis < 3; ++axis) {
      origin[axis] = hn::Set(DB(), r.origin[axis]);
      invDirection[axis] = hn::Set(DB(), r.invDirection[axis]);
      // The slab distances min(t0, t1) and max(t0, t1) are the near and the far plane's: for
      // a positive 1/d the lower plane's distance is the smaller (rounding is monotonic),
      // for a negative one the upper's. 1/d is never 0; its sign is the direction's.
      const bool positive = r.invDirection[axis] > 0.0f;
      nearRow[axis] = kWideLanes * (positive ? axis : axis + 3);
      farRow[axis] = kWideLanes * (positive ? axis + 3 : axis);
      shearRow[axis] = kPacketLanes * k[axis];
      shearOrigin[axis] = hn::Set(D(), r.origin[k[axis]]);
    }
    sx = hn::Set(D(), r.sx);
    sy = hn::Set(D(), r.sy);
    sz = hn::Set(D(), r.sz);
    farScale = hn::Set(DB(), kFarScale);
  }
  VB origin[3], invDirection[3];
  size_t nearRow[3], farRow[3];  // offsets into WideNode::bounds, in floats
  size_t shearRow[3];            // offsets of axes kx, ky, kz into a vertex of a packet
  V shearOrigin[3];              // origin[kx], origin[ky], origin[kz]
  V sx, sy, sz;
  VB farScale;
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
      tMin[axis] = hn::Mul(hn::Sub(hn::Load(d, bounds + ray.nearRow[axis]), ray.origin[axis]),
                           ray.invDirection[axis]);
      tFar[axis] = hn::Mul(hn::Sub(hn::Load(d, bounds + ray.farRow[axis]), ray.origin[axis]),
                           ray.invDirection[axis]);
    }
    const VB enter = hn::Max(hn::Max(tMin[0], tMin[1]), hn::Max(tMin[2], zero));
    const VB exit = hn::Mul(hn::Min(hn::Min(tFar[0], tFar[1]), hn::Min(tFar[2], hn::Set(d, tMax))),
                            ray.farScale);
    box.hit |= laneBits(d, hn::Le(enter, exit)) << (p * kBoxPartLanes);
    hn::StoreU(enter, d, box.enter + p * kBoxPartLanes);
  }
  return box;
}

// Recomputes, in double precision as intersectTriangle does, the edge functions of the
// lanes where one came out exactly 0.
HWY_NOINLINE inline void recomputeEdgesInDouble(uint32_t lanes, V ax, V ay, V bx, V by, V cx, V cy,
                                                V& u, V& v, V& w) {
  const D d;
  alignas(16) float a[2][kPacketLanes], b[2][kPacketLanes], c[2][kPacketLanes];
  alignas(16) float uu[kPacketLanes], vv[kPacketLanes], ww[kPacketLanes];
  hn::Store(ax, d, a[0]);
  hn::Store(ay, d, a[1]);
  hn::Store(bx, d, b[0]);
  hn::Store(by, d, b[1]);
  hn::Store(cx, d, c[0]);
  hn::Store(cy, d, c[1]);
  hn::Store(u, d, uu);
  hn::Store(v, d, vv);
  hn::Store(w, d, ww);
  for (int i = 0; i < kPacketLanes; ++i) {
    if (!(lanes >> i & 1u)) continue;
    uu[i] = float(double(c[0][i]) * double(b[1][i]) - double(c[1][i]) * double(b[0][i]));
    vv[i] = float(double(a[0][i]) * double(c[1][i]) - double(a[1][i]) * double(c[0][i]));
    ww[i] = float(double(b[0][i]) * double(a[1][i]) - double(b[1][i]) * double(a[0][i]));
  }
  u = hn::Load(d, uu);
  v = hn::Load(d, vv);
  w = hn::Load(d, ww);
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
    const float* v0 = packet.v[0][0];
    const float* v1 = packet.v[1][0];
    const float* v2 = packet.v[2][0];
    const V akz = hn::Sub(hn::Load(d, v0 + ray.shearRow[2]), ray.shearOrigin[2]);
    const V bkz = hn::Sub(hn::Load(d, v1 + ray.shearRow[2]), ray.shearOrigin[2]);
    const V ckz = hn::Sub(hn::Load(d, v2 + ray.shearRow[2]), ray.shearOrigin[2]);
    const V ax = hn::Sub(hn::Sub(hn::Load(d, v0 + ray.shearRow[0]), ray.shearOrigin[0]),
                         hn::Mul(ray.sx, akz));
    const V ay = hn::Sub(hn::Sub(hn::Load(d, v0 + ray.shearRow[1]), ray.shearOrigin[1]),
                         hn::Mul(ray.sy, akz));
    const V bx = hn::Sub(hn::Sub(hn::Load(d, v1 + ray.shearRow[0]), ray.shearOrigin[0]),
                         hn::Mul(ray.sx, bkz));
    const V by = hn::Sub(hn::Sub(hn::Load(d, v1 + ray.shearRow[1]), ray.shearOrigin[1]),
                         hn::Mul(ray.sy, bkz));
    const V cx = hn::Sub(hn::Sub(hn::Load(d, v2 + ray.shearRow[0]), ray.shearOrigin[0]),
                         hn::Mul(ray.sx, ckz));
    const V cy = hn::Sub(hn::Sub(hn::Load(d, v2 + ray.shearRow[1]), ray.shearOrigin[1]),
                         hn::Mul(ray.sy, ckz));
    // Scaled barycentrics: 2D edge functions of the projected edges against the origin.
    V u = hn::Sub(hn::Mul(cx, by), hn::Mul(cy, bx));
    V v = hn::Sub(hn::Mul(ax, cy), hn::Mul(ay, cx));
    V w = hn::Sub(hn::Mul(bx, ay), hn::Mul(by, ax));
    const uint32_t zeroEdge =
        laneBits(d, hn::Or(hn::Or(hn::Eq(u, zero), hn::Eq(v, zero)), hn::Eq(w, zero)));
    if (zeroEdge != 0) recomputeEdgesInDouble(zeroEdge, ax, ay, bx, by, cx, cy, u, v, w);
    // Rejections, as intersectTriangle makes them: mixed signs, det == 0, t out of range.
    const M negative = hn::Or(hn::Or(hn::Lt(u, zero), hn::Lt(v, zero)), hn::Lt(w, zero));
    const M positive = hn::Or(hn::Or(hn::Gt(u, zero), hn::Gt(v, zero)), hn::Gt(w, zero));
    const V det = hn::Add(hn::Add(u, v), w);
    // Scaled hit distance; compared against the range scaled by det.
    const V az = hn::Mul(ray.sz, akz);
    const V bz = hn::Mul(ray.sz, bkz);
    const V cz = hn::Mul(ray.sz, ckz);
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

// The hit children of a node in the order to visit them: closest-hit queries take them by
// entry distance, nearest first (its low three bits replaced by the lane, so that keys differ
// and equal distances go in lane order), any-hit queries, which stop at the first hit
// wherever it is, as they come. byOrder[k] is the lane visited k-th; returns how many.
template <bool kAnyHit>
HWY_INLINE int visitOrder(const ChildLanes& box, uint8_t (&byOrder)[kWideLanes]) {
  int count = 0;
  if (kAnyHit || (box.hit & (box.hit - 1u)) == 0) {
    for (uint32_t rest = box.hit; rest != 0; rest &= rest - 1u) {
      byOrder[count++] = uint8_t(std::countr_zero(rest));
    }
    return count;
  }
  uint32_t key[kWideLanes];
  for (uint32_t rest = box.hit; rest != 0; rest &= rest - 1u) {
    const int i = std::countr_zero(rest);
    key[i] = (std::bit_cast<uint32_t>(box.enter[i]) & ~7u) | uint32_t(i);  // enter >= 0
    ++count;
  }
  for (uint32_t rest = box.hit; rest != 0; rest &= rest - 1u) {
    const int i = std::countr_zero(rest);
    int rank = 0;
    for (uint32_t other = box.hit; other != 0; other &= other - 1u) {
      rank += key[std::countr_zero(other)] < key[i] ? 1 : 0;
    }
    byOrder[rank] = uint8_t(i);
  }
  return count;
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
                                   Intersection test, Hit& hit) {
  return test == Intersection::kWatertight ? traverseFromRoot<false, true>(bvh, ray, tMax, hit)
                                           : traverseFromRoot<false, false>(bvh, ray, tMax, hit);
}
HWY_INLINE bool anyHitFromRoot(const WideBvh& bvh, const RayPrecomputed& ray, float tMax,
                               Intersection test) {
  Hit hit;
  return test == Intersection::kWatertight ? traverseFromRoot<true, true>(bvh, ray, tMax, hit)
                                           : traverseFromRoot<true, false>(bvh, ray, tMax, hit);
}

}  // namespace wide_traversal
}  // namespace HWY_NAMESPACE
}  // namespace pt
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
