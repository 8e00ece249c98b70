// The CPU reference's copy of the BVH for SIMD traversal: the binary tree collapsed into
// nodes of up to eight children whose boxes are tested together (each node opens the binary
// nodes below it, or splits a leaf of two packets or more over two lanes, whichever saves
// the most SAH cost first: buildWideBvh), and the leaves' triangles repacked four to a
// packet in the structure-of-arrays layout that the four-lane watertight test loads
// directly. The GPU keeps the binary tree (Bvh); this one is built from it, after it, for the
// CPU backend only.
//
// A query gives exactly the binary traversal's answer (traverse.h), not just an equally
// valid one: same hit distance, same triangle, same barycentrics, bit for bit, because
//  - the triangle and box tests perform the same float operations in the same order (no
//    fused multiply-add), lane by lane, with the same double-precision recomputation of an
//    edge function that comes out exactly 0;
//  - the closest hit is chosen by the rule of every traversal (isCloserHit in sampling.h:
//    smallest t, then the triangle listed first in the scene), which names the same hit in
//    any visiting order, and the ranges that boxes and triangles are tested against
//    (searchRange) never lose a hit the rule could still prefer. So a node's children are
//    visited nearest entry distance first, which is fastest here (the binary traversal's
//    order, which a binary node's early entry can decide while its nearer child is far,
//    visited 6.15 nodes per ray on the bunny box's camera and bounce rays against 5.61),
//    and the boxes of the binary levels in between go untested;
//  - a ray with a NaN or an infinity in it, or without a direction, for which the vector
//    shortcuts are not the scalar operations, takes traverse.cpp's loop itself over this
//    tree's boxes (wide_traverse.cpp). (So does nothing else: for the rest, every distance
//    computed is a number, as long as coordinates stay far from overflowing, below about
//    1e18.)
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/traverse.h"

namespace pt {

inline constexpr int kWideLanes = 8;    // children per node
inline constexpr int kPacketLanes = 4;  // triangles per packet

// Eight children's boxes and references. An interior child is the index of its WideNode; a
// leaf child is kWideLeaf | the index of its first packet, with its packet count alongside.
// The children in use are the first lanes, in the binary tree's depth-first order; where a
// node has fewer than eight (every binary node below it is a leaf), the rest are unused:
// kWideEmpty, with an inverted box (lo = +inf, hi = -inf) that no ray enters.
// (Default construction leaves the fields unset, also in a vector's resize: buildWideBvh
// writes every field of every node and packet, in parallel, and a value-initialising resize
// would first zero the arrays on one thread.)
struct alignas(64) WideNode {
  float bounds[6][kWideLanes];       // lo.x, lo.y, lo.z, hi.x, hi.y, hi.z of each child
  uint32_t child[kWideLanes];        // see above
  uint32_t packetCount[kWideLanes];  // leaf: its packets (>= 1); else 0
  WideNode() {}                      // (see above)
};                                   // 256 bytes: four cache lines
inline constexpr uint32_t kWideLeaf = 0x80000000u;
inline constexpr uint32_t kWideEmpty = 0xFFFFFFFFu;

// Up to four consecutive triangles of one leaf, vertex coordinates by lane. Lanes past
// `count` repeat the last triangle (so every lane computes on real coordinates) and are
// never reported.
struct alignas(16) TrianglePacket {
  float v[3][3][kPacketLanes];       // v[vertex][axis][lane]
  uint32_t primitive[kPacketLanes];  // each lane's Triangle::primitive (isCloserHit's ties)
  uint32_t first;                    // Bvh::triangles index of lane 0; lane i holds first + i
  uint32_t count;                    // 1 to 4 lanes in use

  TrianglePacket() {}  // (fields left unset: see WideNode)

