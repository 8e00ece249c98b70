// The light BVH over a scene's emitters (pbrt-v4's BVHLightSampler, built as pbrt-v4 builds
// it): what shaders/light_bvh.h and path_vertex.h's chooseEmitter read. Each emitter with a
// position (emissive triangle, point, spot or sphere light) is a leaf bounded by pbrt-v4's
// LightBounds (its box, power and cone of normals and emission); distant and infinite lights
// stay outside the tree and are chosen uniformly with probability U / (U + 1).
#pragma once

#include <cstdint>
#include <vector>

#include "common/shared.h"

namespace pt {

struct LightBox {
  vec3 lo, hi;
};

struct LightBvh {
  std::vector<LightBvhNode> nodes;  // depth first from the root; empty without bounded lights
  std::vector<LightBox> boxes;      // each node's box (the walk reads its centre and radius)
  // Each emitter's leaf (kNoEmitter for the unbounded ones), then the unbounded emitters.
  std::vector<uint32_t> words;
  uint32_t unbounded = 0;  // the number of unbounded emitters
};

// Builds the tree over `emitters` (render/prepare.h's table, whose pmf the unbounded emitters
// keep) with the triangles, materials and lights they name.
LightBvh buildLightBvh(const std::vector<Emitter>& emitters, const std::vector<Triangle>& triangles,
                       const std::vector<Material>& materials, const std::vector<Light>& lights);

// Whether the tree chooses by power alone: one light, or lights that all share one bounds (the
// two triangles of an axis-aligned quad light), where the importance of every child is in the
// ratio of its power. The power sampler's alias table then makes the same choice (weighing
// colours by luminance where the tree weighs their largest channel) at less cost.
bool choosesByPowerAlone(const LightBvh& tree);

}  // namespace pt
