// Textures (struct TextureNode, shared_types.h), evaluated as pbrt-v4 evaluates its imagemap,
// checkerboard, constant, scale and mix textures, and the material parameters they replace
// at a hit. Shared by the CPU reference and the shader, so that both filter the same texels
// with the same operations and the images agree as they do without textures.
//
// What the functions read: in C++ a TextureTables (the scene's arrays); in GLSL the includer
// defines textureNodeAt(i), imageWordAt(i), materialTexturesAt(i) and uvsAt(i) over its
// buffers. PT_TEXTURES_PARAM / PT_TEXTURES_ARG pass the tables in C++ and nothing in GLSL.
//
// Where we differ from pbrt-v4: it filters image textures over the ray's footprint (MIP maps,
// trilinear or EWA, from ray differentials) and its checkerboard over the same footprint; we
// look up the full-resolution image (bilinear or nearest) and the sharp checkerboard at the
// hit point. Both converge to the same image where the pixel filter averages many samples over
// the footprint; at low sample counts ours is noisier where a texture has detail below a pixel
// (docs/textures.md).
#ifndef PT_TEXTURE_H
#define PT_TEXTURE_H

#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {

struct TextureTables {
  const TextureNode* nodes = nullptr;
  const uint* words = nullptr;  // the image buffer: texels and decoding tables
  const MaterialTextures* materials = nullptr;
  const TriangleUVs* uvs = nullptr;  // by Triangle::primitive
};
#define PT_TEXTURES_PARAM const TextureTables &tables,
#define PT_TEXTURES_ARG tables,
inline TextureNode textureNodeAt(const TextureTables& tables, uint i) {
  return tables.nodes[i];
}
inline uint imageWordAt(const TextureTables& tables, uint i) {
  return tables.words[i];
}
inline MaterialTextures materialTexturesAt(const TextureTables& tables, uint i) {
  return tables.materials[i];
}
inline TriangleUVs uvsAt(const TextureTables& tables, uint i) {
  return tables.uvs[i];
}
#else
#define PT_TEXTURES_PARAM
#define PT_TEXTURES_ARG
#endif

#ifndef PT_TEXTURE_LOOP_TICK
#define PT_TEXTURE_LOOP_TICK()
#endif
// The kTextureUses* bits of what to evaluate: the shader's specialization constant; the CPU
// evaluates what the data says.
#ifndef PT_TEXTURE_FEATURES
#define PT_TEXTURE_FEATURES kTextureUsesAll
#endif
#define PT_TEXTURE_USES(bit) ((PT_TEXTURE_FEATURES & (bit)) != 0u)

// ---- Texture coordinates ----------------------------------------------------------------

// The hit's (u, v), interpolated with the barycentric weights b of v0, v1, v2 in pbrt-v4's order.
PT_INLINE vec2 interpolatedUV(TriangleUVs t, vec3 b) {
  return b.x * t.uv0 + b.y * t.uv1 + b.z * t.uv2;
}

// pbrt-v4's UVMapping: (s, t) = (uscale u + udelta, vscale v + vdelta).
PT_INLINE vec2 mapUV(vec4 mapping, vec2 uv) {
  return vec2(mapping.x * uv.x + mapping.z, mapping.y * uv.y + mapping.w);
}

// ---- Image lookups ------------------------------------------------------------------------

// A texel coordinate folded into [0, size) by the wrap mode, or -1 (kWrapBlack, outside).
// GLSL leaves % undefined for negative operands, so only non-negative ones are used.
PT_INLINE int wrapTexel(int p, int size, uint wrap) {
  if (p >= 0 && p < size) return p;
  if (wrap == kWrapRepeat) {
    return p >= 0 ? p % size : (size - 1) - ((-(p + 1)) % size);
  }
  if (wrap == kWrapClamp) return p < 0 ? 0 : size - 1;
  return -1;
}

// A decoded 8-bit channel: the image's table of 256 linear values (its colour encoding).
PT_INLINE float decodeByte(PT_TEXTURES_PARAM uint decode, uint byteValue) {
  return uintBitsToFloat(imageWordAt(PT_TEXTURES_ARG decode + byteValue));
}

