// Stanford PLY meshes for the scene loader: ascii and binary (both byte orders), read with
// the standard library only, with messages naming the header line or the element entry.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace pt::scene_detail {

// Triangles of a PLY file in file order, each polygon fanned as (0, i, i + 1). `bytes` is
// the file's whole content (binary-safe), `file` its name for messages; `context` is
// appended to every message to say which scene entry referenced the file. Throws
// InputError "<file>: <where>: <problem><context>", where <where> is "line N" for the
// header, "<element> <index>" for binary data and "<element> <index> (line N)" for ascii
// data (element indices count from 0, like the vertex indices of faces).
//
// Accepts the elements 'vertex' (float or double x, y, z), 'face' (a 'vertex_indices' or
// 'vertex_index' list) and 'tristrips' (a 'vertex_indices' list, -1 restarting a strip);
// every other element and property is skipped.
std::vector<std::array<glm::dvec3, 3>> loadPlyTriangles(const std::string& bytes,
                                                        const std::string& file,
                                                        const std::string& context);

}  // namespace pt::scene_detail
