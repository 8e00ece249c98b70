// The helpers every scene reader shares (reader_helpers.h): material defaults, exact
// rotations, appending triangles. The readers themselves are elsewhere.
#include "scene/reader_helpers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include <glm/geometric.hpp>

namespace pt {

std::pair<double, double> cosSinDegrees(double degrees) {
  const double reduced = std::fmod(degrees, 360.0);  // exact
  if (std::fmod(reduced, 90.0) == 0.0) {
    switch (static_cast<int>(reduced < 0 ? reduced + 360.0 : reduced)) {
      case 0:
        return {1.0, 0.0};
      case 90:
        return {0.0, 1.0};
      case 180:
        return {-1.0, 0.0};
      case 270:
        return {0.0, -1.0};
      default:
        break;
    }
  }
  const double radians = reduced * (3.14159265358979323846 / 180.0);
  return {std::cos(radians), std::sin(radians)};
}

Material defaultMaterial(uint type) {
  Material m{};  // every field a type does not use stays zero
  m.type = type;
  switch (type) {
    case kMaterialDiffuse:
      m.reflectance = vec3(0.8f);
      break;
    case kMaterialMirror:
      m.reflectance = vec3(1.0f);
      break;
    case kMaterialConductor:
      // pbrt-v4's default is copper ("metal-Cu-eta", "metal-Cu-k"): these are RGB
      // approximations of those spectra.
      m.eta = vec3(0.200438f, 0.924033f, 1.10221f);
      m.k = vec3(3.91295f, 2.45285f, 2.14219f);
      break;
    case kMaterialDielectric:
    case kMaterialThinDielectric:
      m.eta = vec3(1.5f, 0.0f, 0.0f);
      break;
    case kMaterialDiffuseTransmission:
      m.reflectance = vec3(0.25f);
      m.transmittance = vec3(0.25f);
      break;
    case kMaterialCoatedDiffuse:
      m.reflectance = vec3(0.5f);
      m.eta = vec3(1.5f, 0.0f, 0.0f);
      m.thickness = 0.01f;
      m.maxDepth = 10;
      m.nSamples = 1;
      break;
    case kMaterialInterface:
      break;  // no surface: nothing to set
    default:
      PT_CHECK(false, "unknown material type");
  }
  return m;
}

void setRoughness(Material& material, float uRoughness, float vRoughness, bool remap) {
  material.alphaX = remap ? std::sqrt(uRoughness) : uRoughness;
  material.alphaY = remap ? std::sqrt(vRoughness) : vRoughness;
}

void scaleDiffuseTransmission(Material& material, float scale) {
  material.reflectance = glm::clamp(material.reflectance * scale, 0.0f, 1.0f);
  material.transmittance = glm::clamp(material.transmittance * scale, 0.0f, 1.0f);
}

void setConductorReflectance(Material& material, vec3 reflectance) {
  material.eta = vec3(1.0f);
  for (int c = 0; c < 3; ++c) {
    // Clamped below 1 so that a white reflectance gives a large finite k (pbrt-v4's rule).
    const double r = std::clamp(static_cast<double>(reflectance[c]), 0.0, 0.9999);
    material.k[c] = static_cast<float>(2.0 * std::sqrt(r) / std::sqrt(1.0 - r));
  }
}

Appended appendTriangle(Scene& scene, Triangle t, const std::array<glm::dvec3, 3>* normals,
                        const std::array<glm::vec2, 3>* uvs) {
  const glm::dvec3 e1 = glm::dvec3(t.v1) - glm::dvec3(t.v0);
  const glm::dvec3 e2 = glm::dvec3(t.v2) - glm::dvec3(t.v0);
  if (!(glm::length(glm::cross(e1, e2)) > 1e-12 * glm::length(e1) * glm::length(e2))) {
    return Appended::kZeroArea;
  }
  if (scene.triangles.size() >= static_cast<std::size_t>(kNoEmitter)) return Appended::kTooMany;
  // A normal made unit; the geometric normal where it is zero or not finite.
  const auto unitNormal = [](glm::dvec3 n, vec3 ng) {
    const double len = glm::length(n);
    if (!(len > 0.0) || !std::isfinite(len)) return ng;
    const vec3 unit = vec3(n / len);
    return std::isfinite(unit.x) && std::isfinite(unit.y) && std::isfinite(unit.z) ? unit : ng;
  };
  const auto flatNormals = [](const Triangle& f) {
    const vec3 ng = glm::normalize(glm::cross(f.v1 - f.v0, f.v2 - f.v0));
    return TriangleNormals{ng, 0u, ng, 0u, ng, 0u};
  };
  t.emitter = kNoEmitter;
  t.primitive = static_cast<uint>(scene.triangles.size());
  scene.triangles.push_back(t);
  if (normals != nullptr && scene.normals.empty()) {
    // The first triangle with vertex normals: the triangles before it shade flat.
    for (std::size_t k = 0; k + 1 < scene.triangles.size(); ++k) {
      scene.normals.push_back(flatNormals(scene.triangles[k]));
    }
  }
  // The per-triangle arrays grow with the triangles' room (reserveGeometric).
  if (!scene.normals.empty() || normals != nullptr)
    reserveGeometric(scene.normals, scene.triangles.capacity());
  if (!scene.uvs.empty() || uvs != nullptr) reserveGeometric(scene.uvs, scene.triangles.capacity());
  if (normals != nullptr) {
    const vec3 ng = flatNormals(t).n0;
    const std::array<glm::dvec3, 3>& n = *normals;
    scene.normals.push_back(TriangleNormals{unitNormal(n[0], ng), 0u, unitNormal(n[1], ng), 0u,
                                            unitNormal(n[2], ng), 0u});
  } else if (!scene.normals.empty()) {
    scene.normals.push_back(flatNormals(t));
  }
  if (uvs != nullptr && scene.uvs.empty()) {
    // The first triangle with texture coordinates: the triangles before it take the defaults.
    scene.uvs.assign(scene.triangles.size() - 1, defaultTriangleUVs());
  }
  if (uvs != nullptr) {
    scene.uvs.push_back(TriangleUVs{(*uvs)[0], (*uvs)[1], (*uvs)[2], vec2(0.0f)});
  } else if (!scene.uvs.empty()) {
    scene.uvs.push_back(defaultTriangleUVs());
  }
  return Appended::kAdded;
}

}  // namespace pt