  Triangle triangle(uint32_t lane) const {
    Triangle tri{};
    tri.v0 = vec3(v[0][0][lane], v[0][1][lane], v[0][2][lane]);
    tri.v1 = vec3(v[1][0][lane], v[1][1][lane], v[1][2][lane]);
    tri.v2 = vec3(v[2][0][lane], v[2][1][lane], v[2][2][lane]);
    return tri;
  }
};  // 176 bytes

// How a wide node's lanes came out of the binary tree (WideBvh::shapes): the number of lanes
// in use (bits 24 to 27), and for each binary node in between, in depth-first order (the
// node's own binary node first), how many of its lanes its left child covers (3 bits each).
// A binary node k covering lanes [first, first + size), size >= 2, has its left child over
// split(k) lanes from first, with index k + 1 if that is a range of two or more, and its
// right child over the rest, with index k + split(k). Where leafSplit(k) (bit 32 + k), k is
// not an interior node but a leaf whose triangles the collapse split over its two lanes
// (their packets consecutive, in the leaf's order; its box the union of theirs).
namespace wide_shape {
constexpr uint64_t make(int lanes) {
  return uint64_t(lanes) << 24;
}
constexpr uint64_t withSplit(uint64_t shape, int k, int leftLanes) {
  return shape | uint64_t(leftLanes) << (3 * k);
}
constexpr uint64_t withLeafSplit(uint64_t shape, int k) {
  return shape | uint64_t(1) << (32 + k);
}
constexpr int lanes(uint64_t shape) {
  return int(shape >> 24 & 15u);
}
constexpr int split(uint64_t shape, int k) {
  return int(shape >> (3 * k) & 7u);
}
constexpr bool leafSplit(uint64_t shape, int k) {
  return (shape >> (32 + k) & 1u) != 0;
}
}  // namespace wide_shape

struct WideBvh {
  std::vector<WideNode> nodes;   // nodes[0] is the root: the binary root's descendants
  std::vector<uint64_t> shapes;  // per node: wide_shape (only degenerate rays read it)
  std::vector<TrianglePacket> packets;
  vec3 rootMin{0.0f}, rootMax{0.0f};  // the binary root's box, tested first as it is there
  int maxDepth = 0;                   // deepest wide node below the root (root = 0)
  double buildSeconds = 0.0;          // of buildWideBvh (after the binary build)
};

// Collapses a built binary BVH. The result refers to bvh.triangles by index (Hit::triangle)
// but holds copies of the vertices, so it does not depend on bvh's lifetime.
// `threads`: workers for the collapse (0: one per hardware thread); the tree is the same for
// any number.
WideBvh buildWideBvh(const Bvh& bvh, int threads = 0);

namespace wide_detail {

// What a query's per-target code returns (wide_traverse.cpp): the ray was degenerate (see
// below: the caller traces it with the binary loop), missed, or hit.
enum Outcome : int { kDegenerate = -1, kMissed = 0, kHit = 1 };

// A ray that the vector code does not take (see above): an infinity or a NaN in it (x - x is
// 0 for a number, NaN otherwise), or no direction.
inline bool degenerateRay(const Ray& ray) {
  const vec3 o = ray.origin, d = ray.direction;
  const bool finite =
      (o.x - o.x) + (o.y - o.y) + (o.z - o.z) + (d.x - d.x) + (d.y - d.y) + (d.z - d.z) == 0.0f;
  return !finite || (std::fabs(d.x) < kMinDirection && std::fabs(d.y) < kMinDirection &&
                     std::fabs(d.z) < kMinDirection);
}

// The triangles of a leaf (packetCount packets from firstPacket) one at a time, as
// traverse.cpp's leaf loop tests them: for Highway's portable target, for Moller-Trumbore,
// and for the rays the vector code does not take. True if one of them became the closest hit
// (any hit: was hit).
template <bool kAnyHit, bool kWatertight>
bool intersectLeafLaneByLane(const WideBvh& bvh, uint32_t firstPacket, uint32_t packetCount,
                             const RayPrecomputed& ray, HitSearch& search) {
  bool found = false;
  for (uint32_t p = firstPacket; p < firstPacket + packetCount; ++p) {
    const TrianglePacket& packet = bvh.packets[p];
    for (uint32_t i = 0; i < packet.count; ++i) {
      Hit hit;
      const bool hitTriangle =
          kWatertight ? intersectTriangle(ray, packet.triangle(i), search.range, hit)
                      : intersectTriangleFast(ray, packet.triangle(i), search.range, hit);
      if (hitTriangle && search.offer(hit, packet.first + i, packet.primitive[i])) {
        if constexpr (kAnyHit) return true;
        found = true;
      }
    }
  }
  return found;
}

}  // namespace wide_detail

// The same queries as on the binary Bvh (traverse.h), with the same answers. Boxes are
// tested eight at a time and triangles four at a time, with x86-64 vector instructions
// chosen at run time (AVX-512 or AVX2, else SSE4 or SSSE3 in halves, else Highway's
// portable code); Moller-Trumbore runs lane by lane.
std::optional<Hit> closestHit(const WideBvh& bvh, const Ray& ray, float tMax = INFINITY,
                              Intersection test = Intersection::kWatertight,
                              const HitFilter* filter = nullptr);
bool anyHit(const WideBvh& bvh, const Ray& ray, float tMax,
            Intersection test = Intersection::kWatertight, const HitFilter* filter = nullptr);

// (Code compiled per Highway target can call the queries after their first steps, without
// dispatching: wide_traversal::closestHitFromRoot and anyHitFromRoot in wide_traverse-inl.h.)

// The instruction sets (Highway target bits, best first) that the queries above are compiled
// for and this CPU runs; the queries use the first. For tests, which make them use each in
// turn with hwy::SetSupportedTargetsForTest.
std::vector<int64_t> wideTraversalTargets();

}  // namespace pt
