// Ray queries on the Vulkan device: traces a batch of rays through the BVH with the shader's
// traversal (shaders/bvh.glsl) and returns the hits, so the GPU traversal can be tested on
// its own against the CPU's and against brute force.
#pragma once

#include <vector>

#include "bvh/bvh.h"
#include "vulkan/device_info.h"

namespace pt {

struct RaycastStats {
  uint32_t validationErrors = 0;
  uint64_t truncated = 0;      // queries cut short by lavapipe's loop cap
  double deviceSeconds = 0.0;  // the dispatch alone, from timestamp queries
};

std::vector<RayResult> traceRaysVulkan(const Bvh& bvh, const std::vector<RayQuery>& queries,
                                       const ContextOptions& options,
                                       RaycastStats* stats = nullptr);

}  // namespace pt
