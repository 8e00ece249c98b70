// The JSON format's "transform" of shapes and grid media and "rotate" of environment images
// (docs/scene-format.md): a scale, then a rotation about an axis, then a translation.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "scene/json_reader.h"

namespace pt::scene_detail {

// p -> rotate(scale * p) + translate, evaluated in double so that vertices are rounded to
// float once.
struct Transform {
  glm::dvec3 scale{1.0};
  glm::dvec3 axis{0.0, 1.0, 0.0};  // unit
  double cosAngle = 1.0;
  double sinAngle = 0.0;
  glm::dvec3 translate{0.0};

  glm::dvec3 apply(glm::dvec3 p) const;
  // The inverse map, world to object: p -> scale^-1 * rotate^-1(p - translate).
  glm::dmat4 inverseMatrix() const;
};

// A "rotate" object ({"axis": [x, y, z], "degrees": d}) into t: right-handed about the axis.
void readRotation(const JsonNode& n, Transform& t);

// A "transform" object: "scale" (a number or three, none zero), "rotate", "translate".
Transform readTransform(const JsonNode& node);

}  // namespace pt::scene_detail
