// The camera of a glTF scene: a perspective camera placed by a node (the first in the scene's
// node order, or the one --camera names), or, where the scene has none, a default framing of
// the scene's bounding box as viewers frame a model.
#pragma once

#include <string>
#include <vector>

#include "scene/gltf/tinygltf.h"

#include "scene/gltf/gltf_context.h"
#include "scene/gltf/gltf_nodes.h"
#include "scene/scene.h"

namespace pt::gltf {

// The film's height in pixels; its width follows the camera's aspectRatio (square without).
inline constexpr int kFilmHeight = 512;
// The default framing's vertical field of view in degrees.
inline constexpr float kDefaultFovDegrees = 45.0f;

// Sets scene.camera. `wanted` is --camera: empty for the first camera, else the index or name
// of one in the file's "cameras". Call after the triangles are in the scene (the default
// framing sees their bounds).
void setCamera(const tinygltf::Model& model, const std::vector<PlacedNode>& nodes,
               const std::string& wanted, Scene& scene, Context& context);

}  // namespace pt::gltf
