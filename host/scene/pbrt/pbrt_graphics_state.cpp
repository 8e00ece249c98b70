// The directives of the graphics state: transforms, coordinate systems, the attribute stack,
// WorldBegin, object definitions and uses. What they apply to is the other families' business.
#include "scene/pbrt/pbrt_graphics_state.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/matrix.hpp>

#include "scene/pbrt/pbrt_builder.h"
#include "scene/reader_helpers.h"

namespace pt::pbrt {

glm::dmat4 translateMatrix(glm::dvec3 delta) {
  glm::dmat4 m(1.0);
  m[3] = glm::dvec4(delta, 1.0);
  return m;
}

glm::dmat4 scaleMatrix(glm::dvec3 factors) {
  glm::dmat4 m(1.0);
  m[0][0] = factors.x;
  m[1][1] = factors.y;
  m[2][2] = factors.z;
  return m;
}

glm::dmat4 rotateMatrix(double degrees, glm::dvec3 axis) {
  const glm::dvec3 a = glm::normalize(axis);
  const auto [c, s] = cosSinDegrees(degrees);
  // Rodrigues' formula as a matrix; glm indexes [column][row].
  glm::dmat4 m(1.0);
  m[0][0] = a.x * a.x + (1 - a.x * a.x) * c;
  m[1][0] = a.x * a.y * (1 - c) - a.z * s;
  m[2][0] = a.x * a.z * (1 - c) + a.y * s;
  m[0][1] = a.x * a.y * (1 - c) + a.z * s;
  m[1][1] = a.y * a.y + (1 - a.y * a.y) * c;
  m[2][1] = a.y * a.z * (1 - c) - a.x * s;
  m[0][2] = a.x * a.z * (1 - c) - a.y * s;
  m[1][2] = a.y * a.z * (1 - c) + a.x * s;
  m[2][2] = a.z * a.z + (1 - a.z * a.z) * c;
  return m;
}

namespace {

// World from camera for LookAt: the camera's axes and position as columns.
glm::dmat4 lookAtInverse(glm::dvec3 eye, glm::dvec3 look, glm::dvec3 up) {
  const glm::dvec3 dir = glm::normalize(look - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(glm::normalize(up), dir));
  const glm::dvec3 newUp = glm::cross(dir, right);
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(right, 0.0);
  m[1] = glm::dvec4(newUp, 0.0);
  m[2] = glm::dvec4(dir, 0.0);
  m[3] = glm::dvec4(eye, 1.0);
  return m;
}

// The inverse of an orthonormal-basis-plus-translation matrix, exactly as pbrt's inversion
// of it would give up to rounding: the transposed rotation and the rotated translation.
glm::dmat4 rigidInverse(const glm::dmat4& m) {
  const glm::dmat3 rt = glm::transpose(glm::dmat3(m));
  glm::dmat4 inverse(rt);
  inverse[3] = glm::dvec4(-(rt * glm::dvec3(m[3])), 1.0);
  return inverse;
}

}  // namespace

glm::dmat4 lookAtMatrix(glm::dvec3 eye, glm::dvec3 look, glm::dvec3 up) {
  return rigidInverse(lookAtInverse(eye, look, up));
}

glm::dmat4 fileMatrix(const double* numbers) {
  return glm::make_mat4(numbers);
}

void Builder::transform(const Statement& s) {
  const std::string& d = s.directive;
  const std::vector<double>& n = s.numbers;
  if (d == "Translate") {
    const glm::dvec3 v(n[0], n[1], n[2]);
    apply(Xform{translateMatrix(v), translateMatrix(-v)});
  } else if (d == "Scale") {
    const glm::dvec3 v(n[0], n[1], n[2]);
    apply(Xform{scaleMatrix(v), scaleMatrix(1.0 / v)});  // a zero factor: see emit
  } else if (d == "Rotate") {
    const glm::dvec3 axis(n[1], n[2], n[3]);
    if (!(glm::length(axis) > 0.0) || !std::isfinite(glm::length(axis))) {
      fail(s.location, "Rotate about the zero vector (the axis is the last three numbers)");
    }
    const glm::dmat4 r = rotateMatrix(n[0], axis);
    apply(Xform{r, glm::transpose(r)});
  } else if (d == "LookAt") {
    const glm::dvec3 eye(n[0], n[1], n[2]), look(n[3], n[4], n[5]), up(n[6], n[7], n[8]);
    const glm::dvec3 dir = look - eye;
    if (!(glm::length(dir) > 0.0))
      fail(s.location, "LookAt: the eye and the look-at point are equal");
    if (!(glm::length(up) > 0.0)) fail(s.location, "LookAt: the up vector is zero");
    const double sine = glm::length(glm::cross(glm::normalize(up), glm::normalize(dir)));
    if (!(sine > 1e-9)) {
      fail(s.location, "LookAt: the up vector is parallel to the view direction");
    }
    const glm::dmat4 worldFromCamera = lookAtInverse(eye, look, up);
    apply(Xform{rigidInverse(worldFromCamera), worldFromCamera});
  } else if (d == "Transform" || d == "ConcatTransform") {
    const glm::dmat4 m = fileMatrix(n.data());
    const Xform t{m, glm::inverse(m)};  // NaN where singular, as in pbrt-v4
    if (d == "Transform") {
      if (gs_.startActive) gs_.ctm = t;
    } else {
      apply(t);
    }
  } else if (d == "Identity") {
    if (gs_.startActive) gs_.ctm = Xform{};
  } else if (d == "CoordinateSystem") {
    coordinateSystems_[s.strings[0]] = gs_.ctm;
  } else if (d == "CoordSysTransform") {
    const auto it = coordinateSystems_.find(s.strings[0]);
    if (it == coordinateSystems_.end()) {
      warnOnce("CoordSysTransform " + s.strings[0], s.location,
               "CoordSysTransform: no coordinate system named " + singleQuoted(s.strings[0]) +
                   " (ignored, as pbrt-v4 does)");
    } else {
      gs_.ctm = it->second;
    }
  } else if (d == "ActiveTransform") {
    gs_.startActive = s.strings[0] != "EndTime";
    if (s.strings[0] != "All") {
      warnOnce("ActiveTransform", s.location,
               "ActiveTransform " + s.strings[0] +
                   ": motion blur is not simulated; only the start-time transforms are used");
    }
  } else if (d == "TransformTimes") {
    requireOptions(s);  // the times only matter with motion blur, which is not simulated
  }
}

void Builder::worldBegin(const Statement& s) {
  if (inWorld_)
    fail(s.location, "WorldBegin appears twice (first at " + worldBegin_.fileLine() + ")");
  inWorld_ = true;
  worldBegin_ = s.location;
  gs_.ctm = Xform{};
  gs_.startActive = true;
  coordinateSystems_["world"] = Xform{};
  setupCamera(s.location);
}

void Builder::attributes(Statement& s) {
  const std::string& d = s.directive;
  if (d == "AttributeBegin" || d == "TransformBegin") {
    requireWorld(s);
    stack_.push_back(Pushed{gs_, 'a', s.location, d});
  } else if (d == "AttributeEnd" || d == "TransformEnd") {
    requireWorld(s);
    if (stack_.empty()) {
      // pbrt-v4 reports it and goes on; so does this reader.
      warnOnce("unmatched " + d, s.location, d + " without a matching AttributeBegin ignored");
      return;
    }
    if (stack_.back().kind == 'o') {
      fail(s.location, d + " closes the ObjectBegin at " + stack_.back().location.fileLine());
    }
    gs_ = std::move(stack_.back().state);
    stack_.pop_back();
  } else if (d == "Attribute") {
    requireWorld(s);
    const std::string& target = s.strings[0];
    std::vector<Param>* list = target == "shape"      ? &gs_.shapeAttributes
                               : target == "light"    ? &gs_.lightAttributes
                               : target == "material" ? &gs_.materialAttributes
                               : target == "medium"   ? &gs_.mediumAttributes
                               : target == "texture"  ? &gs_.textureAttributes
                                                      : nullptr;
    if (list == nullptr) {
      fail(s.stringLocations[0], "unknown Attribute target " + singleQuoted(target) +
                                     " (expected \"shape\", \"light\", \"material\", "
                                     "\"medium\" or \"texture\")");
    }
    for (Param& p : s.params) {
      p.used = true;  // reported, if at all, where a directive reads the list
      list->push_back(std::move(p));
    }
  } else if (d == "ReverseOrientation") {
    requireWorld(s);
    gs_.reverseOrientation = !gs_.reverseOrientation;
  }
}

void Builder::objectBegin(const Statement& s) {
  if (!activeInstance_.empty()) {
    fail(s.location, "ObjectBegin inside the definition of object " +
                         singleQuoted(activeInstance_) + " (pbrt-v4 does not nest them)");
  }
  stack_.push_back(Pushed{gs_, 'o', s.location, s.directive});
  Instance& instance = instances_[s.strings[0]];
  if (instance.defined) {
    fail(s.location, "object " + singleQuoted(s.strings[0]) + " redefined (first at " +
                         instance.location.fileLine() + ")");
  }
  instance.defined = true;
  instance.location = s.location;
  activeInstance_ = s.strings[0];
}

void Builder::objectEnd(const Statement& s) {
  if (activeInstance_.empty()) fail(s.location, "ObjectEnd without an ObjectBegin");
  if (stack_.back().kind != 'o') {
    fail(s.location, "ObjectEnd closes the " + stack_.back().directive + " at " +
                         stack_.back().location.fileLine());
  }
  gs_ = std::move(stack_.back().state);
  stack_.pop_back();
  activeInstance_.clear();
}

void Builder::objectInstance(const Statement& s) {
  if (!activeInstance_.empty()) {
    fail(s.location, "ObjectInstance inside the definition of object " +
                         singleQuoted(activeInstance_) + " (pbrt-v4 does not nest instances)");
  }
  instanceUses_.push_back(InstanceUse{s.strings[0], gs_.ctm.m, s.location});
}

}  // namespace pt::pbrt
