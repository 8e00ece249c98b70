// Wavefront MTL materials (read by tinyobjloader) mapped onto the renderer's material types:
// Lambertian, mirror, glass (dielectric), metal (conductor) and plastic (coated diffuse), with
// emission. What cannot be simulated becomes a warning naming the material and what it
// became. The rule is in docs/scene-format.md.
#pragma once

#include <string>
#include <vector>

#include "common/shared.h"
#include "scene/textures.h"

namespace pt::scene_detail {

// A texture map of an MTL material that the renderer simulates, with its options applied to
// desc (the image is read only when the material is used: buildMtlTextures).
struct MtlMap {
  enum class Target { kReflectance, kAlpha, kDisplacement };
  Target target = Target::kReflectance;
  std::string statement;  // as the file spells it in messages: "map_Kd", "map_d", "bump"
  std::string file;       // the file name as the MTL file gives it, for messages
  ImageTextureDesc desc;  // filename resolved against the MTL file's directory
  vec3 factor{1.0f};      // multiplies the image's value (Kd, Ks or d)
  bool isFloat = false;   // alpha and displacement read one channel (texture.h's float rule)
};

struct MtlMaterial {
  std::string name;
  Material material{};
  std::vector<MtlMap> maps;
  std::vector<std::string> warnings;  // "<file>: material 'x': ... rendered as ...", one each
};

// The Trowbridge-Reitz alpha of a Phong exponent Ns: alpha = sqrt(2 / (Ns + 2)), the match of
// a Phong lobe to a Beckmann one of the same width (Walter et al. 2007, "Microfacet Models for
// Refraction through Rough Surfaces"), taken as the Trowbridge-Reitz alpha directly (no
// remapping). Ns 0 gives alpha 1, Ns 10 0.41, Ns 100 0.14, Ns 1000 0.045, Ns infinite 0.
float phongExponentToAlpha(float ns);

// The materials of one MTL file in file order (`text` its content, `file` its name for
// messages); a name defined twice keeps its first definition. Mapping, first rule that applies:
//  - Ke -> emission (front side), whatever the rest; Ka is ignored (no ambient term in a path
//    tracer).
//  - illum 4, 6 or 7 (glass, refraction): a smooth dielectric of index Ni (1.5 when the
//    material has no Ni line); Kd, Ks, Ns, d and Tf are ignored.
//  - An ideal mirror when illum is 3 or 5 (ray-traced reflection), or when the highlight is
//    mirror-like: Ns >= 1000 and Ks non-black and at least as bright as Kd. Its reflectance is
//    Ks, or 1 when Ks is black.
//  - Ks non-black (a glossy highlight): Kd non-black -> a coated diffuse surface (pbrt-v4's
//    coateddiffuse, base Kd, coat index 1.5, other parameters its defaults); Kd black -> a
//    rough conductor of reflectance Ks. Both with alpha = phongExponentToAlpha(Ns).
//  - Otherwise Lambertian with reflectance Kd.
// Maps (file names relative to the MTL file's directory; the options before the file name
// are read here, as tinyobjloader loses the file after `-s u v` and does not know -cc: -s, -o,
// -clamp, -bm and -colorspace sRGB|linear honoured; -imfchan, -mm, -texres, -boost, -t,
// -type, -blendu off, -blendv off and -cc on warned about, once per map, and ignored):
//  - map_Kd: the reflectance where the rule uses Kd (diffuse, coated diffuse base), the image
//    (sRGB for 8-bit images) times Kd (the image alone where the material has no Kd line).
//  - map_Ks: the reflectance where the rule uses Ks (mirror, rough conductor), the image
//    times the reflectance the rule chose (Ks, or 1 for a mirror whose Ks is black).
//  - map_d: alpha, the image (linear) times d where d < 1 (not for glass, where d is part of
//    the glass); d < 1 is then simulated, not warned about.
//  - map_Bump, map_bump, bump: displacement, the image (linear) times -bm.
//  A material with map_Kd and no Kd line is taken as Kd 0.6 (tinyobjloader's default) to
//  choose its rule. A map the material's rule has no parameter for is a warning, and so is
//  every other map (map_Ka, map_Ns, map_Ke, disp, refl, norm, map_Pr, map_Pm, map_Ps).
// Warnings: transparency (illum 9 or d < 1 outside the glass rule, without map_d), a diffuse
// part dropped from a mirror, maps and map options not simulated. Throws InputError "<file>:
// material 'x': Kd: ..." for colours outside [0, 1] (Kd, Ks), negative or non-finite emission, an
// Ns a glossy material uses that is negative or NaN, and an Ni a glass uses that is not positive
// and finite; and
// "<file>: material 'x': map_Kd 'f.png': ..." for a map's non-finite -s, -o or -bm, an unknown
// -colorspace or no file name, and "...: d: ..." for a negative or NaN d beside a map_d.
std::vector<MtlMaterial> loadMtlMaterials(const std::string& text, const std::string& file);

// The textures of m's maps (m from loadMtlMaterials of `file`), their images read now through
// builder (which builds into scene). Throws InputError "<file>: material 'x': map_Kd 'f.png':
// <the image's own message>" for an image that cannot be read.
MaterialTextures buildMtlTextures(const MtlMaterial& m, const std::string& file,
                                  TextureBuilder& builder, Scene& scene);

}  // namespace pt::scene_detail
