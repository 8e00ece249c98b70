// Traversal of the wide BVH (wide_bvh.h), dispatched at run time to the best x86 instruction
// set that the CPU has (wide_traverse-inl.h holds the per-target code; foreach_target.h
// includes this file once for each of AVX-512, AVX2, SSE4, SSSE3 and Highway's portable
// fallback), so that a build for baseline x86-64 still runs vector code where the CPU has it.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

// AVX-512 (Highway's AVX3) runs the same eight- and four-lane code with 32 vector registers
// and mask registers, and the loop spills less: incoherent rays on the 1M-triangle scenes
// trace 5-8 % faster than with AVX2 (Xeon, Sapphire Rapids). AVX3_DL would add nothing used
// here. (integrator_lanes.cpp, which includes the traversal too, is compiled for the same
// targets.)
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_AVX3_DL)
#endif
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "bvh/wide_traverse.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "bvh/wide_bvh.h"
#include "bvh/wide_traverse-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pt {
namespace HWY_NAMESPACE {
using wide_traversal::traverseFromRoot;
using namespace wide_detail;  // Outcome

template <bool kAnyHit, bool kWatertight>
int traverse(const WideBvh& bvh, const Ray& ray, float tMax, const HitFilter* filter, Hit& best) {
  RayPrecomputed r;
  if (!wide_traversal::precomputeRay(ray, r)) return kDegenerate;
  // traverse.cpp tests the root's box first; that test is left to the root node's: a ray that
  // misses the root's box misses every box inside it (the slab test's distances are monotonic
  // in the planes, so a box inside gives a later entry and an earlier exit).
  return traverseFromRoot<kAnyHit, kWatertight>(bvh, r, tMax, best, filter) ? kHit : kMissed;
}

int closestHitWatertight(const WideBvh& bvh, const Ray& ray, float tMax, const HitFilter* filter,
                         Hit& hit) {
  return traverse</*kAnyHit=*/false, true>(bvh, ray, tMax, filter, hit);
}
int closestHitFast(const WideBvh& bvh, const Ray& ray, float tMax, const HitFilter* filter,
                   Hit& hit) {
  return traverse</*kAnyHit=*/false, false>(bvh, ray, tMax, filter, hit);
}
int anyHitWatertight(const WideBvh& bvh, const Ray& ray, float tMax, const HitFilter* filter,
                     Hit& hit) {
  return traverse</*kAnyHit=*/true, true>(bvh, ray, tMax, filter, hit);
}
int anyHitFast(const WideBvh& bvh, const Ray& ray, float tMax, const HitFilter* filter, Hit& hit) {
  return traverse</*kAnyHit=*/true, false>(bvh, ray, tMax, filter, hit);
}

}  // namespace HWY_NAMESPACE
}  // namespace pt
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace pt {

// The traversal above relies on every distance it computes being a number: the near plane
// standing for min(t0, t1), the entry distances ordering the visits, the boxes of the binary
// nodes in between left untested. A ray with a NaN or an infinity
// in it, or without a direction (|d| below kMinDirection on every axis: its sheared
// coordinates are NaN, and every triangle takes it at t = NaN), breaks that; for those
// this runs traverse.cpp's loop itself over the wide tree. A binary node is a range of one
// wide node's consecutive lanes (WideBvh::shapes says which), and its box the union of its
// lanes' boxes, which is the binary node's box exactly (every parent's box is the union of
// its children's). (The lanes integrator tests the same in vector lanes:
// integrator_lanes.cpp, setUpRays.)
using namespace wide_detail;  // Outcome

namespace {

// Lanes [first, first + size) of a wide node; `split` is the binary node's index in the
// node's wide_shape when size >= 2. A leaf is one leaf lane, or two that the collapse split
// it into (wide_shape::leafSplit).
struct BinaryNode {
  uint32_t node;  // the wide node
  int first, size, split;
  bool isLeaf(const WideBvh& bvh) const {
    return size == 1 ? (bvh.nodes[node].child[first] & kWideLeaf) != 0
                     : size == 2 && wide_shape::leafSplit(bvh.shapes[node], split);
  }
};

// A lane that is an interior node stands for that node's own range of lanes.
BinaryNode resolve(const WideBvh& bvh, BinaryNode b) {
  if (b.size == 1 && !(bvh.nodes[b.node].child[b.first] & kWideLeaf)) {
    const uint32_t child = bvh.nodes[b.node].child[b.first];
    return BinaryNode{child, 0, wide_shape::lanes(bvh.shapes[child]), 0};
  }
  return b;
}

bool intersectBinaryNode(const WideBvh& bvh, const RayPrecomputed& r, BinaryNode b, float tMax,
                         float& tNear) {
  const WideNode& n = bvh.nodes[b.node];
  vec3 lo(INFINITY), hi(-INFINITY);
  for (int i = b.first; i < b.first + b.size; ++i) {
    lo = min(lo, vec3(n.bounds[0][i], n.bounds[1][i], n.bounds[2][i]));
    hi = max(hi, vec3(n.bounds[3][i], n.bounds[4][i], n.bounds[5][i]));
  }
  return intersectBox(r, lo, hi, tMax, tNear);
}

template <bool kAnyHit>
bool traverseAsBinary(const WideBvh& bvh, const Ray& ray, float tMax, Intersection test,
                      const HitFilter* filter, Hit& best) {
  const RayPrecomputed r(ray);
  float tNear = 0.0f;
  if (!intersectBox(r, bvh.rootMin, bvh.rootMax, tMax, tNear)) return false;
  BinaryNode stack[kBvhStackSize];
  uint32_t stackSize = 0;
  BinaryNode node{0, 0, wide_shape::lanes(bvh.shapes[0]), 0};
  HitSearch search(tMax, filter);
  for (;;) {
    if (node.isLeaf(bvh)) {
      // (A split leaf's packets are consecutive: its lanes' together are the leaf's.)
      const WideNode& wide = bvh.nodes[node.node];
      const uint32_t first = wide.child[node.first] & ~kWideLeaf;
      uint32_t count = 0;
      for (int i = node.first; i < node.first + node.size; ++i) count += wide.packetCount[i];
      const bool hit =
          test == Intersection::kWatertight
              ? wide_detail::intersectLeafLaneByLane<kAnyHit, true>(bvh, first, count, r, search)
              : wide_detail::intersectLeafLaneByLane<kAnyHit, false>(bvh, first, count, r, search);
      if (hit && kAnyHit) return true;
    } else {
      const int half = wide_shape::split(bvh.shapes[node.node], node.split);
      const BinaryNode left = resolve(bvh, BinaryNode{node.node, node.first, half, node.split + 1});
      const BinaryNode right = resolve(
          bvh, BinaryNode{node.node, node.first + half, node.size - half, node.split + half});
      float tLeft = 0.0f, tRight = 0.0f;
      const bool hitLeft = intersectBinaryNode(bvh, r, left, search.range, tLeft);
      const bool hitRight = intersectBinaryNode(bvh, r, right, search.range, tRight);
      if (hitLeft && hitRight) {
        const bool leftFirst = tLeft <= tRight;
        stack[stackSize++] = leftFirst ? right : left;
        node = leftFirst ? left : right;
        continue;
      }
      if (hitLeft || hitRight) {
        node = hitLeft ? left : right;
        continue;
      }
    }
    if (stackSize == 0) break;
    node = stack[--stackSize];
  }
  best = search.best;
  return search.found;
}

}  // namespace

HWY_EXPORT(closestHitWatertight);
HWY_EXPORT(closestHitFast);
HWY_EXPORT(anyHitWatertight);
HWY_EXPORT(anyHitFast);

std::optional<Hit> closestHit(const WideBvh& bvh, const Ray& ray, float tMax, Intersection test,
                              const HitFilter* filter) {
  Hit hit;
  const int outcome = test == Intersection::kWatertight
                          ? HWY_DYNAMIC_DISPATCH(closestHitWatertight)(bvh, ray, tMax, filter, hit)
                          : HWY_DYNAMIC_DISPATCH(closestHitFast)(bvh, ray, tMax, filter, hit);
  const bool found = outcome == kDegenerate
                         ? traverseAsBinary</*kAnyHit=*/false>(bvh, ray, tMax, test, filter, hit)
                         : outcome == kHit;
  if (found) return hit;
  return std::nullopt;
}

bool anyHit(const WideBvh& bvh, const Ray& ray, float tMax, Intersection test,
            const HitFilter* filter) {
  Hit hit;
  const int outcome = test == Intersection::kWatertight
                          ? HWY_DYNAMIC_DISPATCH(anyHitWatertight)(bvh, ray, tMax, filter, hit)
                          : HWY_DYNAMIC_DISPATCH(anyHitFast)(bvh, ray, tMax, filter, hit);
  return outcome == kDegenerate
             ? traverseAsBinary</*kAnyHit=*/true>(bvh, ray, tMax, test, filter, hit)
             : outcome == kHit;
}

std::vector<int64_t> wideTraversalTargets() {
  return hwy::SupportedAndGeneratedTargets();
}

}  // namespace pt
#endif  // HWY_ONCE
