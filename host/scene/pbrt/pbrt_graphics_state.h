// pbrt-v4's graphics state: transforms (the CTM and its inverse), the attribute stack's
// contents, named coordinate systems and object instances. The directives that change it are
// the builder's (pbrt_graphics_state.cpp); what a shape or light makes of it is theirs.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "common/shared.h"
#include "scene/pbrt/pbrt_parser.h"
#include "scene/pbrt/pbrt_shapes.h"

namespace pt::pbrt {

// pbrt-v4's transforms (its util/transform.h) as matrices acting on column vectors, in
// double. The current transformation matrix is post-multiplied by each: the directive
// written last acts on the shape's points first.
glm::dmat4 translateMatrix(glm::dvec3 delta);
glm::dmat4 scaleMatrix(glm::dvec3 factors);
// A rotation by `degrees` about `axis` (not zero; normalized here), counter-clockwise looking
// down the axis: the usual right-handed rotation. Exact for multiples of 90 degrees.
glm::dmat4 rotateMatrix(double degrees, glm::dvec3 axis);
// LookAt's matrix: camera from world, where the camera looks down +z with +y up and +x to
// the image's right (pbrt's left-handed camera space). `eye` must differ from `look` and
// `up` must not be parallel to the view direction.
glm::dmat4 lookAtMatrix(glm::dvec3 eye, glm::dvec3 look, glm::dvec3 up);
// The matrix of Transform and ConcatTransform from their 16 numbers as the file lists them:
// column by column (the translation is numbers 13 to 15), which is glm's storage order.
glm::dmat4 fileMatrix(const double* numbers);

// A matrix with its inverse, kept side by side as pbrt's Transform keeps them, so that the
// camera's position comes out exactly (no inversion of a product).
struct Xform {
  glm::dmat4 m{1.0};
  glm::dmat4 inverse{1.0};
};

inline Xform operator*(const Xform& a, const Xform& b) {
  return {a.m * b.m, b.inverse * a.inverse};
}

inline glm::dvec3 transformPoint(const glm::dmat4& m, glm::dvec3 p) {
  const glm::dvec4 h = m * glm::dvec4(p, 1.0);
  return h.w == 1.0 ? glm::dvec3(h) : glm::dvec3(h) / h.w;
}

// The material a shape takes: an inline Material (by its index) or a named one, resolved at
// the end of the file as pbrt-v4 resolves them (so a name may be defined after its use).
struct MaterialRef {
  bool named = false;
  std::size_t inlineIndex = 0;  // 0: pbrt-v4's default material, a diffuse of 0.5
  std::string name;
  Location location;  // of the NamedMaterial that chose it
};

struct AreaLight {
  vec3 radiance{1.0f};  // "L": the colour space's illuminant, normalized, is white
  double scale = 1.0;
  double power = -1.0;  // pbrt-v4's "power" when positive (watts, as it defines them)
  bool twoSided = false;
  Location location;
};

struct GraphicsState {
  Xform ctm;
  bool startActive = true;  // ActiveTransform: whether transforms apply to the start time
  bool reverseOrientation = false;
  MaterialRef material;
  std::optional<AreaLight> areaLight;
  // The current MediumInterface: an index into the builder's table of them (0: vacuum on both
  // sides, pbrt-v4's start).
  std::size_t mediumInterface = 0;
  std::vector<Param> shapeAttributes, lightAttributes, materialAttributes, mediumAttributes,
      textureAttributes;
};

// Object instances: a definition's shapes (ObjectBegin to ObjectEnd) and each use
// (ObjectInstance), flattened at the end of the file.
struct InstanceShape {
  Mesh mesh;  // oriented, in the world space of the definition
  uint slot;
  std::size_t mediumInterface;  // the definition's, as pbrt-v4 keeps it for every use
  Location location;
  std::string context;
};

struct Instance {
  std::vector<InstanceShape> shapes;
  Location location;
  bool defined = false;
};

struct InstanceUse {
  std::string name;
  glm::dmat4 m;
  Location location;
};

}  // namespace pt::pbrt
