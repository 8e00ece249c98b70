// A unit vector in 30 bits: its octahedral coordinates (the vector over its L1 norm, the lower
// half folded out over the diagonals), 15 bits each, x in bits 15-29 and y in bits 0-14; within
// 2e-4 radians. For packed tangents (texture.h) and glTF's coat normal (gltf_material_fields.h).
#ifndef PT_OCTAHEDRAL_H
#define PT_OCTAHEDRAL_H

#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

PT_INLINE uint octahedralQuantized(float v) {
  return uint(clamp(v, -1.0f, 1.0f) * 16383.0f + 16383.5f);
}
// v of a finite, non-zero length (need not be unit).
PT_INLINE uint packOctahedral(vec3 v) {
  vec3 o = v / (abs(v.x) + abs(v.y) + abs(v.z));
  float x = o.x;
  float y = o.y;
  if (o.z < 0.0f) {
    x = (1.0f - abs(o.y)) * (o.x >= 0.0f ? 1.0f : -1.0f);
    y = (1.0f - abs(o.x)) * (o.y >= 0.0f ? 1.0f : -1.0f);
  }
  return octahedralQuantized(x) << 15u | octahedralQuantized(y);
}
// The unit vector of packOctahedral's bits (bits 30 and 31 ignored).
PT_INLINE vec3 unpackOctahedral(uint packed) {
  float x = float((packed >> 15u) & 0x7FFFu) / 16383.0f - 1.0f;
  float y = float(packed & 0x7FFFu) / 16383.0f - 1.0f;
  vec3 t = vec3(x, y, 1.0f - abs(x) - abs(y));
  if (t.z < 0.0f) {
    t.x = (1.0f - abs(y)) * (x >= 0.0f ? 1.0f : -1.0f);
    t.y = (1.0f - abs(x)) * (y >= 0.0f ? 1.0f : -1.0f);
  }
  return normalize(t);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_OCTAHEDRAL_H
