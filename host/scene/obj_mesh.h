// Wavefront OBJ meshes for the scene loader: validation with line-accurate messages, then
// loading with tinyobjloader and fan triangulation.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace pt::scene_detail {

// Triangles of an OBJ file in file order, each polygon fanned as (0, i, i + 1). `text` is
// the file's content and `file` its name for messages; `context` is appended to every
// message to say which scene entry referenced the file. Throws InputError
// "<file>: line N: <problem>" for malformed content and "<file>: no faces" for a file
// without faces.
std::vector<std::array<glm::dvec3, 3>> loadObjTriangles(const std::string& text,
                                                        const std::string& file,
                                                        const std::string& context);

}  // namespace pt::scene_detail
