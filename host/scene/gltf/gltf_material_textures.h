// A glTF material's textures as the renderer's MaterialTextures (shaders/texture.h): the base
// colour's RGB (sRGB) and alpha, the metallic-roughness texture's G (roughness) and B
// (metallic), linear, the emissive texture (sRGB) and the tangent-space normal map, each times
// its factor; the alpha mode as a cut-out (MASK, at alphaCutoff) or stochastic coverage
// (BLEND); and the material extensions' textures (gltf_extension_textures.h).
#pragma once

#include "scene/gltf/gltf_context.h"
#include "scene/gltf/gltf_material_extensions.h"
#include "scene/gltf/gltf_textures.h"
#include "scene/gltf/tinygltf.h"

#include "common/shared.h"

namespace pt::gltf {

// The textures of materials[index] (index >= 0), whose factors readMaterial made `material`
// (and `extensions`, its extensions' factors); noMaterialTextures() where it has none. uvSet:
// the texture coordinate set they read (0 or 1), the first read texture's (the core textures
// first, then the extensions'); the triangles of the material keep that set, and a texture of
// the other is left out (warned).
MaterialTextures readMaterialTextures(const tinygltf::Model& model, int index,
                                      const Material& material,
                                      const MaterialExtensions& extensions, TextureReader& textures,
                                      Context& context, int& uvSet);

}  // namespace pt::gltf
