// Wavefront MTL materials (read by tinyobjloader) mapped onto the renderer's material types:
// Lambertian, mirror, glass (dielectric), metal (conductor) and plastic (coated diffuse), with
// emission. What cannot be simulated becomes a warning naming the material and what it
// became. The rule is in docs/scene-format.md.
#pragma once

#include <string>
#include <vector>

#include "common/shared.h"

namespace pt::scene_detail {

struct MtlMaterial {
  std::string name;
  Material material{};
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
// Warnings: transparency (illum 9 or d < 1 outside the glass rule), a diffuse part dropped
// from a mirror, texture maps. Throws InputError "<file>: material 'x': Kd: ..." for colours
// outside [0, 1] (Kd, Ks), negative or non-finite emission, an Ns a glossy material uses that
// is negative or NaN, and an Ni a glass uses that is not positive and finite.
std::vector<MtlMaterial> loadMtlMaterials(const std::string& text, const std::string& file);

}  // namespace pt::scene_detail