// Texel (x, y) of the image, as linear (R, G, B, A): grey repeated in R, G and B, and alpha 1
// where the image has none. Zero for kWrapBlack outside the image.
PT_INLINE vec4 imageTexel(PT_TEXTURES_PARAM TextureNode node, int x, int y) {
  uint wrap = (node.flags >> 4u) & 0xFu;
  x = wrapTexel(x, int(node.width), wrap);
  y = wrapTexel(y, int(node.height), wrap);
  if (x < 0 || y < 0) return vec4(0.0f);
  uint index = uint(y) * node.width + uint(x);
  uint format = node.flags & 0xFu;
  if (format == kTexel8) {
    uint w = imageWordAt(PT_TEXTURES_ARG node.texels + index);
    return vec4(decodeByte(PT_TEXTURES_ARG node.decode, w & 0xFFu),
                decodeByte(PT_TEXTURES_ARG node.decode, (w >> 8u) & 0xFFu),
                decodeByte(PT_TEXTURES_ARG node.decode, (w >> 16u) & 0xFFu),
                decodeByte(PT_TEXTURES_ARG node.decode, w >> 24u));
  }
  if (format == kTexelFloat1) {
    float g = uintBitsToFloat(imageWordAt(PT_TEXTURES_ARG node.texels + index));
    return vec4(g, g, g, 1.0f);
  }
  uint stride = format == kTexelFloat3 ? 3u : 4u;
  uint at = node.texels + stride * index;
  return vec4(uintBitsToFloat(imageWordAt(PT_TEXTURES_ARG at)),
              uintBitsToFloat(imageWordAt(PT_TEXTURES_ARG at + 1u)),
              uintBitsToFloat(imageWordAt(PT_TEXTURES_ARG at + 2u)),
              stride == 4u ? uintBitsToFloat(imageWordAt(PT_TEXTURES_ARG at + 3u)) : 1.0f);
}

// A coordinate in texels made safe to convert to int: NaN to 0, the rest within +-2^24 (beyond
// that a float has no fraction left to filter).
PT_INLINE float safeTexelCoordinate(float x) {
  return x >= -16777216.0f && x <= 16777216.0f
             ? x
             : (x > 0.0f ? 16777216.0f : (x < 0.0f ? -16777216.0f : 0.0f));
}

// std::round (halves away from zero), which GLSL's round does not promise.
PT_INLINE float roundHalfAway(float x) {
  float t = trunc(x);
  return abs(x - t) >= 0.5f ? t + (x < 0.0f ? -1.0f : 1.0f) : t;
}

// The image's value at (s, t) in [0, 1]^2 (t = 1 at row 0, as pbrt-v4's ImageTexture flips t),
// filtered as the node says: pbrt-v4's Image::Bilerp (texel centres at half-integers) or the
// nearest texel. Float textures take the channel pbrt-v4's MIPMap takes (kFloatChannel*) into
// all three; pbrt-v4's "scale" and "invert" are applied last.
PT_INLINE vec3 imageLookup(PT_TEXTURES_PARAM TextureNode node, vec2 st) {
  float x = safeTexelCoordinate(st.x * float(node.width) - 0.5f);
  float y = safeTexelCoordinate((1.0f - st.y) * float(node.height) - 0.5f);
  uint channel = (node.flags >> 12u) & 0xFu;
  bool isFloat = (node.flags & kTextureFloat) != 0u;
  vec3 v;
  if (((node.flags >> 8u) & 0xFu) == kTexturePoint) {
    vec4 c = imageTexel(PT_TEXTURES_ARG node, int(roundHalfAway(x)), int(roundHalfAway(y)));
    v = isFloat ? vec3(c.x) : vec3(c);
  } else {
    float fx = floor(x);
    float fy = floor(y);
    int xi = int(fx);
    int yi = int(fy);
    float dx = x - fx;
    float dy = y - fy;
    vec4 c = (1.0f - dx) * (1.0f - dy) * imageTexel(PT_TEXTURES_ARG node, xi, yi) +
             dx * (1.0f - dy) * imageTexel(PT_TEXTURES_ARG node, xi + 1, yi) +
             (1.0f - dx) * dy * imageTexel(PT_TEXTURES_ARG node, xi, yi + 1) +
             dx * dy * imageTexel(PT_TEXTURES_ARG node, xi + 1, yi + 1);
    if (!isFloat) {
      v = vec3(c);
    } else if (channel == kFloatChannelAverage) {
      v = vec3((c.x + c.y + c.z) / 3.0f);
    } else if (channel == kFloatChannelAlpha) {
      v = vec3(c.w);
    } else {
      v = vec3(c.x);
    }
  }
  v = node.value * v;
  if ((node.flags & kTextureInvert) != 0u) v = max(vec3(1.0f) - v, vec3(0.0f));
  return v;
}

