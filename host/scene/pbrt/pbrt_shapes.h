// pbrt-v4's shapes as triangle meshes in object space, and what is done to them on the way to
// the scene (ReverseOrientation, the CTM). The Shape directive itself is the builder's.
#pragma once

#include <array>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace pt::pbrt {

// The tessellation of spheres and disks until they are exact primitives: rings from pole to
// pole and segments around the axis. The chord error is radius * (1 - cos(pi / 128)), 3e-4
// of the radius, for both.
inline constexpr int kSphereRings = 64;
inline constexpr int kSphereSegments = 128;
inline constexpr int kDiskSegments = 128;

using Tri = std::array<glm::dvec3, 3>;

// Triangles with, optionally, the vertex normals of each (parallel to `triangles`). Once
// oriented (orient below), a triangle's front side is the side of its winding's normal
// (v1 - v0) x (v2 - v0), or, where it has vertex normals, the side they point to.
using UVs = std::array<glm::vec2, 3>;

struct Mesh {
  std::vector<Tri> triangles;
  std::vector<Tri> normals;
  std::vector<UVs> uvs;  // per triangle, or empty: the mesh has none
};

// ReverseOrientation in object space, as pbrt-v4 does it: the front becomes the back, which
// here means the other winding (and negated vertex normals).
void reverseMesh(Mesh& mesh);

// `mesh` under the matrix `m`: points transformed, normals by the inverse transpose. A
// matrix that swaps handedness reverses the winding of the transformed points, so each
// triangle is rewound to keep its front (pbrt-v4 flips its normal instead, by
// transformSwapsHandedness). A triangle with vertex normals is wound to face where they
// point, as pbrt-v4 faces its geometric normal towards the interpolated one.
Mesh transformMesh(Mesh mesh, const glm::dmat4& m);

}  // namespace pt::pbrt
