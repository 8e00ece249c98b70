// Stanford PLY meshes for the scene loader: ascii and binary (both byte orders), read with
// the standard library only, with messages naming the header line or the element entry.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace pt::scene_detail {

// A PLY file's triangles with the vertex normals the file gives for them.
struct PlyMesh {
  std::vector<std::array<glm::dvec3, 3>> triangles;  // file order, polygons fanned
  // The normals at the three vertices of each triangle, parallel to `triangles` (same
  // fanning, same strip order), or empty when the vertex element has no nx, ny, nz. As
  // read: not normalized (the scene loader normalizes after transforming), and a file's
  // own 0 0 0 stays a zero vector, which the scene loader replaces by the geometric normal.
  std::vector<std::array<glm::dvec3, 3>> normals;
  // Vertex normals with a NaN or infinite component (scanned meshes and exporters write them:
  // Bitterli's lamp has 32): kept as 0 0 0, so that their triangles take the geometric normal
  // there, and counted, so that the scene loader can say so.
  std::size_t nonFiniteNormals = 0;
};

// Triangles of a PLY file in file order, each polygon fanned as (0, i, i + 1). `bytes` is
// the file's whole content (binary-safe), `file` its name for messages; `context` is
// appended to every message to say which scene entry referenced the file. Throws
// InputError "<file>: <where>: <problem><context>", where <where> is "line N" for the
// header, "<element> <index>" for binary data and "<element> <index> (line N)" for ascii
// data (element indices count from 0, like the vertex indices of faces).
//
// Accepts the elements 'vertex' (float or double x, y, z and, optionally, float or double
// nx, ny, nz: all three or none), 'face' (a 'vertex_indices' or 'vertex_index' list) and
// 'tristrips' (a 'vertex_indices' list, -1 restarting a strip); every other element and
// property is skipped. Normals, like coordinates, must be finite and fit a 32-bit float.
PlyMesh loadPlyMesh(const std::string& bytes, const std::string& file, const std::string& context);

// Just the triangles.
inline std::vector<std::array<glm::dvec3, 3>> loadPlyTriangles(const std::string& bytes,
                                                               const std::string& file,
                                                               const std::string& context) {
  return loadPlyMesh(bytes, file, context).triangles;
}

}  // namespace pt::scene_detail
