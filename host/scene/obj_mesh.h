// Wavefront OBJ meshes for the scene loader: validation with line-accurate messages, then
// loading with tinyobjloader and fan triangulation.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace pt::scene_detail {

// An OBJ file's triangles with their vertex normals, texture coordinates and the material
// statements that apply to them.
struct ObjMesh {
  std::vector<std::array<glm::dvec3, 3>> triangles;  // file order, polygons fanned
  // The normals at the three vertices of each triangle, parallel to `triangles` (same fan),
  // from the faces' `v//vn` and `v/vt/vn` references; empty when no face references a
  // normal. A face that does not reference one at each of its vertices gets all-zero
  // triples, which the scene loader replaces by the geometric normal (so do the zeros of a
  // file's own `vn 0 0 0`). As read: not normalized (the scene loader normalizes after
  // transforming).
  std::vector<std::array<glm::dvec3, 3>> normals;
  // The texture coordinates at the three vertices of each triangle, parallel to `triangles`
  // (same fanning), or empty when the file has none. From the faces' `v/vt` and `v/vt/vn`
  // references (the `vt` line's u and v as written, not flipped; a w is ignored, a missing v
  // is 0); empty when no face references a texture coordinate. A face that does not
  // reference one at each of its vertices gets pbrt-v4's default per-triangle coordinates
  // (0,0), (1,0), (1,1) for each of its triangles.
  std::vector<std::array<glm::vec2, 3>> uvs;
  // Per triangle: index into usemtl (the `usemtl` in force for its face), or -1 before any.
  std::vector<int> material;
  struct Statement {
    std::string name;  // usemtl: the material name; mtllib: one file name
    std::size_t line = 0;
  };
  std::vector<Statement> usemtl;  // distinct names, with the line of their first use
  std::vector<Statement> mtllib;  // every file named by an `mtllib` line
};

// Triangles of an OBJ file in file order, each polygon fanned as (0, i, i + 1). `text` is
// the file's content and `file` its name for messages; `context` is appended to every
// message to say which scene entry referenced the file. Throws InputError
// "<file>: line N: <problem>" for malformed content (a `vn` line too: 3 numbers that fit a
// 32-bit float, whether or not a face uses it; a `vt` line: at least 1 number, u and the
// optional v fitting a 32-bit float) and "<file>: no faces" for a file without faces.
ObjMesh loadObjMesh(const std::string& text, const std::string& file, const std::string& context);

// Just the triangles (the scene's own material for all of them).
inline std::vector<std::array<glm::dvec3, 3>> loadObjTriangles(const std::string& text,
                                                               const std::string& file,
                                                               const std::string& context) {
  return loadObjMesh(text, file, context).triangles;
}

}  // namespace pt::scene_detail
