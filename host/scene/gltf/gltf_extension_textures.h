// The textures of glTF's material extensions, bound as the renderer's MaterialTextures (one
// texture per layer parameter, each times its factor, evaluated at the hit by texture.h as the
// core textures are): KHR_materials_transmission's transmissionTexture (R),
// KHR_materials_clearcoat's clearcoatTexture (R), clearcoatRoughnessTexture (G) and
// clearcoatNormalTexture (RGB, linear, with its scale), KHR_materials_specular's specularTexture
// (A) and specularColorTexture (RGB, sRGB), KHR_materials_sheen's sheenColorTexture (RGB, sRGB)
// and sheenRoughnessTexture (A). Their textureInfo objects are plain JSON values in tinygltf (it
// has no structure for them): read and checked here. KHR_materials_volume's thicknessTexture is
// ignored by design (the mesh is the volume).
#pragma once

#include <string>
#include <vector>

#include "scene/gltf/gltf_context.h"
#include "scene/gltf/gltf_material_extensions.h"
#include "scene/gltf/gltf_textures.h"
#include "scene/gltf/tinygltf.h"

#include "common/shared.h"

namespace pt::gltf {

// One textureInfo of an extension object: its texture, set and KHR_texture_transform.
struct ExtensionTextureInfo {
  int index = -1;  // -1: absent
  int texCoord = 0;
  tinygltf::ExtensionMap extensions;
  double scale = 1.0;  // a normal map's (normalTextureInfo's) scale of x and y
  std::string where;   // its JSON path
  TextureRef ref() const { return TextureRef{index, texCoord, &extensions}; }
};

// The extension textures of one material that the renderer reads.
struct ExtensionTextureInfos {
  ExtensionTextureInfo transmission;        // KHR_materials_transmission.transmissionTexture
  ExtensionTextureInfo clearcoat;           // KHR_materials_clearcoat.clearcoatTexture
  ExtensionTextureInfo clearcoatRoughness;  // KHR_materials_clearcoat.clearcoatRoughnessTexture
  ExtensionTextureInfo specular;            // KHR_materials_specular.specularTexture
  ExtensionTextureInfo specularColour;      // KHR_materials_specular.specularColorTexture
  ExtensionTextureInfo sheenColour;         // KHR_materials_sheen.sheenColorTexture
  ExtensionTextureInfo sheenRoughness;      // KHR_materials_sheen.sheenRoughnessTexture
  ExtensionTextureInfo clearcoatNormal;     // KHR_materials_clearcoat.clearcoatNormalTexture
};

// The textureInfo objects of m's extensions (materials[...] at `path`), checked: an index and a
// texCoord that are not non-negative integers are errors.
ExtensionTextureInfos readExtensionTextureInfos(const tinygltf::Material& m,
                                                const std::string& path, const Context& context);

// The references of the textures that are read: those present whose factor is not 0 (a factor
// of 0 makes the parameter 0 whatever the texture holds), in the order above.
std::vector<TextureRef> readExtensionTextureRefs(const ExtensionTextureInfos& infos,
                                                 const MaterialExtensions& factors);

// Binds the textures that are read into t (t.transmission, t.clearcoat, ...), each times its
// factor; a texture left out (warned by the reader) leaves the factor alone. The coat's normal
// map's scale goes to t.scale.
void bindExtensionTextures(const ExtensionTextureInfos& infos, const MaterialExtensions& factors,
                           TextureReader& textures, MaterialTextures& t);

}  // namespace pt::gltf
