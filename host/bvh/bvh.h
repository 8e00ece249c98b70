// BVH over triangles, DFS-linearized into the 32-byte BvhNode the GPU reads. The default
// builder is the linear BVH: Morton codes of centroids, radix sort, split at the highest
// differing bit (Karras 2012). A binned-SAH builder (bvh_sah.cpp) is there to measure what
// that choice costs. Knows nothing of materials, cameras or Vulkan.
#pragma once

#include <cstdint>
#include <vector>

#include "common/named_values.h"
#include "common/shared.h"

namespace pt {

enum class BvhBuilder {
  kLbvh,       // Morton order, split at the highest differing bit: fast to build
  kBinnedSah,  // top-down, 16 bins per node on the widest centroid axis, surface-area cost
};

inline constexpr NameTable<BvhBuilder, 2> kBuilderNames{{
    {"lbvh", BvhBuilder::kLbvh, "Morton order, fast to build"},
    {"sah", BvhBuilder::kBinnedSah, "binned SAH, slower to build, faster to trace"},
}};

struct BvhBuildOptions {
  int maxLeafSize = 4;  // a range of at most this many triangles becomes a leaf (>= 1)
  BvhBuilder builder = BvhBuilder::kLbvh;
};

struct Bvh {
  std::vector<BvhNode> nodes;       // nodes[0] is the root; depth-first order
  std::vector<Triangle> triangles;  // reordered so that every leaf is a contiguous range
  int maxDepth = 0;                 // depth of the deepest leaf (root = 0), <= kBvhStackSize
  double buildSeconds = 0.0;
};

// Builds the BVH. Triangles keep their fields; only their order changes.
// Requires at least one triangle.
Bvh buildBvh(std::vector<Triangle> triangles, const BvhBuildOptions& options = {});

// 63-bit Morton code of a point with coordinates in [0, 1]: 21 bits per axis, interleaved
// as ... z1 y1 x1 z0 y0 x0 (x in the lowest bit of each triple).
uint64_t mortonCode63(vec3 unitPoint);

}  // namespace pt
