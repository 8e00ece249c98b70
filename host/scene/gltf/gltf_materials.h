// glTF materials as the renderer's materials. The metallic-roughness model is mapped onto
// pbrt-v4's materials (docs/gltf.md): metallic >= 0.5 a conductor of the base colour's
// reflectance, otherwise a coated diffuse surface (the dielectric specular layer of index `ior`
// over a Lambertian base of the base colour), Trowbridge-Reitz alpha = roughness^2 for both.
// What this mapping does not simulate (textures, fractional metallic, alpha, extensions) is
// warned, once per kind.
#pragma once

#include <cstddef>

#include "scene/gltf/tinygltf.h"

#include "common/shared.h"
#include "scene/gltf/gltf_context.h"

namespace pt::gltf {

// materials[index], or the specification's default material where index is -1 (base colour 1,
// metallic 1, roughness 1). Factors out of range are InputErrors naming the field.
Material readMaterial(const tinygltf::Model& model, int index, Context& context);

}  // namespace pt::gltf
