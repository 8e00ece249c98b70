// The node hierarchy of a glTF scene flattened: every node reached from the scene's roots with
// its world transform (the product of its ancestors' local transforms, each a matrix or
// translation * rotation * scale), in depth-first order.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/mat4x4.hpp>
#include "scene/gltf/tinygltf.h"

#include "scene/gltf/gltf_context.h"

namespace pt::gltf {

struct PlacedNode {
  std::size_t node;  // index into model.nodes
  glm::dmat4 world;  // object to world
};

// A node's local transform: its "matrix" (column-major), or T * R * S from "translation",
// "rotation" (a quaternion x, y, z, w, normalized here) and "scale". (tinygltf reads no TRS
// where a node has a matrix: the matrix wins.)
glm::dmat4 localTransform(const tinygltf::Node& node, std::size_t index, const Context& context);

// The nodes of the scene the file names ("scene", else scenes[0]; a file without scenes: every
// node that is no node's child), each once. A node with two parents, a cycle or a child out of
// range is an InputError naming the field.
std::vector<PlacedNode> placeNodes(const tinygltf::Model& model, const Context& context);

}  // namespace pt::gltf
