// pbrt-v4 scene files, second stage: pbrt's graphics state (transforms, materials, area lights,
// object instances) applied to the parser's statements, giving the same Scene as the JSON
// reader: camera, integrator settings, materials and a flat triangle list. What is supported,
// what warns and how pbrt-v4 and this renderer differ: docs/pbrt-format.md.
#pragma once

#include <filesystem>
#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "scene/scene.h"

namespace pt {

// Reads a pbrt-v4 scene file and the files it includes. Throws InputError
// "file:line:column: message" for anything malformed; what it reads but does not simulate
// becomes one warning per kind in Scene::warnings ("file:line: message"), or with
// options.strict the InputError "file:line:column: message".
Scene loadPbrtScene(const std::filesystem::path& path, const SceneLoadOptions& options = {});

// The same for `text` given as the content of the file `path` (which need not exist;
// relative paths in it resolve against its directory).
Scene loadPbrtSceneText(std::string text, const std::filesystem::path& path,
                        const SceneLoadOptions& options = {});

namespace pbrt {

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

// The tessellation of spheres and disks until they are exact primitives: rings from pole to
// pole and segments around the axis. The chord error is radius * (1 - cos(pi / 128)), 3e-4
// of the radius, for both.
inline constexpr int kSphereRings = 64;
inline constexpr int kSphereSegments = 128;
inline constexpr int kDiskSegments = 128;

}  // namespace pbrt
}  // namespace pt
