// glTF materials as the renderer's kMaterialGltf (shaders/bsdf.h: the specification's
// metallic-roughness model), from their factors, KHR_materials_ior and
// KHR_materials_emissive_strength (the textures and the alpha mode are
// gltf_material_textures.h's). Other extensions are warned, once per kind.
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
