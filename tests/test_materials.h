// Materials of bsdf.h's types as the scene reader fills them (struct Material, alphas already
// remapped), for the tests.
#pragma once

#include "common/shared.h"
#include "gltf_material_fields.h"
#include "sanitizer_build.h"

// Sanitized builds (ASan + UBSan at -O1) and unoptimized ones run the sampling tests
// (bsdf_test.cpp, materials_test.cpp) on fewer samples: the tests keep their significance, they
// only lose some power.
#if PT_TEST_SANITIZED || !defined(__OPTIMIZE__)
#define PT_BSDF_TEST_SLOW 1
#endif

namespace pt::test {

inline Material conductor(float alphaX, float alphaY, vec3 eta = vec3(0.2f, 0.92f, 1.1f),
                          vec3 k = vec3(3.9f, 2.45f, 2.14f)) {
  Material m{};
  m.type = kMaterialConductor;
  m.alphaX = alphaX;
  m.alphaY = alphaY;
  m.eta = eta;
  m.k = k;
  return m;
}
// eta 0, k 1: Fresnel reflectance exactly 1 at every angle (a lossless ideal conductor).
inline Material whiteConductor(float alphaX, float alphaY) {
  return conductor(alphaX, alphaY, vec3(0.0f), vec3(1.0f));
}
inline Material dielectric(float alphaX, float alphaY, float eta) {
  Material m{};
  m.type = kMaterialDielectric;
  m.alphaX = alphaX;
  m.alphaY = alphaY;
  m.eta = vec3(eta);
  return m;
}
inline Material thinDielectric(float eta) {
  Material m{};
  m.type = kMaterialThinDielectric;
  m.eta = vec3(eta);
  return m;
}
inline Material diffuseTransmission(vec3 r, vec3 t) {
  Material m{};
  m.type = kMaterialDiffuseTransmission;
  m.reflectance = r;
  m.transmittance = t;
  return m;
}
// glTF's metallic-roughness material as the glTF reader fills it (alpha = roughness^2).
inline Material gltfMaterial(vec3 baseColor, float metallic, float roughness, float ior = 1.5f) {
  Material m{};
  m.type = kMaterialGltf;
  m.reflectance = baseColor;
  m.thickness = metallic;
  m.eta = vec3(ior, 0.0f, 0.0f);
  m.alphaX = m.alphaY = roughness * roughness;
  return m;
}
// glTF's material with its extensions (KHR_materials_transmission, _volume, _clearcoat,
// _specular, _sheen) as the glTF reader fills them, and the coat's own normal as a hit gives it.
struct GltfLayerParams {
  vec3 base = vec3(0.8f, 0.4f, 0.1f);
  float metallic = 0.0f;
  float roughness = 0.5f;
  float ior = 1.5f;
  float transmission = 0.0f;
  bool volume = false;  // the transmission refracts (thicknessFactor > 0)
  float clearcoat = 0.0f;
  float clearcoatRoughness = 0.0f;
  float specular = 1.0f;
  vec3 specularColour = vec3(1.0f);
  vec3 sheenColour = vec3(0.0f);  // 0: no sheen
  float sheenRoughness = 0.0f;
  vec3 coatNormal = vec3(0.0f);  // 0: none (the base's); else in the base's local frame
};
inline Material gltfLayered(const GltfLayerParams& p) {
  Material m = gltfMaterial(p.base, p.metallic, p.roughness, p.ior);
  m.nSamples = kGltfTransmission | kGltfSpecular | (p.volume ? kGltfVolume : 0u) |
               (p.clearcoat > 0.0f ? kGltfClearcoat : 0u);
  m.transmittance = vec3(p.transmission, p.clearcoat, p.clearcoatRoughness * p.clearcoatRoughness);
  m.k = p.specularColour;
  m.eta.y = p.specular;
  if (p.sheenColour != vec3(0.0f)) {
    m.nSamples |= kGltfSheen;
    m = gltfWithSheenRoughness(gltfWithSheenColour(m, p.sheenColour), p.sheenRoughness);
  }
  if (p.coatNormal != vec3(0.0f)) m = gltfWithCoatNormal(m, normalize(p.coatNormal));
  return m;
}
}  // namespace pt::test
