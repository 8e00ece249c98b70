// Textures (struct TextureNode, shared_types.h), evaluated as pbrt-v4 evaluates its imagemap,
// checkerboard, constant, scale and mix textures, and the material parameters they replace
// at a hit. Shared by the CPU reference and the shader, so that both filter the same texels
// with the same operations and the images agree as they do without textures.
//
// What the functions read: in C++ a TextureTables (the scene's arrays); in GLSL the includer
// defines textureNodeAt(i), imageWordAt(i), materialTexturesAt(i) and uvsAt(i) over its
// buffers. PT_TEXTURES_PARAM / PT_TEXTURES_ARG pass the tables in C++ and nothing in GLSL.
//
// Images are filtered over the ray's footprint (UVFootprint, from differentials.h) in their MIP
// maps (host/scene/mip_pyramid.h) as pbrt-v4's MIPMap::Filter filters them, and the
// checkerboard over the same footprint (docs/textures.md).
//
// One call site: the shader's compiler (lavapipe's, as GPU drivers') copies a function's body
// into every place that calls it, and a texture lookup is large (the program, the filter, the
// texel reads, the decoding). Where a lookup is made several times, for the texels of a
// bilinear interpolation, the levels of a trilinear or EWA filter, the parameters of a
// material or the displacements of a bump map, it is made in a loop around one call, so that
// the shader holds one copy: a third of the code lavapipe compiled for a textured scene, and
// that much less time creating its pipeline (docs/performance.md). The values and the order
// of the operations are those of the calls written out.
#ifndef PT_TEXTURE_H
#define PT_TEXTURE_H

#include "gltf_material_fields.h"
#include "octahedral.h"
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
// The kTextureUses* bits of what to evaluate: a constant of the shader's compilation; the CPU
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
// A change of (u, v) mapped to one of (s, t).
PT_INLINE vec2 mapDerivative(vec4 mapping, vec2 duv) {
  return vec2(mapping.x * duv.x, mapping.y * duv.y);
}

