// MeshReader (gltf_meshes.h).
#include "scene/gltf/gltf_meshes.h"

#include <cmath>
#include <limits>
#include <utility>

#include <glm/matrix.hpp>

#include "scene/gltf/gltf_accessors.h"
#include "scene/reader_helpers.h"
#include "texture.h"

namespace pt::gltf {

namespace {

// The attributes the reader knows; others (COLOR_0, JOINTS_0, WEIGHTS_0, custom "_NAME"
// attributes) do not change the rest pose's geometry and are ignored.
const char* const kRead[] = {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "TEXCOORD_1"};

int attribute(const tinygltf::Primitive& p, const char* name) {
  const auto it = p.attributes.find(name);
  return it == p.attributes.end() ? -1 : it->second;
}

}  // namespace

void MeshReader::decode(const tinygltf::Primitive& p, const std::string& where,
                        LocalPrimitive& out) {
  out.where = where;
  out.material = p.material;
  if (p.material < -1 || (p.material >= 0 && std::size_t(p.material) >= model_.materials.size())) {
    context_.fail(where + ".material", "material " + std::to_string(p.material) +
                                           " out of range (the file has " +
                                           std::to_string(model_.materials.size()) + ")");
  }
  if (p.extensions.count("KHR_draco_mesh_compression") != 0 ||
      p.extensions.count("EXT_meshopt_compression") != 0) {
    context_.warnOnce("compressed", where + ".extensions",
                      "compressed geometry (Draco, meshopt) is not decoded: primitive skipped");
    return;
  }
  const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE ||
      mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP) {
    context_.warnOnce("points and lines", where + ".mode",
                      "points and lines have no area and are not rendered");
    return;
  }
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    context_.fail(where + ".mode", std::to_string(mode) + " is not a glTF primitive mode (0-6)");
  }
  if (!p.targets.empty()) {
    context_.warnOnce("morph targets", where + ".targets",
                      "morph targets are not simulated: the rest pose is rendered");
  }
  const std::string attributes = where + ".attributes.";
  const int position = attribute(p, "POSITION");
  if (position < 0) context_.fail(where + ".attributes", "no POSITION");
  const AccessorValues v =
      readAccessor(model_, position, {attributes + "POSITION", TINYGLTF_TYPE_VEC3}, context_);
  // An optional attribute of `type`, one element per vertex; empty where absent.
  const auto optional = [&](const char* name, int type) {
    AccessorValues a;
    const int i = attribute(p, name);
    if (i < 0) return a;
    a = readAccessor(model_, i, {attributes + name, type}, context_);
    if (a.count != v.count) {
      context_.fail(attributes + name,
                    std::to_string(a.count) + " elements, POSITION has " + std::to_string(v.count));
    }
    return a;
  };
  const AccessorValues n = optional("NORMAL", TINYGLTF_TYPE_VEC3);
  const AccessorValues uv = optional("TEXCOORD_0", TINYGLTF_TYPE_VEC2);
  // Tangents serve normal maps, in the frame of the normals: without NORMAL they are ignored,
  // as the specification says.
  const AccessorValues tangent = optional("TANGENT", TINYGLTF_TYPE_VEC4);
  const AccessorValues uv1 = optional("TEXCOORD_1", TINYGLTF_TYPE_VEC2);
  for (const auto& [name, index] : p.attributes) {
    bool known = false;
    for (const char* k : kRead) known = known || name == k;
    if (!known && name.rfind("TEXCOORD_", 0) == 0) {
      context_.warnOnce("texcoord", attributes + name,
                        "texture coordinate sets beyond TEXCOORD_1 are not used");
    }
  }
  // The vertex order of the primitive's triangles.
  std::vector<std::size_t> order;
  if (p.indices >= 0) {
    const AccessorValues idx =
        readAccessor(model_, p.indices, {where + ".indices", TINYGLTF_TYPE_SCALAR, true}, context_);
    order.reserve(idx.count);
    for (double d : idx.values) {
      if (d >= double(v.count)) {
        context_.fail(where + ".indices", "index " + std::to_string(std::uint64_t(d)) +
                                              " out of range (POSITION has " +
                                              std::to_string(v.count) + " elements)");
      }
      order.push_back(std::size_t(d));
    }
  } else {
    order.resize(v.count);
    for (std::size_t i = 0; i < v.count; ++i) order[i] = i;
  }
  // Triangles by mode, the specification's vertex order: lists take each three; a strip's
  // triangle i is (i, i+1, i+2), or (i, i+2, i+1) for odd i; a fan's is (i+1, i+2, 0).
  std::vector<std::array<std::size_t, 3>> corners;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    for (std::size_t i = 0; i + 2 < order.size(); i += 3) {
      corners.push_back({order[i], order[i + 1], order[i + 2]});
    }
  } else {
    for (std::size_t i = 0; i + 2 < order.size(); ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        corners.push_back({order[i + 1], order[i + 2], order[0]});
      } else if (i % 2 == 0) {
        corners.push_back({order[i], order[i + 1], order[i + 2]});
      } else {
        corners.push_back({order[i], order[i + 2], order[i + 1]});
      }
    }
  }
  const auto vec3At = [](const AccessorValues& a, std::size_t i) {
    return glm::dvec3(a.at(i, 0), a.at(i, 1), a.at(i, 2));
  };
  for (const auto& c : corners) {
    std::array<glm::dvec3, 3> t;
    for (int k = 0; k < 3; ++k) t[std::size_t(k)] = vec3At(v, c[std::size_t(k)]);
    out.positions.push_back(t);
    if (n.count > 0) {
      for (int k = 0; k < 3; ++k) t[std::size_t(k)] = vec3At(n, c[std::size_t(k)]);
      out.normals.push_back(t);
      if (tangent.count > 0) {
        std::array<glm::dvec4, 3> tg;
        for (int k = 0; k < 3; ++k) {
          const std::size_t i = c[std::size_t(k)];
          tg[std::size_t(k)] =
              glm::dvec4(tangent.at(i, 0), tangent.at(i, 1), tangent.at(i, 2), tangent.at(i, 3));
        }
        out.tangents.push_back(tg);
      }
    }
    // glTF's v runs down the image; the renderer's textures have t = 1 at the top row.
    const auto corners = [&](const AccessorValues& a) {
      std::array<glm::vec2, 3> u;
      for (int k = 0; k < 3; ++k) {
        const std::size_t i = c[std::size_t(k)];
        u[std::size_t(k)] = glm::vec2(float(a.at(i, 0)), float(1.0 - a.at(i, 1)));
      }
      return u;
    };
    if (uv.count > 0) out.uvs.push_back(corners(uv));
    if (uv1.count > 0) out.uvs1.push_back(corners(uv1));
  }
}

