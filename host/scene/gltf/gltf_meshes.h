// glTF meshes as triangles: each primitive's vertices and indices decoded once (triangles,
// strips and fans; points and lines warned and skipped), then every node that uses the mesh
// appends them to the scene under its world transform (instances flattened, as the pbrt
// reader flattens ObjectInstance).
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include "scene/gltf/tinygltf.h"

#include "scene/gltf/gltf_context.h"
#include "scene/scene.h"

namespace pt::gltf {

// One primitive in the mesh's own space, as triangles.
struct LocalPrimitive {
  int material = -1;  // index into model.materials, -1: the default material
  std::string where;  // "meshes[2].primitives[0]", for messages
  std::vector<std::array<glm::dvec3, 3>> positions;
  std::vector<std::array<glm::dvec3, 3>> normals;  // parallel, or empty: no NORMAL
  std::vector<std::array<glm::vec2, 3>> uvs;       // TEXCOORD_0, parallel, or empty
  std::vector<std::array<glm::vec2, 3>> uvs1;      // TEXCOORD_1, parallel, or empty
  // TANGENT (direction and bitangent sign w), parallel to normals, or empty: none, or no NORMAL.
  std::vector<std::array<glm::dvec4, 3>> tangents;
};

// The scene's material for a glTF material index (-1: the default material), made on first
// use, and the texture coordinate set its textures read (0 or 1: the triangles keep that one).
struct MaterialChoice {
  uint material = 0;
  int uvSet = 0;
};
using MaterialSlot = std::function<MaterialChoice(int material, const std::string& where)>;

class MeshReader {
 public:
  MeshReader(const tinygltf::Model& model, Context& context) : model_(model), context_(context) {}

  // Appends mesh `mesh` (referred to by the field `where`) under `world` to scene.
  void emit(int mesh, const std::string& where, const glm::dmat4& world, const MaterialSlot& slot,
            Scene& scene);

  // Zero-area triangles dropped so far.
  std::size_t dropped() const { return dropped_; }

 private:
  const std::vector<LocalPrimitive>& primitives(std::size_t mesh);
  void decode(const tinygltf::Primitive& p, const std::string& where, LocalPrimitive& out);

  const tinygltf::Model& model_;
  Context& context_;
  std::map<std::size_t, std::vector<LocalPrimitive>> decoded_;
  std::size_t dropped_ = 0;
};

}  // namespace pt::gltf
