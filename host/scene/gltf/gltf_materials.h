// glTF materials as the renderer's kMaterialGltf (shaders/bsdf.h: the specification's
// metallic-roughness model), from their factors and the KHR_materials_* extensions that
// gltf_material_extensions.h reads (the textures and the alpha mode are
// gltf_material_textures.h's).
#pragma once

#include <cstddef>

#include "scene/gltf/tinygltf.h"

#include "common/shared.h"
#include "scene/gltf/gltf_context.h"
#include "scene/gltf/gltf_material_extensions.h"

namespace pt::gltf {

// materials[index], or the specification's default material where index is -1 (base colour 1,
// metallic 1, roughness 1). Factors out of range are InputErrors naming the field.
// The extensions it read go to `extensions` where given.
Material readMaterial(const tinygltf::Model& model, int index, Context& context,
                      MaterialExtensions* extensions = nullptr);

}  // namespace pt::gltf