// pbrt-v4's 2D checkerboard without a filter footprint: the weight of tex2, 0 on the squares
// where floor(s) + floor(t) is even (tex1), 1 on the others.
PT_INLINE float checkerboardWeight(vec2 st) {
  float s = floor(safeTexelCoordinate(st.x));
  float t = floor(safeTexelCoordinate(st.y));
  return ((int(s) + int(t)) & 1) == 0 ? 0.0f : 1.0f;
}

// ---- Evaluation --------------------------------------------------------------------------

// The value of the texture whose program starts at node `first`, at texture coordinates uv.
PT_INLINE vec3 evalTexture(PT_TEXTURES_PARAM uint first, vec2 uv) {
  TextureNode head = textureNodeAt(PT_TEXTURES_ARG first);
  // The common case, one leaf, without the stack.
  if (head.count == 1u || !PT_TEXTURE_USES(kTextureUsesPrograms)) {
    if (PT_TEXTURE_USES(kTextureUsesImages) && head.type == kTextureImage) {
      return imageLookup(PT_TEXTURES_ARG head, mapUV(head.mapping, uv));
    }
    return head.value;
  }
  vec3 stack[kTextureStackSize];
  uint top = 0u;  // values on the stack
  for (uint i = 0u; i < head.count; ++i) {
    PT_TEXTURE_LOOP_TICK();
    TextureNode node = i == 0u ? head : textureNodeAt(PT_TEXTURES_ARG first + i);
    vec3 v;
    if (node.type == kTextureConstant) {
      v = node.value;
    } else if (PT_TEXTURE_USES(kTextureUsesImages) && node.type == kTextureImage) {
      v = imageLookup(PT_TEXTURES_ARG node, mapUV(node.mapping, uv));
    } else if (node.type == kTextureCheckerboard) {
      top -= 2u;
      v = checkerboardWeight(mapUV(node.mapping, uv)) == 0.0f ? stack[top] : stack[top + 1u];
    } else if (node.type == kTextureScale) {
      top -= 2u;
      float scale = stack[top + 1u].x;
      v = scale == 0.0f ? vec3(0.0f) : stack[top] * scale;
    } else {  // kTextureMix
      top -= 3u;
      float amount = stack[top + 2u].x;
      v = (1.0f - amount) * stack[top] + amount * stack[top + 1u];
    }
    stack[top] = v;
    ++top;
  }
  return stack[0];
}

// A float texture's value (its first channel).
PT_INLINE float evalFloatTexture(PT_TEXTURES_PARAM uint first, vec2 uv) {
  return evalTexture(PT_TEXTURES_ARG first, uv).x;
}

// ---- Materials ----------------------------------------------------------------------------

// Whether a material reads any texture (and so the hit's texture coordinates).
PT_INLINE bool anyTexture(MaterialTextures t) {
  return t.reflectance != kNoTexture || t.transmittance != kNoTexture ||
         t.uRoughness != kNoTexture || t.vRoughness != kNoTexture || t.eta != kNoTexture ||
         t.k != kNoTexture || t.displacement != kNoTexture || t.alpha != kNoTexture ||
         t.thickness != kNoTexture || t.g != kNoTexture;
}

