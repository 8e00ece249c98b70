// Pieces shared by the BVH builders (bvh.cpp, bvh_sah.cpp, bvh_ploc.cpp); not part of the
// interface.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/workers.h"
#include "common/check.h"

namespace pt {

struct Bounds {
  vec3 lo{INFINITY};
  vec3 hi{-INFINITY};
  void grow(vec3 p) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
  void grow(const Bounds& b) {
    lo = min(lo, b.lo);
    hi = max(hi, b.hi);
  }
  float surfaceArea() const {
    const vec3 d = max(hi - lo, vec3(0.0f));
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

inline Bounds triangleBounds(const Triangle& t) {
  Bounds b;
  b.grow(t.v0);
  b.grow(t.v1);
  b.grow(t.v2);
  return b;
}

// Smallest number of levels below a node that a balanced split of `count` triangles needs.
inline int balancedLevels(size_t count, size_t leafSize) {
  int levels = 0;
  for (size_t leaves = (count + leafSize - 1) / leafSize; leaves > 1; leaves = (leaves + 1) / 2)
    ++levels;
  return levels;
}

// Emits the subtree of triangles[first, last) depth first, appending to `nodes` (child
// indices are indices into `nodes`). A range of at most leafSize triangles becomes a leaf;
// a longer one is cut at split(first, last, depth), which must lie strictly inside it.
template <typename Split>
class RangeEmitter {
 public:
  RangeEmitter(const Triangle* triangles, size_t leafSize, const Split& split,
               std::vector<BvhNode>& nodes)
      : triangles_(triangles), leafSize_(leafSize), split_(split), nodes_(nodes) {}

  // Returns the index of the subtree's root.
  uint32_t emit(size_t first, size_t last, int depth) {
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.push_back(BvhNode{});
    maxDepth_ = std::max(maxDepth_, depth);
    Bounds bounds;
    const size_t count = last - first;
    if (count <= leafSize_) {
      for (size_t i = first; i < last; ++i) bounds.grow(triangleBounds(triangles_[i]));
      nodes_[index] = BvhNode{bounds.lo, uint32_t(first), bounds.hi, uint32_t(count)};
      return index;
    }
    const size_t split = split_(first, last, depth);
    PT_CHECK(first < split && split < last);
    const uint32_t left = emit(first, split, depth + 1);
    const uint32_t right = emit(split, last, depth + 1);
    PT_CHECK(left == index + 1, "left child must follow its parent");
    bounds.grow(Bounds{nodes_[left].boundsMin, nodes_[left].boundsMax});
    bounds.grow(Bounds{nodes_[right].boundsMin, nodes_[right].boundsMax});
    nodes_[index] = BvhNode{bounds.lo, right, bounds.hi, 0u};
    return index;
  }

  int maxDepth() const { return maxDepth_; }

 private:
  const Triangle* triangles_;
  size_t leafSize_;
  const Split& split_;
  std::vector<BvhNode>& nodes_;
  int maxDepth_ = 0;
};

// Triangles sorted by the 63-bit Morton code of their centroid (normalised to the centroids'
// bounding box) shifted right by skipBits (a multiple of 3 drops whole levels of the grid),
// stably: equal keys keep load order.
struct MortonOrder {
  std::unique_ptr<uint64_t[]> codes;  // sorted by code >> skipBits
  std::unique_ptr<uint32_t[]> order;  // order[i]: index of the triangle with the i-th code
};
MortonOrder sortByMorton(const std::vector<Triangle>& triangles, int skipBits, Workers& workers);

// Bvh::sahCost of a finished tree; the same for any number of workers (the partial sums are
// over fixed chunks, added in order).
double sahCostOf(const std::vector<BvhNode>& nodes, Workers& workers);

// The builders behind buildBvh; they fill everything but buildSeconds and sahCost. A
// depthLimit below kBvhStackSize (at least balancedLevels(triangles, leafSize)) is for tests
// of PLOC's fallback for trees deeper than the traversal stack.
Bvh buildBinnedSahBvh(std::vector<Triangle> triangles, size_t leafSize);
Bvh buildPlocBvh(std::vector<Triangle> triangles, size_t leafSize, Workers& workers,
                 int depthLimit = int(kBvhStackSize));

}  // namespace pt
