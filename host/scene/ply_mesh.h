// Stanford PLY meshes for the scene loader: ascii and binary (both byte orders), read with
// the standard library only, with messages naming the header line or the element entry.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace pt::scene_detail {

// A PLY file's triangles with the vertex normals and texture coordinates the file gives for
// them.
struct PlyMesh {
  std::vector<std::array<glm::dvec3, 3>> triangles;  // file order, polygons fanned
  // The normals at the three vertices of each triangle, parallel to `triangles` (same
  // fanning, same strip order), or empty when the vertex element has no nx, ny, nz. As
  // read: not normalized (the scene loader normalizes after transforming), and a file's
  // own 0 0 0 stays a zero vector, which the scene loader replaces by the geometric normal.
  std::vector<std::array<glm::dvec3, 3>> normals;
  // The texture coordinates at the three vertices of each triangle, parallel to `triangles`
  // (same fanning, same strip order), or empty when the file has none: the vertex element has
  // no pair of texture coordinate properties (see loadPlyMesh), and then no triangle has
  // any. As read, not flipped (the scene loader decides conventions).
  std::vector<std::array<glm::vec2, 3>> uvs;
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
// nx, ny, nz: all three or none; optionally, float or double texture coordinates: the first
// pair of u and v, s and t, texture_u and texture_v, texture_s and texture_t that the element
// has both of, as pbrt-v4 reads them, and without any whole pair, one of them alone is an
// error), 'face' (a 'vertex_indices' or 'vertex_index' list) and 'tristrips' (a
// 'vertex_indices' list, -1 restarting a strip); every other element and property is
// skipped. Coordinates and texture coordinates must be finite and fit a 32-bit float;
// normals too, except that a normal with a NaN or infinite component is counted in
// nonFiniteNormals and kept as 0 0 0.
PlyMesh loadPlyMesh(const std::string& bytes, const std::string& file, const std::string& context);

// Just the triangles.
inline std::vector<std::array<glm::dvec3, 3>> loadPlyTriangles(const std::string& bytes,
                                                               const std::string& file,
                                                               const std::string& context) {
  return loadPlyMesh(bytes, file, context).triangles;
}

}  // namespace pt::scene_detail
