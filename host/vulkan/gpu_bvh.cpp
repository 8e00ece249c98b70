// The GPU layout of the BVH; see gpu_bvh.h.
#include "vulkan/gpu_bvh.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "common/check.h"

namespace pt {
namespace {

class Layout {
 public:
  Layout(const Bvh& bvh, GpuBvh& gpu) : bvh_(bvh), gpu_(gpu) {}

  // The reference to binary node `index`, emitting it and everything below it depth first
  // when it is interior; `depth` counts the interior nodes above it.
  uint32_t reference(uint32_t index, int depth) {
    const BvhNode& node = bvh_.nodes[index];
    if (node.count > 0) return leaf(node.offset, node.count, depth);
    const uint32_t at = add(depth + 1);
    const uint32_t right = node.offset;
    const uint32_t leftRef = reference(index + 1, depth + 1);  // may reallocate gpu_.nodes
    const uint32_t rightRef = reference(right, depth + 1);
    GpuBvhNode& n = gpu_.nodes[at];
    n.leftMin = bvh_.nodes[index + 1].boundsMin;
    n.leftMax = bvh_.nodes[index + 1].boundsMax;
    n.left = leftRef;
    n.rightMin = bvh_.nodes[right].boundsMin;
    n.rightMax = bvh_.nodes[right].boundsMax;
    n.right = rightRef;
    return at;
  }

 private:
  // A new, zeroed node at `depth` interior nodes from the root (itself included).
  uint32_t add(int depth) {
    PT_CHECK(gpu_.nodes.size() < size_t(kGpuBvhLeaf), "too many GPU BVH nodes");
    gpu_.maxDepth = std::max(gpu_.maxDepth, depth);
    gpu_.nodes.emplace_back();
    return uint32_t(gpu_.nodes.size() - 1);
  }

  // The reference to the leaf of triangles [first, first + count). A leaf too large for one
  // reference becomes a node over its two halves with infinite boxes: both are entered at
  // distance 0 whatever the closest hit so far, so the left half comes first (ties go left)
  // and every triangle is tested in order, as in the binary leaf.
  uint32_t leaf(uint32_t first, uint32_t count, int depth) {
    if (count <= kGpuBvhMaxLeafCount) return kGpuBvhLeaf | first << kGpuBvhCountBits | count;
    const uint32_t at = add(depth + 1);
    const uint32_t half = count / 2;
    const uint32_t leftRef = leaf(first, half, depth + 1);
    const uint32_t rightRef = leaf(first + half, count - half, depth + 1);
    GpuBvhNode& n = gpu_.nodes[at];
    n.leftMin = n.rightMin = vec3(-INFINITY);
    n.leftMax = n.rightMax = vec3(INFINITY);
    n.left = leftRef;
    n.right = rightRef;
    return at;
  }

  const Bvh& bvh_;
  GpuBvh& gpu_;
};

}  // namespace

GpuBvh buildGpuBvh(const Bvh& bvh) {
  PT_CHECK(!bvh.nodes.empty() && !bvh.triangles.empty());
  // Leaf references keep 31 - kGpuBvhCountBits bits for the first triangle.
  constexpr size_t kMaxTriangles = size_t(1) << (31 - kGpuBvhCountBits);
  if (bvh.triangles.size() > kMaxTriangles) {
    throw InputError(
        "scene too large for the Vulkan backend: " + std::to_string(bvh.triangles.size()) +
        " triangles, its BVH layout addresses at most " + std::to_string(kMaxTriangles));
  }
  GpuBvh gpu;
  // One node per binary interior node, and node 0.
  gpu.nodes.reserve(bvh.nodes.size() / 2 + 1);
  gpu.nodes.emplace_back();
  Layout layout(bvh, gpu);
  const uint32_t root = layout.reference(0, 0);
  gpu.nodes[0].leftMin = bvh.nodes[0].boundsMin;
  gpu.nodes[0].leftMax = bvh.nodes[0].boundsMax;
  gpu.nodes[0].left = root;
  if (gpu.maxDepth > int(kBvhStackSize)) {
    throw InputError("BVH too deep for the Vulkan backend's traversal stack: leaves split to " +
                     std::to_string(kGpuBvhMaxLeafCount) + " triangles make it " +
                     std::to_string(gpu.maxDepth) + " levels deep, at most " +
                     std::to_string(kBvhStackSize) + " (use a smaller --leaf-size)");
  }
  return gpu;
}

std::vector<uint32_t> gpuTraversalTexels(const GpuBvh& gpu,
                                         const std::vector<Triangle>& triangles) {
  static_assert(sizeof(GpuBvhNode) == 64 && sizeof(Triangle) == 48);
  const size_t nodeWords = gpu.nodes.size() * 16, triangleWords = triangles.size() * 12;
  if ((nodeWords + triangleWords) / 4 + 1 > size_t(INT32_MAX)) {
    throw InputError("scene too large for the Vulkan backend: " + std::to_string(triangles.size()) +
                     " triangles and " + std::to_string(gpu.nodes.size()) +
                     " BVH nodes exceed 2^31 texels");
  }
  std::vector<uint32_t> words(nodeWords + triangleWords + 4, 0u);
  std::memcpy(words.data(), gpu.nodes.data(), nodeWords * sizeof(uint32_t));
  std::memcpy(words.data() + nodeWords, triangles.data(), triangleWords * sizeof(uint32_t));
  // node 0's reserved0 (word 11): the first texel of the triangles.
  static_assert(offsetof(GpuBvhNode, reserved0) == 11 * sizeof(uint32_t));
  words[11] = uint32_t(nodeWords / 4);
  return words;
}

}  // namespace pt
