// LBVH construction. Why 63-bit codes: with 21 bits per axis a scanned mesh of a million
// triangles inside a large room still gets distinct codes for almost all centroids, where
// 30-bit codes (1024 cells per axis) put many small triangles in one cell and leave their
// order, and thus the tree, to the midpoint fallback.
#include "bvh/bvh.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <utility>

#include "bvh/bvh_build.h"
#include "common/check.h"

namespace pt {
namespace {

// Spreads the low 21 bits of x so that bit i moves to bit 3i, two zero bits after each:
//   x   = ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- dcba
//   out = ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- d--c --b- -a
// (shown for the low four bits). Each step moves the upper half of every group of bits
// left by 32, 16, 8, 4 and 2 places and masks off what is left behind.
uint64_t spreadBits3(uint64_t x) {
  x &= 0x1fffffull;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// Stable LSD radix sort of (code, index) pairs by code, 11 bits per pass (6 passes cover 63
// bits). Stable, so equal codes keep load order and the build is deterministic.
void radixSort(std::vector<uint64_t>& codes, std::vector<uint32_t>& index) {
  constexpr int kBits = 11;
  constexpr size_t kBuckets = size_t(1) << kBits;
  const size_t n = codes.size();
  std::vector<uint64_t> codesTmp(n);
  std::vector<uint32_t> indexTmp(n);
  std::vector<size_t> offsets(kBuckets);
  for (int shift = 0; shift < 64; shift += kBits) {
    std::fill(offsets.begin(), offsets.end(), 0);
    for (uint64_t c : codes) offsets[(c >> shift) & (kBuckets - 1)]++;
    size_t sum = 0;
    for (size_t& o : offsets) sum += std::exchange(o, sum);
    for (size_t i = 0; i < n; ++i) {
      size_t dst = offsets[(codes[i] >> shift) & (kBuckets - 1)]++;
      codesTmp[dst] = codes[i];
      indexTmp[dst] = index[i];
    }
    codes.swap(codesTmp);
    index.swap(indexTmp);
  }
}

class Builder {
 public:
  Builder(const std::vector<Triangle>& triangles, const std::vector<uint64_t>& codes,
          size_t leafSize, std::vector<BvhNode>& nodes)
      : triangles_(triangles), codes_(codes), leafSize_(leafSize), nodes_(nodes) {}

  // Emits the subtree of triangles [first, last) in depth-first order and returns its root.
  uint32_t emit(size_t first, size_t last, int depth) {
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.push_back(BvhNode{});
    maxDepth_ = std::max(maxDepth_, depth);
    Bounds bounds;
    const size_t count = last - first;
    if (count <= leafSize_) {
      for (size_t i = first; i < last; ++i) {
        bounds.grow(triangles_[i].v0);
        bounds.grow(triangles_[i].v1);
        bounds.grow(triangles_[i].v2);
      }
      nodes_[index] = BvhNode{bounds.lo, uint32_t(first), bounds.hi, uint32_t(count)};
      return index;
    }
    const size_t split = chooseSplit(first, last, depth);
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
  size_t chooseSplit(size_t first, size_t last, int depth) const {
    const size_t middle = first + (last - first) / 2;
    // Guarantee the traversal stack: when the Morton split could make this subtree deeper
    // than the stack allows, fall back to a balanced split, which needs the fewest levels.
    if (depth + 1 + balancedLevels(last - first, leafSize_) >= int(kBvhStackSize)) return middle;
    const uint64_t a = codes_[first];
    const uint64_t b = codes_[last - 1];
    // Equal codes (coincident or very close centroids) must still split: halve the range.
    if (a == b) return middle;
    // Karras 2012: the codes are sorted, so the range's first and last code differ in the
    // highest bit any pair in the range differs in; split where that bit turns from 0 to 1.
    const int bit = 63 - std::countl_zero(a ^ b);
    const uint64_t mask = uint64_t(1) << bit;
    auto it =
        std::partition_point(codes_.begin() + ptrdiff_t(first), codes_.begin() + ptrdiff_t(last),
                             [mask](uint64_t c) { return (c & mask) == 0; });
    return size_t(it - codes_.begin());
  }

  const std::vector<Triangle>& triangles_;
  const std::vector<uint64_t>& codes_;
  size_t leafSize_;
  std::vector<BvhNode>& nodes_;
  int maxDepth_ = 0;
};

}  // namespace

uint64_t mortonCode63(vec3 unitPoint) {
  constexpr float kCells = float(1 << 21);
  auto quantize = [](float x) {
    // Clamp in float first: x = 1 maps to the last cell, not one past it; NaN maps to 0.
    float cell = std::clamp(x * kCells, 0.0f, kCells - 1.0f);
    return cell == cell ? uint64_t(cell) : 0;
  };
  return spreadBits3(quantize(unitPoint.x)) | spreadBits3(quantize(unitPoint.y)) << 1 |
         spreadBits3(quantize(unitPoint.z)) << 2;
}

Bvh buildBvh(std::vector<Triangle> triangles, const BvhBuildOptions& options) {
  PT_CHECK(!triangles.empty(), "a BVH needs at least one triangle");
  PT_CHECK(options.maxLeafSize >= 1);
  PT_CHECK(triangles.size() < size_t(UINT32_MAX));
  if (options.builder == BvhBuilder::kBinnedSah) {
    return buildBinnedSahBvh(std::move(triangles), size_t(options.maxLeafSize));
  }
  const auto start = std::chrono::steady_clock::now();
  const size_t n = triangles.size();

  // Morton codes of the centroids, normalised to the centroids' bounding box (tighter than
  // the scene box, so the 21 bits per axis are spent where the triangles are).
  std::vector<vec3> centroids(n);
  Bounds centroidBounds;
  for (size_t i = 0; i < n; ++i) {
    centroids[i] = (triangles[i].v0 + triangles[i].v1 + triangles[i].v2) * (1.0f / 3.0f);
    centroidBounds.grow(centroids[i]);
  }
  const vec3 extent = centroidBounds.hi - centroidBounds.lo;
  // A flat axis (all centroids in one plane) gets scale 0 instead of a division by zero.
  const vec3 scale = vec3(extent.x > 0 ? 1 / extent.x : 0, extent.y > 0 ? 1 / extent.y : 0,
                          extent.z > 0 ? 1 / extent.z : 0);
  std::vector<uint64_t> codes(n);
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) {
    codes[i] = mortonCode63((centroids[i] - centroidBounds.lo) * scale);
    order[i] = uint32_t(i);
  }
  radixSort(codes, order);

  Bvh bvh;
  bvh.triangles.resize(n);
  for (size_t i = 0; i < n; ++i) bvh.triangles[i] = triangles[order[i]];
  bvh.nodes.reserve(2 * n);
  Builder builder(bvh.triangles, codes, size_t(options.maxLeafSize), bvh.nodes);
  builder.emit(0, n, 0);
  bvh.maxDepth = builder.maxDepth();
  PT_CHECK(bvh.maxDepth <= int(kBvhStackSize));
  bvh.nodes.shrink_to_fit();
  bvh.buildSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

}  // namespace pt