// The material's parameters at texture coordinates uv: each parameter that has a texture takes
// the texture's value there, as pbrt-v4's materials evaluate theirs (reflectances clamped to
// [0, 1] as its albedo spectra are; roughness remapped to alpha where the material asks;
// diffusetransmission's scale; a conductor given by its reflectance takes eta = 1 and pbrt-v4's
// k). Parameters without a texture keep the host's values.
PT_INLINE Material resolveMaterial(PT_TEXTURES_PARAM Material m, MaterialTextures t, vec2 uv) {
  if (PT_TEXTURE_USES(kTextureUsesReflectance) && t.reflectance != kNoTexture) {
    vec3 r = clamp(evalTexture(PT_TEXTURES_ARG t.reflectance, uv), vec3(0.0f), vec3(1.0f));
    if (m.type == kMaterialConductor) {
      // pbrt-v4's ConductorMaterial with "reflectance": eta 1, k = 2 sqrt(r) / sqrt(1 - r).
      r = clamp(r, vec3(0.0f), vec3(0.9999f));
      m.eta = vec3(1.0f);
      m.k = 2.0f * sqrt(r) / sqrt(vec3(1.0f) - r);
    } else if (m.type == kMaterialDiffuseTransmission) {
      m.reflectance = clamp(t.scale * r, vec3(0.0f), vec3(1.0f));
    } else {
      m.reflectance = r;
    }
  }
  if (PT_TEXTURE_USES(kTextureUsesTransmittance) && t.transmittance != kNoTexture) {
    vec3 r = clamp(evalTexture(PT_TEXTURES_ARG t.transmittance, uv), vec3(0.0f), vec3(1.0f));
    m.transmittance =
        m.type == kMaterialDiffuseTransmission ? clamp(t.scale * r, vec3(0.0f), vec3(1.0f)) : r;
  }
  if (PT_TEXTURE_USES(kTextureUsesEtaK) && t.eta != kNoTexture)
    m.eta = evalTexture(PT_TEXTURES_ARG t.eta, uv);
  if (PT_TEXTURE_USES(kTextureUsesEtaK) && t.k != kNoTexture)
    m.k = evalTexture(PT_TEXTURES_ARG t.k, uv);
  bool remap = (t.flags & kRemapRoughness) != 0u;
  if (PT_TEXTURE_USES(kTextureUsesRoughness) && t.uRoughness != kNoTexture) {
    float r = max(evalFloatTexture(PT_TEXTURES_ARG t.uRoughness, uv), 0.0f);
    m.alphaX = remap ? sqrt(r) : r;
  }
  if (PT_TEXTURE_USES(kTextureUsesRoughness) && t.vRoughness != kNoTexture) {
    float r = max(evalFloatTexture(PT_TEXTURES_ARG t.vRoughness, uv), 0.0f);
    m.alphaY = remap ? sqrt(r) : r;
  }
  // coateddiffuse's medium: pbrt-v4 keeps the thickness at least the smallest normal float and
  // clamps g to [-1, 1]; we keep g inside (-1, 1), where Henyey-Greenstein is not a delta.
  if (PT_TEXTURE_USES(kTextureUsesMedium) && t.thickness != kNoTexture) {
    m.thickness = max(evalFloatTexture(PT_TEXTURES_ARG t.thickness, uv), 1.17549435e-38f);
  }
  if (PT_TEXTURE_USES(kTextureUsesMedium) && t.g != kNoTexture)
    m.g = clamp(evalFloatTexture(PT_TEXTURES_ARG t.g, uv), -0.999f, 0.999f);
  return m;
}

// ---- Bump maps ---------------------------------------------------------------------------

// Two unit vectors completing v (unit) to an orthonormal basis (pbrt-v4's CoordinateSystem).
PT_INLINE void coordinateSystem(vec3 v, PT_OUT(vec3) a, PT_OUT(vec3) b) {
  float sign = v.z >= 0.0f ? 1.0f : -1.0f;
  float k = -1.0f / (sign + v.z);
  float c = v.x * v.y * k;
  a = vec3(1.0f + sign * v.x * v.x * k, sign * c, -sign * v.x);
  b = vec3(c, sign + v.y * v.y * k, -v.y);
}

