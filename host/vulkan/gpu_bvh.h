// The GPU's copy of the BVH: the binary tree of bvh/bvh.h with every interior node holding
// both of its children's boxes (GpuBvhNode, shaders/shared_types.h), so that the shader's
// traversal fetches one 64-byte node per visit where the binary layout took a fetch for the
// node and one for each child, and meets a leaf in its parent's node instead of on a visit
// of its own. Built on the host from the Bvh at upload, deterministically: the same tree
// always gives the same bytes.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "bvh/bvh.h"

namespace pt {

struct GpuBvh {
  std::vector<GpuBvhNode> nodes;  // nodes[0]: the root's box and reference; then depth first
  // Most interior nodes on one path from the root: the traversal's stack holds at most one
  // entry per interior node above it, so this must not exceed kBvhStackSize.
  int maxDepth = 0;
};

// Builds the GPU layout of `bvh`: the same boxes, the same triangle order, so that the
// shader visits the leaves in the binary traversal's order (host/bvh/traverse.cpp). (Its
// answers would be the same in any order: the closest-hit rule, isCloserHit in sampling.h,
// does not depend on it.) A leaf of more triangles than a reference holds
// (kGpuBvhMaxLeafCount) is split under nodes whose children's boxes are infinite, which the
// traversal enters left first at distance 0, so its triangles are still tested in order.
// Throws InputError for a tree the layout cannot address (more than 2^27 triangles) or
// whose split leaves make it deeper than the traversal stack.
GpuBvh buildGpuBvh(const Bvh& bvh);

// The buffer the shader's traversal reads (PT_BINDING_NODES), as 32-bit words: the nodes,
// then a copy of the triangles, then one zero texel; node 0's reserved0 holds the texel
// where the triangles start. Each step of the traversal reads four texels at one place, a
// node's four or a triangle's three and the next (the zero texel after the last triangle),
// so that a node visit and a triangle test share the fetches (bvh.glsl). Throws InputError
// when the texels cannot be addressed by a 32-bit int.
std::vector<uint32_t> gpuTraversalTexels(const GpuBvh& gpu, const std::vector<Triangle>& triangles);

// The rows of four stack entries the shader's traversal needs for this tree (its
// specialization constant PT_SPEC_STACK_ROWS): one entry per interior node above the one
// visited, so maxDepth entries.
inline uint gpuStackRows(const GpuBvh& gpu) {
  return uint(std::max(gpu.maxDepth, 1) + 3) / 4u;
}

inline bool isGpuBvhLeaf(uint reference) {
  return (reference & kGpuBvhLeaf) != 0u;
}
inline uint gpuBvhLeafFirst(uint reference) {
  return (reference & ~kGpuBvhLeaf) >> kGpuBvhCountBits;
}
inline uint gpuBvhLeafCount(uint reference) {
  return reference & kGpuBvhMaxLeafCount;
}

}  // namespace pt
