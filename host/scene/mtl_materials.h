// Wavefront MTL materials (read by tinyobjloader) mapped onto what the renderer simulates:
// Lambertian or ideal mirror surfaces with emission. What cannot be simulated becomes a
// warning naming the material and what it became. The rule is in docs/scene-format.md.
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

// The materials of one MTL file in file order (`text` its content, `file` its name for
// messages); a name defined twice keeps its first definition. Mapping:
//  - Ke -> emission (front side); Ka is ignored (no ambient term in a path tracer).
//  - An ideal mirror when illum is 3 or 5 (ray-traced reflection), or when the highlight is
//    mirror-like: Ns >= 1000 and Ks at least as bright as Kd. Its reflectance is Ks, or 1
//    when Ks is black.
//  - Otherwise Lambertian with reflectance Kd.
// Warnings: transparency or refraction (illum 4, 6, 7, 9 or d < 1), a glossy highlight
// (Ks > 0 on a diffuse material), a diffuse part dropped from a mirror, texture maps.
// Throws InputError "<file>: material 'x': Kd: ..." for colours outside [0, 1] (Kd, Ks) or
// negative or non-finite emission.
std::vector<MtlMaterial> loadMtlMaterials(const std::string& text, const std::string& file);

}  // namespace pt::scene_detail