// The shading normal that pbrt-v4's BumpMap gives a triangle (vertices of tri, texture
// coordinates t, the hit's uv) whose displacement is the float texture `displacement`: the
// surface's partial derivatives dp/du and dp/dv (pbrt-v4's Triangle: from the vertices and
// their (u, v), a coordinate system about the normal where (u, v) are degenerate) and, with
// vertex normals (hasNormals, the normals at the vertices and ns interpolated), the shading
// frame's tangents and dn/du, dn/dv as pbrt-v4 derives them; then the displacement's finite
// differences along u and v move them, and the normal of the moved pair, turned to the side of
// ng (pbrt-v4's FaceForward), is the bumped one. pbrt-v4 steps by half the ray footprint's
// extent in (u, v); we have no ray differentials and step by its fallback, 0.0005. Where both
// differences are exactly zero (a constant displacement) the surface is left as it is.
PT_INLINE vec3 bumpedNormal(PT_TEXTURES_PARAM uint displacement, Triangle tri, TriangleUVs t,
                            vec2 uv, vec3 ng, vec3 ns, bool hasNormals, TriangleNormals normals) {
  const float kStep = 0.0005f;
  float displace = evalFloatTexture(PT_TEXTURES_ARG displacement, uv);
  float uDisplace = evalFloatTexture(PT_TEXTURES_ARG displacement, uv + vec2(kStep, 0.0f));
  float vDisplace = evalFloatTexture(PT_TEXTURES_ARG displacement, uv + vec2(0.0f, kStep));
  if (uDisplace == displace && vDisplace == displace) return ns;
  // dp/du and dp/dv (pbrt-v4's Triangle::InteractionFromIntersection).
  vec2 duv02 = t.uv0 - t.uv2;
  vec2 duv12 = t.uv1 - t.uv2;
  vec3 dp02 = tri.v0 - tri.v2;
  vec3 dp12 = tri.v1 - tri.v2;
  float determinant = duv02.x * duv12.y - duv02.y * duv12.x;
  vec3 dpdu = vec3(0.0f);
  vec3 dpdv = vec3(0.0f);
  bool degenerate = abs(determinant) < 1e-9f;
  if (!degenerate) {
    float invDet = 1.0f / determinant;
    dpdu = (duv12.y * dp02 - duv02.y * dp12) * invDet;
    dpdv = (duv02.x * dp12 - duv12.x * dp02) * invDet;
  }
  vec3 c = cross(dpdu, dpdv);
  if (degenerate || dot(c, c) == 0.0f) {
    coordinateSystem(normalize(cross(tri.v2 - tri.v0, tri.v1 - tri.v0)), dpdu, dpdv);
  }
  // The shading frame: ns with the tangent dp/du made perpendicular, and dn/du, dn/dv.
  vec3 n = ng;
  vec3 dndu = vec3(0.0f);
  vec3 dndv = vec3(0.0f);
  if (hasNormals) {
    n = ns;
    vec3 ss = dpdu;
    vec3 ts = cross(ns, ss);
    if (dot(ts, ts) > 0.0f) {
      ss = cross(ts, ns);
    } else {
      coordinateSystem(ns, ss, ts);
    }
    dpdu = ss;
    dpdv = ts;
    vec3 dn1 = normals.n0 - normals.n2;
    vec3 dn2 = normals.n1 - normals.n2;
    if (abs(determinant) < 1e-32f) {
      vec3 dn = cross(normals.n2 - normals.n0, normals.n1 - normals.n0);
      if (dot(dn, dn) != 0.0f) coordinateSystem(normalize(dn), dndu, dndv);
    } else {
      float invDet = 1.0f / determinant;
      dndu = (duv12.y * dn1 - duv02.y * dn2) * invDet;
      dndv = (duv02.x * dn2 - duv12.x * dn1) * invDet;
    }
  }
  vec3 bumpedU = dpdu + ((uDisplace - displace) / kStep) * n + displace * dndu;
  vec3 bumpedV = dpdv + ((vDisplace - displace) / kStep) * n + displace * dndv;
  vec3 bumped = cross(bumpedU, bumpedV);
  float len2 = dot(bumped, bumped);
  if (!(len2 > 0.0f) || !(len2 < 3.0e38f)) return ns;
  bumped = bumped / sqrt(len2);
  return dot(bumped, ng) < 0.0f ? -bumped : bumped;
}

// ---- Alpha cut-outs -----------------------------------------------------------------------

// The number a ray's alpha tests compare alpha with, one per ray (for all the surfaces it
// meets, as pbrt-v4's HashFloat(r.o, r.d) is). pbrt-v4 hashes the ray itself; the backends'
// rays can differ in their last bits, which would part their decisions, so the number comes
// from what both share exactly: for a path's ray, a hash of its pixel, sample and scattering
// events so far; for a shadow ray, a hash of the light sample's two numbers.
PT_INLINE float pathAlphaRandom(uvec2 pixel, uint sampleIndex, uint depth, uint seed) {
  uvec4 h =
      pcg4d(uvec4(pixel.x, pixel.y, sampleIndex, (0xA1FA0000u + depth) ^ (seed * 0x9E3779B9u)));
  return float(h.x >> 8u) * (1.0f / 16777216.0f);
}
PT_INLINE float shadowAlphaRandom(vec2 uLight) {
  uvec4 h = pcg4d(uvec4(floatBitsToUint(uLight.x), floatBitsToUint(uLight.y), 0xA1FAu, 0x5EEDu));
  return float(h.x >> 8u) * (1.0f / 16777216.0f);
}

// pbrt-v4's alpha test (GeometricPrimitive::Intersect) of a hit with barycentric weights b on
// a triangle of `material` (Triangle::primitive `primitive`) by a ray whose number is u (above):
// the surface is there where its alpha texture is 1 or more (or it has none), missing where it
// is 0 or less, and in between there for the rays whose number is at most alpha.
PT_INLINE bool alphaKeepsHit(PT_TEXTURES_PARAM uint material, uint primitive, vec3 b, float u) {
  uint alpha = materialTexturesAt(PT_TEXTURES_ARG material).alpha;
  if (alpha == kNoTexture) return true;
  float a =
      evalFloatTexture(PT_TEXTURES_ARG alpha, interpolatedUV(uvsAt(PT_TEXTURES_ARG primitive), b));
  if (a >= 1.0f) return true;
  if (a <= 0.0f) return false;
  return u <= a;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_TEXTURE_H