// A node's mapping of (u, v), with its cross terms where it has them (kTextureSkewed: a rotated
// mapping), and of a change of (u, v).
PT_INLINE vec2 mapNodeUV(TextureNode node, vec2 uv) {
  vec2 st = mapUV(node.mapping, uv);
  if ((node.flags & kTextureSkewed) != 0u) st = st + vec2(node.skew.x * uv.y, node.skew.y * uv.x);
  return st;
}
PT_INLINE vec2 mapNodeDerivative(TextureNode node, vec2 duv) {
  vec2 d = mapDerivative(node.mapping, duv);
  if ((node.flags & kTextureSkewed) != 0u) d = d + vec2(node.skew.x * duv.y, node.skew.y * duv.x);
  return d;
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

// One level of an image's MIP map: its first word in the image buffer and its size.
struct ImageLevel {
  uint texels;
  int width;
  int height;
};

// The number of levels of the node's MIP map (1 + log2 of its larger side).
PT_INLINE int imageLevelCount(TextureNode node) {
  return int((node.flags >> kTextureLevelsShift) & 0x1Fu);
}

// Level `level` of the node's MIP map: level 0 is the image (at powers of two), each next one
// half its size, down to 1 x 1.
PT_INLINE ImageLevel imageLevel(PT_TEXTURES_PARAM TextureNode node, int level) {
  ImageLevel l;
  l.texels = level == 0 ? node.texels : imageWordAt(PT_TEXTURES_ARG node.levels + uint(level));
  l.width = int(max(node.width >> uint(level), 1u));
  l.height = int(max(node.height >> uint(level), 1u));
  return l;
}

// Texel (x, y) of a level, as linear (R, G, B, A): grey repeated in R, G and B, and alpha 1
// where the image has none. Zero for kWrapBlack outside the image.
PT_INLINE vec4 levelTexel(PT_TEXTURES_PARAM TextureNode node, ImageLevel level, int x, int y) {
  uint wrap = (node.flags >> 4u) & 0xFu;
  x = wrapTexel(x, level.width, wrap);
  y = wrapTexel(y, level.height, wrap);
  if (x < 0 || y < 0) return vec4(0.0f);
  uint index = uint(y) * uint(level.width) + uint(x);
  uint format = node.flags & 0xFu;
  if (format == kTexel8) {
    uint w = imageWordAt(PT_TEXTURES_ARG level.texels + index);
    return vec4(decodeByte(PT_TEXTURES_ARG node.decode, w & 0xFFu),
                decodeByte(PT_TEXTURES_ARG node.decode, (w >> 8u) & 0xFFu),
                decodeByte(PT_TEXTURES_ARG node.decode, (w >> 16u) & 0xFFu),
                decodeByte(PT_TEXTURES_ARG node.decode, w >> 24u));
  }
  if (format == kTexelFloat1) {
    float g = uintBitsToFloat(imageWordAt(PT_TEXTURES_ARG level.texels + index));
    return vec4(g, g, g, 1.0f);
  }
  uint stride = format == kTexelFloat3 ? 3u : 4u;
  uint at = level.texels + stride * index;
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

// What a texture reads of a filtered (R, G, B, A): the colour, or for a float texture the
// channel pbrt-v4's MIPMap::Bilerp<Float> reads (kFloatChannel*) in all three.
PT_INLINE vec3 bilerpValue(TextureNode node, vec4 c) {
  if ((node.flags & kTextureFloat) == 0u) return vec3(c);
  uint channel = (node.flags >> 12u) & 0xFu;
  if (channel == kFloatChannelAverage) return vec3((c.x + c.y + c.z) / 3.0f);
  if (channel == kFloatChannelAlpha) return vec3(c.w);
  return vec3(c.x);
}
// What a texture reads of one texel (pbrt-v4's MIPMap::Texel): a float texture its first channel.
PT_INLINE vec3 texelValue(TextureNode node, vec4 c) {
  return (node.flags & kTextureFloat) != 0u ? vec3(c.x) : vec3(c);
}

// pbrt-v4's Image::Bilerp of a level at st (image coordinates, row 0 at t = 0): texel centres
// at half-integers.
PT_INLINE vec3 levelBilerp(PT_TEXTURES_PARAM TextureNode node, ImageLevel level, vec2 st) {
  float x = safeTexelCoordinate(st.x * float(level.width) - 0.5f);
  float y = safeTexelCoordinate(st.y * float(level.height) - 0.5f);
  float fx = floor(x);
  float fy = floor(y);
  int xi = int(fx);
  int yi = int(fy);
  float dx = x - fx;
  float dy = y - fy;
  // The four texels through one call of levelTexel (see "One call site" above).
  vec4 t[4];
  for (int i = 0; i < 4; ++i) {
    PT_TEXTURE_LOOP_TICK();
    t[i] = levelTexel(PT_TEXTURES_ARG node, level, xi + (i & 1), yi + (i >> 1));
  }
  vec4 c = (1.0f - dx) * (1.0f - dy) * t[0] + dx * (1.0f - dy) * t[1] + (1.0f - dx) * dy * t[2] +
           dx * dy * t[3];
  return bilerpValue(node, c);
}

// pbrt-v4's EWA weight at squared radius r2 in [0, 1) of the ellipse: its table of
// exp(-2 r2) - exp(-2) at 128 steps, looked up by truncation.
PT_INLINE float ewaWeight(float r2) {
  float i = min(floor(r2 * 128.0f), 127.0f);
  return exp(-2.0f * (i / 127.0f)) - 0.135335283f;
}

// pbrt-v4's MIPMap::EWA: the gaussian-weighted average of the texels of `level` inside the
// ellipse of axes dst0, dst1 (in [0, 1]^2 units) about st, widened by a texel. Beyond the last
// level, the last level's texel.
PT_INLINE vec3 levelEwa(PT_TEXTURES_PARAM TextureNode node, int level, vec2 st, vec2 dst0,
                        vec2 dst1) {
  int count = imageLevelCount(node);
  if (level >= count) {
    return texelValue(
        node, levelTexel(PT_TEXTURES_ARG node, imageLevel(PT_TEXTURES_ARG node, count - 1), 0, 0));
  }
  ImageLevel l = imageLevel(PT_TEXTURES_ARG node, level);
  vec2 res = vec2(float(l.width), float(l.height));
  st = st * res - vec2(0.5f);
  dst0 = dst0 * res;
  dst1 = dst1 * res;
  float a = dst0.y * dst0.y + dst1.y * dst1.y + 1.0f;
  float b = -2.0f * (dst0.x * dst0.y + dst1.x * dst1.y);
  float c = dst0.x * dst0.x + dst1.x * dst1.x + 1.0f;
  float invF = 1.0f / (a * c - b * b * 0.25f);
  a *= invF;
  b *= invF;
  c *= invF;
  float det = -b * b + 4.0f * a * c;
  float invDet = 1.0f / det;
  float uSqrt = sqrt(max(det * c, 0.0f));
  float vSqrt = sqrt(max(a * det, 0.0f));
  int s0 = int(ceil(safeTexelCoordinate(st.x - 2.0f * invDet * uSqrt)));
  int s1 = int(floor(safeTexelCoordinate(st.x + 2.0f * invDet * uSqrt)));
  int t0 = int(ceil(safeTexelCoordinate(st.y - 2.0f * invDet * vSqrt)));
  int t1 = int(floor(safeTexelCoordinate(st.y + 2.0f * invDet * vSqrt)));
  vec3 sum = vec3(0.0f);
  float sumWeights = 0.0f;
  for (int it = t0; it <= t1; ++it) {
    float tt = float(it) - st.y;
    for (int is = s0; is <= s1; ++is) {
      PT_TEXTURE_LOOP_TICK();
      float ss = float(is) - st.x;
      float r2 = a * ss * ss + b * ss * tt + c * tt * tt;
      if (r2 < 1.0f) {
        float w = ewaWeight(r2);
        sum += w * texelValue(node, levelTexel(PT_TEXTURES_ARG node, l, is, it));
        sumWeights += w;
      }
    }
  }
  return sumWeights > 0.0f ? sum / sumWeights : vec3(0.0f);
}

// One level's part of an image lookup (kLevel*): its texel (0, 0), the texel nearest to st,
// the bilinear interpolation at st, or the EWA average over the ellipse of axes dst0, dst1.
PT_CONST int kLevelCorner = 0;
PT_CONST int kLevelNearest = 1;
PT_CONST int kLevelBilinear = 2;
PT_CONST int kLevelEwa = 3;
PT_INLINE vec3 levelLookup(PT_TEXTURES_PARAM TextureNode node, int kind, int level, vec2 st,
                           vec2 dst0, vec2 dst1) {
  if (PT_TEXTURE_USES(kTextureUsesEwa) && kind == kLevelEwa) {
    return levelEwa(PT_TEXTURES_ARG node, level, st, dst0, dst1);
  }
  ImageLevel l = imageLevel(PT_TEXTURES_ARG node, level);
  if (kind == kLevelBilinear) return levelBilerp(PT_TEXTURES_ARG node, l, st);
  int x = 0;
  int y = 0;
  if (kind == kLevelNearest) {
    x = int(roundHalfAway(safeTexelCoordinate(st.x * float(l.width) - 0.5f)));
    y = int(roundHalfAway(safeTexelCoordinate(st.y * float(l.height) - 0.5f)));
  }
  return texelValue(node, levelTexel(PT_TEXTURES_ARG node, l, x, y));
}

// The image's value at (s, t) (t = 1 at row 0, as pbrt-v4's ImageTexture flips t), filtered as
// the node says over the footprint whose changes of (s, t) across the pixel are dstdx and dstdy
// (pbrt-v4's MIPMap::Filter, given the derivatives before the flip as pbrt-v4 gives them):
// point, bilinear and trilinear lookups in the level that the footprint's largest extent calls
// for (level 0 at a footprint of zero), EWA over the ellipse the two span, in the levels its
// shorter axis calls for, the longer one clamped to maxAnisotropy times the shorter.
// pbrt-v4's "scale" and "invert" are applied last. The filter decides which levels are read and
// how; they are read through one call of levelLookup (see "One call site" above).
PT_INLINE vec3 imageLookup(PT_TEXTURES_PARAM TextureNode node, vec2 st, vec2 dstdx, vec2 dstdy) {
  st.y = 1.0f - st.y;
  uint filterType = (node.flags >> 8u) & 0xFu;
  int count = imageLevelCount(node);
  int kind = kLevelBilinear;
  int level = 0;
  int levels = 1;  // 2: level and level + 1, weighed 1 - delta and delta
  float delta = 0.0f;
  vec2 dst0 = dstdx;
  vec2 dst1 = dstdy;
  if (!PT_TEXTURE_USES(kTextureUsesEwa) || filterType != kTextureEwa) {
    float width = 2.0f * max(max(abs(dstdx.x), abs(dstdx.y)), max(abs(dstdy.x), abs(dstdy.y)));
    float lod = float(count - 1) + log2(max(width, 1e-8f));
    if (lod >= float(count - 1)) {
      kind = kLevelCorner;
      level = count - 1;
    } else {
      level = max(0, int(floor(lod)));
      if (filterType == kTexturePoint) {
        kind = kLevelNearest;
      } else if (filterType == kTextureTrilinear && level > 0) {
        levels = 2;
        delta = lod - float(level);
      }
    }
  } else {
    if (dot(dst0, dst0) < dot(dst1, dst1)) {
      dst0 = dstdy;
      dst1 = dstdx;
    }
    float longer = length(dst0);
    float shorter = length(dst1);
    if (shorter * node.maxAnisotropy < longer && shorter > 0.0f) {
      float scale = longer / (shorter * node.maxAnisotropy);
      dst1 *= scale;
      shorter *= scale;
    }
    if (shorter != 0.0f) {
      float lod = max(0.0f, float(count - 1) + log2(shorter));
      kind = kLevelEwa;
      level = int(floor(lod));
      levels = 2;
      delta = lod - float(level);
    }
  }
  vec3 first = vec3(0.0f);
  vec3 second = vec3(0.0f);
  for (int i = 0; i < levels; ++i) {
    PT_TEXTURE_LOOP_TICK();
    vec3 r = levelLookup(PT_TEXTURES_ARG node, kind, level + i, st, dst0, dst1);
    if (i == 0) {
      first = r;
    } else {
      second = r;
    }
  }
  vec3 v = levels == 2 ? (1.0f - delta) * first + delta * second : first;
  v = node.value * v;
  if ((node.flags & kTextureInvert) != 0u) v = max(vec3(1.0f) - v, vec3(0.0f));
  return v;
}

// pbrt-v4's 2D checkerboard, filtered over the footprint: the weight of tex2 at st, whose
// changes across the pixel are dstdx and dstdy. The squares where floor(s) + floor(t) is even
// are tex1's (weight 0), the others tex2's (weight 1); where the footprint's box (1.5 times
// its largest extent on each axis) crosses an edge, the integral of the checks against a
// triangle filter of that radius (pbrt-v4's Checkerboard()).
PT_INLINE float checkerFiltered1D(float x, float r) {
  float lo = floor(safeTexelCoordinate(x - r));
  float hi = floor(safeTexelCoordinate(x + r));
  if (lo == hi) return 1.0f - 2.0f * float(int(floor(safeTexelCoordinate(x))) & 1);
  // d(x): the twice-integrated square wave of period 2.
  float y0 = (x + r) / 2.0f - floor((x + r) / 2.0f) - 0.5f;
  float y1 = x / 2.0f - floor(x / 2.0f) - 0.5f;
  float y2 = (x - r) / 2.0f - floor((x - r) / 2.0f) - 0.5f;
  float d0 = (x + r) / 2.0f + y0 * (1.0f - 2.0f * abs(y0));
  float d1 = x / 2.0f + y1 * (1.0f - 2.0f * abs(y1));
  float d2 = (x - r) / 2.0f + y2 * (1.0f - 2.0f * abs(y2));
  return (d0 - 2.0f * d1 + d2) / (r * r);
}
PT_INLINE float checkerboardWeight(vec2 st, vec2 dstdx, vec2 dstdy) {
  float ds = 1.5f * max(abs(dstdx.x), abs(dstdy.x));
  float dt = 1.5f * max(abs(dstdx.y), abs(dstdy.y));
  return 0.5f - checkerFiltered1D(st.x, ds) * checkerFiltered1D(st.y, dt) / 2.0f;
}

// ---- Evaluation --------------------------------------------------------------------------

// Where a texture is evaluated: the texture coordinates (u, v) and their changes across the
// pixel, (du/dx, dv/dx) and (du/dy, dv/dy) (pbrt-v4's TextureEvalContext); zero changes where
// nothing is known of the footprint (alpha tests in the traversal, as pbrt-v4's).
struct UVFootprint {
  vec2 uv;
  vec2 duvdx;
  vec2 duvdy;
};
PT_INLINE UVFootprint pointFootprint(vec2 uv) {
  return UVFootprint(uv, vec2(0.0f), vec2(0.0f));
}

// The value of the texture whose program starts at node `first`, at footprint c.
PT_INLINE vec3 evalTextureAt(PT_TEXTURES_PARAM uint first, UVFootprint c) {
  TextureNode head = textureNodeAt(PT_TEXTURES_ARG first);
  // A constant leaf, the common case, without the stack; an image leaf through the program's
  // loop, which holds the one call of imageLookup (see "One call site" above).
  bool leaf = head.count == 1u || !PT_TEXTURE_USES(kTextureUsesPrograms);
  if (leaf && !(PT_TEXTURE_USES(kTextureUsesImages) && head.type == kTextureImage)) {
    return head.value;
  }
  vec3 stack[kTextureStackSize];
  uint top = 0u;  // values on the stack
  uint count = leaf ? 1u : head.count;
  for (uint i = 0u; i < count; ++i) {
    PT_TEXTURE_LOOP_TICK();
    TextureNode node = i == 0u ? head : textureNodeAt(PT_TEXTURES_ARG first + i);
    vec3 v;
    if (node.type == kTextureConstant) {
      v = node.value;
    } else if (PT_TEXTURE_USES(kTextureUsesImages) && node.type == kTextureImage) {
      v = imageLookup(PT_TEXTURES_ARG node, mapNodeUV(node, c.uv), mapNodeDerivative(node, c.duvdx),
                      mapNodeDerivative(node, c.duvdy));
    } else if (node.type == kTextureCheckerboard) {
      top -= 2u;
      float w = checkerboardWeight(mapUV(node.mapping, c.uv), mapDerivative(node.mapping, c.duvdx),
                                   mapDerivative(node.mapping, c.duvdy));
      v = w == 0.0f   ? stack[top]
          : w == 1.0f ? stack[top + 1u]
                      : (1.0f - w) * stack[top] + w * stack[top + 1u];
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

// At a point (a footprint of zero).
PT_INLINE vec3 evalTexture(PT_TEXTURES_PARAM uint first, vec2 uv) {
  return evalTextureAt(PT_TEXTURES_ARG first, pointFootprint(uv));
}

// A float texture's value (its first channel).
PT_INLINE float evalFloatTextureAt(PT_TEXTURES_PARAM uint first, UVFootprint c) {
  return evalTextureAt(PT_TEXTURES_ARG first, c).x;
}
PT_INLINE float evalFloatTexture(PT_TEXTURES_PARAM uint first, vec2 uv) {
  return evalTextureAt(PT_TEXTURES_ARG first, pointFootprint(uv)).x;
}

// ---- Materials ----------------------------------------------------------------------------

// Whether a material reads a texture of gltf's extensions (compiled only where one is used).
PT_INLINE bool gltfLayerTextured(MaterialTextures t) {
  return (PT_TEXTURE_USES(kTextureUsesGltfLayers) &&
          (t.transmission != kNoTexture || t.clearcoat != kNoTexture ||
           t.clearcoatRoughness != kNoTexture || t.specular != kNoTexture ||
           t.specularColour != kNoTexture)) ||
         (PT_TEXTURE_USES(kTextureUsesGltfSheen) &&
          (t.sheenColour != kNoTexture || t.sheenRoughness != kNoTexture)) ||
         (PT_TEXTURE_USES(kTextureUsesCoatNormal) && t.clearcoatNormal != kNoTexture);
}

// Whether a material reads any texture (and so the hit's texture coordinates).
PT_INLINE bool anyTexture(MaterialTextures t) {
  return t.reflectance != kNoTexture || t.transmittance != kNoTexture ||
         t.uRoughness != kNoTexture || t.vRoughness != kNoTexture || t.eta != kNoTexture ||
         t.k != kNoTexture || t.displacement != kNoTexture || t.alpha != kNoTexture ||
         t.thickness != kNoTexture || t.g != kNoTexture || t.emission != kNoTexture ||
         t.normalMap != kNoTexture || gltfLayerTextured(t);
}

// gltf's extension textures, parameters 9 to 15 of resolveMaterialAt: transmission, clear coat,
// the coat's roughness, specular, specular colour, sheen colour, sheen roughness (kNoTexture
// where the shader has none).
PT_INLINE uint gltfLayerTexture(MaterialTextures t, uint i) {
  return i == 9u    ? t.transmission
         : i == 10u ? t.clearcoat
         : i == 11u ? t.clearcoatRoughness
         : i == 12u ? t.specular
         : i == 13u ? t.specularColour
         : i == 14u ? t.sheenColour
                    : t.sheenRoughness;
}
// The value of parameter i (9 to 15) in the fields gltfLayersOf reads (shaders/bsdf.h): each
// texture is its factor times the texel (the reader's scale), as the extensions define them.
PT_INLINE Material gltfLayerTextureApplied(Material m, uint i, vec3 value) {
  float x = clamp(value.x, 0.0f, 1.0f);
  if (i == 9u) {
    m.transmittance.x = x;
  } else if (i == 10u) {
    m.transmittance.y = x;
  } else if (i == 11u) {
    m.transmittance.z = x * x;  // the coat's alpha: its roughness squared
  } else if (i == 12u) {
    m.eta.y = x;
  } else if (i == 13u) {
    m.k = max(value, vec3(0.0f));
  } else if (i == 14u) {
    m = gltfWithSheenColour(m, clamp(value, vec3(0.0f), vec3(1.0f)));
  } else {
    m = gltfWithSheenRoughness(m, x);
  }
  return m;
}

// The material's parameters at texture coordinates uv: each parameter that has a texture takes
// the texture's value there, as pbrt-v4's materials evaluate theirs (reflectances clamped to
// [0, 1] as its albedo spectra are; roughness remapped to alpha where the material asks;
// diffusetransmission's scale; a conductor given by its reflectance takes eta = 1 and pbrt-v4's
// k; gltf's roughness squared to alpha, its metallic in [0, 1], its emission as it is; its
// extensions' transmission, clear coat and specular in [0, 1], the coat's roughness squared to
// alpha, the specular colour at least 0). Parameters without a texture keep the host's values.
PT_INLINE Material resolveMaterialAt(PT_TEXTURES_PARAM Material m, MaterialTextures t,
                                     UVFootprint uv) {
  bool remap = (t.flags & kRemapRoughness) != 0u;
  bool square = (t.flags & kSquareRoughness) != 0u;
  // The parameters in this order, each texture evaluated by one call of evalTextureAt (see "One
  // call site" above). The emission (i = 8) only where some material has an emission texture,
  // gltf's extension textures (i = 9 to 13) only where some material has one of them, its sheen
  // textures (14 and 15) where one has them.
  uint parameters = PT_TEXTURE_USES(kTextureUsesGltfSheen)    ? 16u
                    : PT_TEXTURE_USES(kTextureUsesGltfLayers) ? 14u
                    : PT_TEXTURE_USES(kTextureUsesEmission)   ? 9u
                                                              : 8u;
  for (uint i = 0u; i < parameters; ++i) {
    PT_TEXTURE_LOOP_TICK();
    uint texture = i == 0u ? (PT_TEXTURE_USES(kTextureUsesReflectance) ? t.reflectance : kNoTexture)
                   : i == 1u
                       ? (PT_TEXTURE_USES(kTextureUsesTransmittance) ? t.transmittance : kNoTexture)
                   : i == 2u ? (PT_TEXTURE_USES(kTextureUsesEtaK) ? t.eta : kNoTexture)
                   : i == 3u ? (PT_TEXTURE_USES(kTextureUsesEtaK) ? t.k : kNoTexture)
                   : i == 4u ? (PT_TEXTURE_USES(kTextureUsesRoughness) ? t.uRoughness : kNoTexture)
                   : i == 5u ? (PT_TEXTURE_USES(kTextureUsesRoughness) ? t.vRoughness : kNoTexture)
                   : i == 6u ? (PT_TEXTURE_USES(kTextureUsesMedium) ? t.thickness : kNoTexture)
                   : i == 7u ? (PT_TEXTURE_USES(kTextureUsesMedium) ? t.g : kNoTexture)
                   : PT_TEXTURE_USES(kTextureUsesGltfLayers | kTextureUsesGltfSheen) && i > 8u
                       ? gltfLayerTexture(t, i)
                       : t.emission;
    if (texture == kNoTexture) continue;
    vec3 value = evalTextureAt(PT_TEXTURES_ARG texture, uv);
    if (i == 0u) {
      vec3 r = clamp(value, vec3(0.0f), vec3(1.0f));
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
    } else if (i == 1u) {
      vec3 r = clamp(value, vec3(0.0f), vec3(1.0f));
      m.transmittance =
          m.type == kMaterialDiffuseTransmission ? clamp(t.scale * r, vec3(0.0f), vec3(1.0f)) : r;
    } else if (i == 2u) {
      m.eta = value;
    } else if (i == 3u) {
      m.k = value;
    } else if (i == 4u) {
      float r = max(value.x, 0.0f);
      m.alphaX = square ? r * r : remap ? sqrt(r) : r;
    } else if (i == 5u) {
      float r = max(value.x, 0.0f);
      m.alphaY = square ? r * r : remap ? sqrt(r) : r;
    } else if (i == 6u) {
      // coateddiffuse's medium: pbrt-v4 keeps the thickness at least the smallest normal float
      // and clamps g to [-1, 1]; we keep g inside (-1, 1), where Henyey-Greenstein is not a
      // delta. gltf's metallic, in the same field, is kept in [0, 1].
      m.thickness =
          m.type == kMaterialGltf ? clamp(value.x, 0.0f, 1.0f) : max(value.x, 1.17549435e-38f);
    } else if (i == 7u) {
      m.g = clamp(value.x, -0.999f, 0.999f);
    } else if (PT_TEXTURE_USES(kTextureUsesGltfLayers | kTextureUsesGltfSheen) && i > 8u) {
      m = gltfLayerTextureApplied(m, i, value);
    } else {
      m.emission = max(value, vec3(0.0f));
    }
  }
  return m;
}

// At a point (a footprint of zero).
PT_INLINE Material resolveMaterial(PT_TEXTURES_PARAM Material m, MaterialTextures t, vec2 uv) {
  return resolveMaterialAt(PT_TEXTURES_ARG m, t, pointFootprint(uv));
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

// A triangle's partial derivatives dp/du and dp/dv (pbrt-v4's
// Triangle::InteractionFromIntersection: from the vertices of tri and their texture coordinates t,
// a coordinate system about the normal where (u, v) are degenerate) and the determinant of its (u,
// v) differences.
struct TriangleDerivatives {
  vec3 dpdu;
  vec3 dpdv;
  float determinant;
};
PT_INLINE TriangleDerivatives triangleDerivatives(Triangle tri, TriangleUVs t) {
  TriangleDerivatives d;
  vec2 duv02 = t.uv0 - t.uv2;
  vec2 duv12 = t.uv1 - t.uv2;
  vec3 dp02 = tri.v0 - tri.v2;
  vec3 dp12 = tri.v1 - tri.v2;
  d.determinant = duv02.x * duv12.y - duv02.y * duv12.x;
  d.dpdu = vec3(0.0f);
  d.dpdv = vec3(0.0f);
  bool degenerate = abs(d.determinant) < 1e-9f;
  if (!degenerate) {
    float invDet = 1.0f / d.determinant;
    d.dpdu = (duv12.y * dp02 - duv02.y * dp12) * invDet;
    d.dpdv = (duv02.x * dp12 - duv12.x * dp02) * invDet;
  }
  vec3 c = cross(d.dpdu, d.dpdv);
  if (degenerate || dot(c, c) == 0.0f) {
    coordinateSystem(normalize(cross(tri.v2 - tri.v0, tri.v1 - tri.v0)), d.dpdu, d.dpdv);
  }
  return d;
}

// The changes of the interpolated vertex normal along u and v, dn/du and dn/dv, as pbrt-v4's
// Triangle derives them (zero without vertex normals).
PT_INLINE void normalDerivatives(TriangleUVs t, TriangleNormals normals, float determinant,
                                 PT_OUT(vec3) dndu, PT_OUT(vec3) dndv) {
  dndu = vec3(0.0f);
  dndv = vec3(0.0f);
  vec2 duv02 = t.uv0 - t.uv2;
  vec2 duv12 = t.uv1 - t.uv2;
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

// The shading normal that pbrt-v4's BumpMap gives a triangle (its derivatives d, the hit's
// footprint uv) whose displacement is the float texture `displacement`: with vertex normals
// (hasNormals, ns interpolated, dndu and dndv from normalDerivatives) the shading frame's
// tangents as pbrt-v4 derives them, otherwise dp/du and dp/dv; the displacement's finite
// differences along u and v move them, and the normal of the moved pair, turned to the side of
// ng (pbrt-v4's FaceForward), is the bumped one. The differences step by half the footprint's
// extent in u and in v (pbrt-v4's), 0.0005 where that is zero. Where both differences are
// exactly zero (a constant displacement) the surface is left as it is.
PT_INLINE vec3 bumpedNormal(PT_TEXTURES_PARAM uint displacement, TriangleDerivatives d,
                            UVFootprint uv, vec3 ng, vec3 ns, bool hasNormals, vec3 dndu,
                            vec3 dndv) {
  float du = 0.5f * (abs(uv.duvdx.x) + abs(uv.duvdy.x));
  if (du == 0.0f) du = 0.0005f;
  float dv = 0.5f * (abs(uv.duvdx.y) + abs(uv.duvdy.y));
  if (dv == 0.0f) dv = 0.0005f;
  // The displacement at uv, a step along u and a step along v, by one call of evalTextureAt
  // (see "One call site" above).
  float displace = 0.0f;
  float uDisplace = 0.0f;
  float vDisplace = 0.0f;
  for (int i = 0; i < 3; ++i) {
    PT_TEXTURE_LOOP_TICK();
    UVFootprint at = uv;
    if (i == 1) at.uv = uv.uv + vec2(du, 0.0f);
    if (i == 2) at.uv = uv.uv + vec2(0.0f, dv);
    float value = evalFloatTextureAt(PT_TEXTURES_ARG displacement, at);
    if (i == 0) {
      displace = value;
    } else if (i == 1) {
      uDisplace = value;
    } else {
      vDisplace = value;
    }
  }
  if (uDisplace == displace && vDisplace == displace) return ns;
  vec3 dpdu = d.dpdu;
  vec3 dpdv = d.dpdv;
  // The shading frame: ns with the tangent dp/du made perpendicular.
  vec3 n = ng;
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
  }
  vec3 bumpedU = dpdu + ((uDisplace - displace) / du) * n + displace * dndu;
  vec3 bumpedV = dpdv + ((vDisplace - displace) / dv) * n + displace * dndv;
  vec3 bumped = cross(bumpedU, bumpedV);
  float len2 = dot(bumped, bumped);
  if (!(len2 > 0.0f) || !(len2 < 3.0e38f)) return ns;
  bumped = bumped / sqrt(len2);
  return dot(bumped, ng) < 0.0f ? -bumped : bumped;
}

// ---- Normal maps -------------------------------------------------------------------------

// A vertex's tangent (glTF's TANGENT: a direction and the sign w of its bitangent) in one word
// (TriangleNormals::tangent*): bit 31 set (zero is no tangent), bit 30 for w < 0, and the
// direction's octahedral coordinates in 15 bits each (bits 15-29 and 0-14; within 2e-4
// radians).
#ifdef __cplusplus
inline uint packTangent(vec3 t, float w) {
  float l1 = abs(t.x) + abs(t.y) + abs(t.z);
  if (!(l1 > 0.0f) || !(l1 < 3.0e38f)) return 0u;
  return 0x80000000u | (w < 0.0f ? 0x40000000u : 0u) | packOctahedral(t);
}
#endif
// The direction of a packed tangent (unit; zero where there is none).
PT_INLINE vec3 unpackTangent(uint packed) {
  if (packed == 0u) return vec3(0.0f);
  return unpackOctahedral(packed);
}
// A triangle's tangent at barycentrics b (the vertices' interpolated, not made unit) and, in w,
// the sign of its bitangent (v0's); w = 0 where the triangle has no tangents.
PT_INLINE vec4 interpolatedTangent(TriangleNormals t, vec3 b) {
  if (t.tangent0 == 0u) return vec4(0.0f);
  vec3 d = b.x * unpackTangent(t.tangent0) + b.y * unpackTangent(t.tangent1) +
           b.z * unpackTangent(t.tangent2);
  return vec4(d, (t.tangent0 & 0x40000000u) != 0u ? -1.0f : 1.0f);
}

// The shading normal that a tangent-space normal map (glTF's normalTexture) gives a triangle
// (its derivatives d, the hit's footprint uv) whose normal there is ns (the vertex normals'
// or the geometric one): the map's RGB c at uv is the normal (2 c - 1) in the frame of the
// tangent T, the bitangent B and ns; its x and y times `scale`. T is the vertices' tangent
// where the mesh has them (vertexTangent, interpolatedTangent's: w its bitangent's sign; w = 0
// for none), else dp/du, made perpendicular to ns; B = ns x T times w, or turned to dp/dv's
// side. The green channel points up the image (along +t, glTF's -v), as glTF's normal maps
// are stored. Where the frame or the normal is degenerate, ns is kept.
PT_INLINE vec3 normalMappedNormal(PT_TEXTURES_PARAM uint normalMap, float scale,
                                  TriangleDerivatives d, vec4 vertexTangent, UVFootprint uv,
                                  vec3 ns) {
  vec3 c = evalTextureAt(PT_TEXTURES_ARG normalMap, uv);
  vec3 local = 2.0f * c - vec3(1.0f);
  local = vec3(local.x * scale, local.y * scale, local.z);
  bool given = vertexTangent.w != 0.0f;
  vec3 along = given ? vec3(vertexTangent.x, vertexTangent.y, vertexTangent.z) : d.dpdu;
  vec3 tangent = along - dot(along, ns) * ns;
  float t2 = dot(tangent, tangent);
  vec3 bitangent;
  if (!(t2 > 0.0f) || !(t2 < 3.0e38f)) {
    coordinateSystem(ns, tangent, bitangent);
  } else {
    tangent = tangent / sqrt(t2);
    bitangent = cross(ns, tangent);
    if (given) {
      bitangent = vertexTangent.w * bitangent;
    } else if (dot(bitangent, d.dpdv) < 0.0f) {
      bitangent = -bitangent;
    }
  }
  vec3 n = local.x * tangent + local.y * bitangent + local.z * ns;
  float len2 = dot(n, n);
  if (!(len2 > 0.0f) || !(len2 < 3.0e38f)) return ns;
  return n / sqrt(len2);
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
// With kAlphaCutoff (glTF's MASK) alpha is first cut: 1 at or above the cut-off, else 0.
PT_INLINE bool alphaKeepsHit(PT_TEXTURES_PARAM uint material, uint primitive, vec3 b, float u) {
  MaterialTextures t = materialTexturesAt(PT_TEXTURES_ARG material);
  uint alpha = t.alpha;
  if (alpha == kNoTexture) return true;
  float a =
      evalFloatTexture(PT_TEXTURES_ARG alpha, interpolatedUV(uvsAt(PT_TEXTURES_ARG primitive), b));
  if ((t.flags & kAlphaCutoff) != 0u) a = a >= t.alphaCutoff ? 1.0f : 0.0f;
  if (a >= 1.0f) return true;
  if (a <= 0.0f) return false;
  return u <= a;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_TEXTURE_H
