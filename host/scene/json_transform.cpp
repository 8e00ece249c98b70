// The JSON format's transforms (json_transform.h).
#include "scene/json_transform.h"

#include <cstddef>
#include <tuple>

#include <glm/geometric.hpp>

#include "scene/reader_helpers.h"

namespace pt::scene_detail {

glm::dvec3 Transform::apply(glm::dvec3 p) const {
  p *= scale;
  // Rodrigues' rotation formula (right-handed about axis).
  p = p * cosAngle + glm::cross(axis, p) * sinAngle + axis * (glm::dot(axis, p) * (1.0 - cosAngle));
  return p + translate;
}

glm::dmat4 Transform::inverseMatrix() const {
  // The rotation by -angle, then the inverse scale, applied to the unit vectors.
  const auto unrotate = [&](glm::dvec3 p) {
    return p * cosAngle - glm::cross(axis, p) * sinAngle +
           axis * (glm::dot(axis, p) * (1.0 - cosAngle));
  };
  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) {
    glm::dvec3 e(0.0);
    e[c] = 1.0;
    m[c] = glm::dvec4(unrotate(e) / scale, 0.0);
  }
  m[3] = glm::dvec4(-(unrotate(translate) / scale), 1.0);
  return m;
}

void readRotation(const JsonNode& n, Transform& t) {
  n.checkKeys({"axis", "degrees"});
  const JsonNode axisNode = n.require("axis");
  const glm::dvec3 axis = axisNode.vec3();
  if (glm::length(axis) == 0.0) axisNode.fail("rotation axis must not be the zero vector");
  t.axis = glm::normalize(axis);
  std::tie(t.cosAngle, t.sinAngle) = cosSinDegrees(n.require("degrees").number());
}

Transform readTransform(const JsonNode& node) {
  node.checkKeys({"scale", "rotate", "translate"});
  Transform t;
  if (auto n = node.find("scale")) {
    if (n->json().is_array()) {
      t.scale = n->vec3();
      for (std::size_t c = 0; c < 3; ++c) {
        if (t.scale[c] == 0.0) (*n)[c].fail("scale factors must be non-zero");
      }
    } else {
      if (!n->json().is_number()) {
        n->fail("expected a number or an array of 3 numbers, got " + n->describe());
      }
      t.scale = glm::dvec3(n->floatNumber());
      if (t.scale.x == 0.0) n->fail("scale factor must be non-zero");
    }
  }
  if (auto n = node.find("rotate")) readRotation(*n, t);
  if (auto n = node.find("translate")) t.translate = n->vec3();
  return t;
}

}  // namespace pt::scene_detail
