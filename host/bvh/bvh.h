// BVH over triangles, DFS-linearized into the 32-byte BvhNode the GPU reads. The default
// builder is the linear BVH: Morton codes of centroids, radix sort, split at the highest
// differing bit (Karras 2012), on all cores. PLOC (bvh_ploc.cpp) clusters the same Morton
// order bottom-up (Meister and Bittner 2018) and splits the clusters top-down by binned SAH,
// for a tree that traces like the binned-SAH builder's (bvh_sah.cpp, the serial reference)
// at a fraction of its build time. Knows nothing of materials, cameras or Vulkan.
#pragma once

#include <cstdint>
#include <vector>

#include "common/named_values.h"
#include "common/shared.h"

namespace pt {

enum class BvhBuilder {
  kLbvh,       // Morton order, split at the highest differing bit: fast to build
  kBinnedSah,  // top-down, 16 bins per node on the widest centroid axis, surface-area cost
  kPloc,       // Morton-order clusters (Meister and Bittner 2018) under binned-SAH top levels
};

inline constexpr NameTable<BvhBuilder, 3> kBuilderNames{{
    {"lbvh", BvhBuilder::kLbvh, "Morton order, fast to build"},
    {"sah", BvhBuilder::kBinnedSah, "binned SAH, slower to build, faster to trace"},
    {"ploc", BvhBuilder::kPloc, "PLOC clusters under binned SAH, traces like sah, builds faster"},
}};

struct BvhBuildOptions {
  int maxLeafSize = 4;  // a range of at most this many triangles becomes a leaf (>= 1)
  BvhBuilder builder = BvhBuilder::kLbvh;
  // Threads for the LBVH and PLOC builders (the binned-SAH builder is serial); 0: one per
  // hardware thread. The tree does not depend on it.
  int threads = 0;
};

// The cost model of Bvh::sahCost: a ray that reaches a node pays kSahTraversalCost for an
// interior node and kSahTriangleCost per triangle of a leaf. Unit costs for both, the usual
// choice for comparing trees across builders (not a model of any one traversal's timing).
inline constexpr double kSahTraversalCost = 1.0;
inline constexpr double kSahTriangleCost = 1.0;

struct Bvh {
  std::vector<BvhNode> nodes;       // nodes[0] is the root; depth-first order
  std::vector<Triangle> triangles;  // reordered so that every leaf is a contiguous range
  int maxDepth = 0;                 // depth of the deepest leaf (root = 0), <= kBvhStackSize
  double buildSeconds = 0.0;
  // Expected cost of a ray that hits the root box (Goldsmith and Salmon 1987, MacDonald and
  // Booth 1990): the sum over nodes of area(node) / area(root) times kSahTraversalCost for
  // interior nodes and kSahTriangleCost * count for leaves. Lower usually traces faster.
  double sahCost = 0.0;
};

// Builds the BVH. Triangles keep their fields; only their order changes.
// Requires at least one triangle.
Bvh buildBvh(std::vector<Triangle> triangles, const BvhBuildOptions& options = {});

// 63-bit Morton code of a point with coordinates in [0, 1]: 21 bits per axis, interleaved
// as ... z1 y1 x1 z0 y0 x0 (x in the lowest bit of each triple).
uint64_t mortonCode63(vec3 unitPoint);

}  // namespace pt
