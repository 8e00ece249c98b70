// placeNodes and localTransform (gltf_nodes.h).
#include "scene/gltf/gltf_nodes.h"

#include <cmath>
#include <string>
#include <utility>

#include <glm/gtc/quaternion.hpp>

namespace pt::gltf {

namespace {

void checkFinite(const std::vector<double>& values, const std::string& where,
                 const Context& context) {
  for (double v : values) {
    if (!std::isfinite(v)) context.fail(where, "a value is not finite");
  }
}

}  // namespace

glm::dmat4 localTransform(const tinygltf::Node& node, std::size_t index, const Context& context) {
  const std::string path = indexed("nodes", index);
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) {
      context.fail(path + ".matrix",
                   "expected 16 numbers, got " + std::to_string(node.matrix.size()));
    }
    checkFinite(node.matrix, path + ".matrix", context);
    glm::dmat4 m(1.0);
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[std::size_t(c * 4 + r)];
    }
    if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0) {
      context.fail(path + ".matrix", "the last row must be 0, 0, 0, 1 (an affine transform)");
    }
    return m;
  }
  glm::dmat4 t(1.0), r(1.0), s(1.0);
  if (!node.translation.empty()) {
    if (node.translation.size() != 3) context.fail(path + ".translation", "expected 3 numbers");
    checkFinite(node.translation, path + ".translation", context);
    t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
  }
  if (!node.rotation.empty()) {
    if (node.rotation.size() != 4) context.fail(path + ".rotation", "expected 4 numbers");
    checkFinite(node.rotation, path + ".rotation", context);
    // glTF's order is x, y, z, w; GLM's constructor takes w first.
    glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    const double length = glm::length(q);
    if (!(length > 1e-6)) context.fail(path + ".rotation", "not a unit quaternion (length 0)");
    r = glm::mat4_cast(q / length);
  }
  if (!node.scale.empty()) {
    if (node.scale.size() != 3) context.fail(path + ".scale", "expected 3 numbers");
    checkFinite(node.scale, path + ".scale", context);
    s[0][0] = node.scale[0];
    s[1][1] = node.scale[1];
    s[2][2] = node.scale[2];
  }
  return t * r * s;
}

std::vector<PlacedNode> placeNodes(const tinygltf::Model& model, const Context& context) {
  const std::size_t n = model.nodes.size();
  // Parents first: a node may have one (the hierarchy is a set of disjoint trees).
  std::vector<long> parent(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& children = model.nodes[i].children;
    for (std::size_t k = 0; k < children.size(); ++k) {
      const int c = children[k];
      const std::string where = indexed("nodes", i) + ".children" + "[" + std::to_string(k) + "]";
      if (c < 0 || std::size_t(c) >= n) {
        context.fail(where, "node " + std::to_string(c) + " out of range (the file has " +
                                std::to_string(n) + ")");
      }
      if (parent[std::size_t(c)] >= 0) {
        context.fail(where, "node " + std::to_string(c) + " is already a child of node " +
                                std::to_string(parent[std::size_t(c)]) +
                                " (a node has one parent)");
      }
      parent[std::size_t(c)] = long(i);
    }
  }
  std::vector<std::pair<std::size_t, std::string>> roots;  // node, the field naming it
  if (!model.scenes.empty()) {
    int chosen = model.defaultScene < 0 ? 0 : model.defaultScene;
    if (std::size_t(chosen) >= model.scenes.size()) {
      context.fail("scene", "scene " + std::to_string(chosen) + " out of range (the file has " +
                                std::to_string(model.scenes.size()) + ")");
    }
    const auto& nodes = model.scenes[std::size_t(chosen)].nodes;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const std::string where =
          indexed("scenes", std::size_t(chosen)) + ".nodes[" + std::to_string(k) + "]";
      if (nodes[k] < 0 || std::size_t(nodes[k]) >= n) {
        context.fail(where, "node " + std::to_string(nodes[k]) + " out of range (the file has " +
                                std::to_string(n) + ")");
      }
      if (parent[std::size_t(nodes[k])] >= 0) {
        context.fail(where, "node " + std::to_string(nodes[k]) + " is a child of node " +
                                std::to_string(parent[std::size_t(nodes[k])]) + ", not a root");
      }
      roots.emplace_back(std::size_t(nodes[k]), where);
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      if (parent[i] < 0) roots.emplace_back(i, indexed("nodes", i));
    }
  }
  std::vector<PlacedNode> placed;
  std::vector<bool> visited(n, false);
  std::vector<PlacedNode> stack;
  for (const auto& [root, where] : roots) {
    if (visited[root]) context.fail(where, "node " + std::to_string(root) + " is listed twice");
    stack.push_back(PlacedNode{root, localTransform(model.nodes[root], root, context)});
    visited[root] = true;
    while (!stack.empty()) {
      const PlacedNode p = stack.back();
      stack.pop_back();
      placed.push_back(p);
      const auto& children = model.nodes[p.node].children;
      // Pushed in reverse, so that children are visited in their order.
      for (std::size_t k = children.size(); k-- > 0;) {
        const std::size_t c = std::size_t(children[k]);
        // One parent each and every root parentless: a child seen again closes a cycle.
        if (visited[c]) {
          context.fail(indexed("nodes", p.node) + ".children[" + std::to_string(k) + "]",
                       "node " + std::to_string(c) + " is its own ancestor (a cycle)");
        }
        visited[c] = true;
        stack.push_back(PlacedNode{c, p.world * localTransform(model.nodes[c], c, context)});
      }
    }
  }
  return placed;
}

}  // namespace pt::gltf
