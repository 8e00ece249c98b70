// The directional albedo E(cos theta_o, roughness) of the sheen lobe (sheen.h) without its
// colour: what KHR_materials_sheen's albedo scaling, 1 - max(sheenColor) E, takes from the
// layers below the sheen. Tabulated by our own quadrature of the lobe (tools/sheen-albedo.cpp,
// sheen_albedo_table.h) at kSheenAlbedoCos x kSheenAlbedoRoughness nodes, evenly spaced in the
// square root of the cosine (the albedo of a smooth sheen changes fastest at grazing angles) and
// in the roughness, and interpolated bilinearly. C++ reads the table as an array; the shader
// reads it from the scene's material buffer, after the materials (a large constant array costs
// lavapipe minutes of compilation), through sheenAlbedoNode(i), which its includer defines.
#ifndef PT_SHEEN_ALBEDO_H
#define PT_SHEEN_ALBEDO_H

#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

PT_CONST int kSheenAlbedoCos = 32;
PT_CONST int kSheenAlbedoRoughness = 32;

#ifdef __cplusplus
#include "sheen_albedo_table.h"

inline constexpr float kSheenAlbedo[kSheenAlbedoCos * kSheenAlbedoRoughness] = {
    PT_SHEEN_ALBEDO_TABLE};
inline float sheenAlbedoNode(int i) {
  return kSheenAlbedo[i];
}
#endif

PT_INLINE float sheenAlbedo(float cosThetaO, float roughness) {
  float x = sqrt(clamp(cosThetaO, 0.0f, 1.0f)) * float(kSheenAlbedoCos - 1);
  float y = clamp(roughness, 0.0f, 1.0f) * float(kSheenAlbedoRoughness - 1);
  int i = min(int(x), kSheenAlbedoCos - 2);
  int j = min(int(y), kSheenAlbedoRoughness - 2);
  float fx = x - float(i);
  float fy = y - float(j);
  int at = j * kSheenAlbedoCos + i;
  float low = mix(sheenAlbedoNode(at), sheenAlbedoNode(at + 1), fx);
  float high =
      mix(sheenAlbedoNode(at + kSheenAlbedoCos), sheenAlbedoNode(at + kSheenAlbedoCos + 1), fx);
  return mix(low, high, fy);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_SHEEN_ALBEDO_H
