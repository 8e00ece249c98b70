// KHR_lights_punctual: the point, spot and directional lights that placed nodes carry, as the
// renderer's point, spot and distant lights at the node's position, shining along its -z.
#pragma once

#include <vector>

#include "scene/gltf/gltf_context.h"
#include "scene/gltf/gltf_nodes.h"
#include "scene/gltf/tinygltf.h"
#include "scene/scene.h"

namespace pt::gltf {

// Appends to scene.lights the light of every node in `nodes` that has one: color times
// intensity as the point and spot lights' radiant intensity and the directional light's
// radiance (docs/gltf.md). "range" is warned (the falloff stays inverse-square, uncut).
void addPunctualLights(const tinygltf::Model& model, const std::vector<PlacedNode>& nodes,
                       Scene& scene, Context& context);

}  // namespace pt::gltf