const std::vector<LocalPrimitive>& MeshReader::primitives(std::size_t mesh) {
  const auto found = decoded_.find(mesh);
  if (found != decoded_.end()) return found->second;
  std::vector<LocalPrimitive> out;
  const tinygltf::Mesh& m = model_.meshes[mesh];
  for (std::size_t i = 0; i < m.primitives.size(); ++i) {
    LocalPrimitive p;
    decode(m.primitives[i], indexed("meshes", mesh) + ".primitives[" + std::to_string(i) + "]", p);
    out.push_back(std::move(p));
  }
  return decoded_.emplace(mesh, std::move(out)).first->second;
}

void MeshReader::emit(int mesh, const std::string& where, const glm::dmat4& world,
                      const MaterialSlot& slot, Scene& scene) {
  if (mesh < 0 || std::size_t(mesh) >= model_.meshes.size()) {
    context_.fail(where, "mesh " + std::to_string(mesh) + " out of range (the file has " +
                             std::to_string(model_.meshes.size()) + ")");
  }
  // Normals by the inverse transpose; a transform that mirrors reverses the winding, which
  // the swap of two corners restores (the specification's clockwise front faces there).
  const glm::dmat3 linear(world);
  const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(linear));
  const bool mirrors = glm::determinant(linear) < 0.0;
  for (const LocalPrimitive& p : primitives(std::size_t(mesh))) {
    const auto [material, uvSet] = slot(p.material, p.where);
    // The set the material's textures read; TEXCOORD_0 where the primitive lacks it (warned).
    if (uvSet == 1 && p.uvs1.empty()) {
      context_.warnOnce("texcoord missing", p.where + ".attributes",
                        "the material's textures read TEXCOORD_1, which the primitive lacks: "
                        "TEXCOORD_0 is used");
    }
    const std::vector<std::array<glm::vec2, 3>>& uvs =
        uvSet == 1 && !p.uvs1.empty() ? p.uvs1 : p.uvs;
    reserveGeometric(scene.triangles, scene.triangles.size() + p.positions.size());
    for (std::size_t i = 0; i < p.positions.size(); ++i) {
      std::array<glm::dvec3, 3> n{};
      std::array<glm::vec2, 3> uv{};
      std::array<uint, 3> tangents{};
      Triangle t{};
      vec3* corners[3] = {&t.v0, &t.v1, &t.v2};
      for (std::size_t k = 0; k < 3; ++k) {
        *corners[k] = vec3(glm::dvec3(world * glm::dvec4(p.positions[i][k], 1.0)));
        if (!std::isfinite(corners[k]->x) || !std::isfinite(corners[k]->y) ||
            !std::isfinite(corners[k]->z)) {
          context_.fail(where, "the transform moves vertices beyond the range of 32-bit floats");
        }
        if (!p.normals.empty()) n[k] = normalMatrix * p.normals[i][k];
        if (!uvs.empty()) uv[k] = uvs[i][k];
        if (!p.tangents.empty()) {
          // A tangent is a direction in the surface: it moves with the transform itself, and a
          // mirroring transform turns the bitangent's sign (the frame's handedness).
          const glm::dvec4 tg = p.tangents[i][k];
          tangents[k] = packTangent(vec3(linear * glm::dvec3(tg)), float(mirrors ? -tg.w : tg.w));
        }
      }
      if (mirrors) {
        std::swap(t.v1, t.v2);
        std::swap(n[1], n[2]);
        std::swap(uv[1], uv[2]);
        std::swap(tangents[1], tangents[2]);
      }
      t.material = material;
      // The renderer's geometric normal is the float cross product normalized: a triangle too
      // small or too large for it (its square length below float's normal range, or beyond
      // it) has none, and is dropped as a zero-area triangle is.
      const vec3 ng = glm::cross(t.v1 - t.v0, t.v2 - t.v0);
      const float length2 = glm::dot(ng, ng);
      if (!(length2 >= std::numeric_limits<float>::min() && std::isfinite(length2))) {
        ++dropped_;
        continue;
      }
      const Appended a =
          appendTriangle(scene, t, p.normals.empty() ? nullptr : &n, uvs.empty() ? nullptr : &uv);
      if (a == Appended::kZeroArea) ++dropped_;
      if (a == Appended::kAdded && !p.tangents.empty()) {
        TriangleNormals& added = scene.normals.back();
        added.tangent0 = tangents[0];
        added.tangent1 = tangents[1];
        added.tangent2 = tangents[2];
      }
      if (a == Appended::kTooMany) {
        context_.fail(where, "too many triangles in the scene (at most 4294967295)");
      }
    }
  }
}

}  // namespace pt::gltf
