// Binned-SAH BVH builder (Wald 2007, "On fast construction of SAH-based bounding volume
// hierarchies"): top-down, each node's triangles binned into 16 slabs of the widest
// centroid axis, split at the bin boundary of least surface-area cost. Emits the same
// depth-first 32-byte nodes as the LBVH builder, so both backends trace it unchanged; it
// exists to measure what the faster LBVH build costs in trace time.
#include <algorithm>
#include <array>

#include "bvh/bvh_build.h"
#include "common/check.h"

namespace pt {
namespace {

constexpr int kBins = 16;

class SahBuilder {
 public:
  SahBuilder(const std::vector<Triangle>& triangles, size_t leafSize, std::vector<BvhNode>& nodes)
      : leafSize_(leafSize), nodes_(nodes) {
    order_.resize(triangles.size());
    centroids_.resize(triangles.size());
    boxes_.resize(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i) {
      const Triangle& t = triangles[i];
      order_[i] = uint32_t(i);
      centroids_[i] = (t.v0 + t.v1 + t.v2) * (1.0f / 3.0f);
      boxes_[i].grow(t.v0);
      boxes_[i].grow(t.v1);
      boxes_[i].grow(t.v2);
    }
  }

  // Emits the subtree of order_[first, last) depth first and returns its root's index.
  uint32_t emit(size_t first, size_t last, int depth) {
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.push_back(BvhNode{});
    maxDepth_ = std::max(maxDepth_, depth);
    Bounds bounds, centroidBounds;
    for (size_t i = first; i < last; ++i) {
      bounds.grow(boxes_[order_[i]]);
      centroidBounds.grow(centroids_[order_[i]]);
    }
    const size_t count = last - first;
    if (count <= leafSize_) {
      nodes_[index] = BvhNode{bounds.lo, uint32_t(first), bounds.hi, uint32_t(count)};
      return index;
    }
    const size_t split = chooseSplit(first, last, depth, centroidBounds);
    PT_CHECK(first < split && split < last);
    const uint32_t left = emit(first, split, depth + 1);
    const uint32_t right = emit(split, last, depth + 1);
    PT_CHECK(left == index + 1, "left child must follow its parent");
    nodes_[index] = BvhNode{bounds.lo, right, bounds.hi, 0u};
    return index;
  }

  const std::vector<uint32_t>& order() const { return order_; }
  int maxDepth() const { return maxDepth_; }

 private:
  size_t chooseSplit(size_t first, size_t last, int depth, const Bounds& centroidBounds) {
    const vec3 extent = centroidBounds.hi - centroidBounds.lo;
    const int axis =
        extent.x > extent.y ? (extent.x > extent.z ? 0 : 2) : (extent.y > extent.z ? 1 : 2);
    const size_t middle = first + (last - first) / 2;
    auto medianSplit = [&]() {
      std::nth_element(order_.begin() + ptrdiff_t(first), order_.begin() + ptrdiff_t(middle),
                       order_.begin() + ptrdiff_t(last), [&](uint32_t a, uint32_t b) {
                         return centroids_[a][axis] < centroids_[b][axis];
                       });
      return middle;
    };
    // As in the LBVH: never deeper than the traversal stack; coincident centroids halve.
    if (depth + 1 + balancedLevels(last - first, leafSize_) >= int(kBvhStackSize)) {
      return medianSplit();
    }
    if (!(extent[axis] > 0.0f)) return medianSplit();

    // Bin the centroids, then sweep the bin boundaries for the least
    // area(left) * count(left) + area(right) * count(right).
    const float scale = float(kBins) / extent[axis];
    auto binOf = [&](uint32_t t) {
      return std::min(int((centroids_[t][axis] - centroidBounds.lo[axis]) * scale), kBins - 1);
    };
    std::array<Bounds, kBins> binBounds;
    std::array<size_t, kBins> binCount{};
    for (size_t i = first; i < last; ++i) {
      const int b = binOf(order_[i]);
      binBounds[b].grow(boxes_[order_[i]]);
      binCount[b]++;
    }
    std::array<float, kBins> rightCost{};  // cost of bins [b, kBins) as the right side
    Bounds acc;
    size_t n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(binBounds[b]);
      n += binCount[b];
      rightCost[b] = n ? acc.surfaceArea() * float(n) : 0.0f;
    }
    float bestCost = INFINITY;
    int bestBin = -1;
    acc = Bounds{};
    n = 0;
    for (int b = 1; b < kBins; ++b) {  // split before bin b
      acc.grow(binBounds[b - 1]);
      n += binCount[b - 1];
      if (n == 0 || n == last - first) continue;
      const float cost = acc.surfaceArea() * float(n) + rightCost[b];
      if (cost < bestCost) bestCost = cost, bestBin = b;
    }
    if (bestBin < 0) return medianSplit();
    const auto mid =
        std::partition(order_.begin() + ptrdiff_t(first), order_.begin() + ptrdiff_t(last),
                       [&](uint32_t t) { return binOf(t) < bestBin; });
    return size_t(mid - order_.begin());
  }

  size_t leafSize_;
  std::vector<BvhNode>& nodes_;
  std::vector<uint32_t> order_;
  std::vector<vec3> centroids_;
  std::vector<Bounds> boxes_;
  int maxDepth_ = 0;
};

}  // namespace

Bvh buildBinnedSahBvh(std::vector<Triangle> triangles, size_t leafSize) {
  Bvh bvh;
  bvh.nodes.reserve(2 * triangles.size());
  SahBuilder builder(triangles, leafSize, bvh.nodes);
  builder.emit(0, triangles.size(), 0);
  bvh.maxDepth = builder.maxDepth();
  PT_CHECK(bvh.maxDepth <= int(kBvhStackSize));
  bvh.triangles.resize(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) bvh.triangles[i] = triangles[builder.order()[i]];
  bvh.nodes.shrink_to_fit();
  return bvh;
}

}  // namespace pt
