// Where glTF's KHR_materials_sheen and the clear coat's own normal live in a Material
// (kMaterialGltf with kGltfSheen or kGltfCoatNormal in nSamples), in the fields the
// metallic-roughness material leaves free: the sheen colour in eta.z, g and maxDepth (a float's
// bits), the sheen roughness in nSamples' high 16 bits (0 to 1 in steps of 1 / 65535; the
// kGltf* flags keep the low 16), the coat's shading normal in reserved1 (octahedral.h, in the
// local shading frame of the base: z is the base's shading normal). Written by the glTF reader,
// by texture.h at a hit and by path_vertex.h (the coat normal); read by bsdf.h.
#ifndef PT_GLTF_MATERIAL_FIELDS_H
#define PT_GLTF_MATERIAL_FIELDS_H

#include "octahedral.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

PT_INLINE vec3 gltfSheenColour(Material m) {
  return vec3(m.eta.z, m.g, uintBitsToFloat(m.maxDepth));
}
PT_INLINE Material gltfWithSheenColour(Material m, vec3 c) {
  m.eta.z = c.x;
  m.g = c.y;
  m.maxDepth = floatBitsToUint(c.z);
  return m;
}
PT_INLINE float gltfSheenRoughness(Material m) {
  return float(m.nSamples >> 16u) * (1.0f / 65535.0f);
}
PT_INLINE Material gltfWithSheenRoughness(Material m, float roughness) {
  uint q = uint(clamp(roughness, 0.0f, 1.0f) * 65535.0f + 0.5f);
  m.nSamples = (m.nSamples & 0xFFFFu) | (q << 16u);
  return m;
}
// The coat's normal n (unit, in the base's local frame), flagged kGltfCoatNormal.
PT_INLINE vec3 gltfCoatNormal(Material m) {
  return unpackOctahedral(m.reserved1);
}
PT_INLINE Material gltfWithCoatNormal(Material m, vec3 n) {
  m.reserved1 = packOctahedral(n);
  m.nSamples |= kGltfCoatNormal;
  return m;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_GLTF_MATERIAL_FIELDS_H
