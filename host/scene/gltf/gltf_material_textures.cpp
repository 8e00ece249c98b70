// readMaterialTextures (gltf_material_textures.h).
#include "scene/gltf/gltf_material_textures.h"

#include <cmath>
#include <string>
#include <vector>

#include "scene/gltf/gltf_extension_textures.h"
#include "scene/textures.h"

namespace pt::gltf {

namespace {

// alphaMode as the alpha texture (and its cut-off) of t: alpha is the base colour factor's
// times the base colour texture's (where its image has an alpha channel that is not all ones).
void readAlpha(const tinygltf::Material& m, const std::string& path, TextureReader& textures,
               MaterialTextures& t) {
  if (m.alphaMode == "OPAQUE") return;
  const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
  const float factor = pbr.baseColorFactor.size() == 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
  uint alpha = kNoTexture;
  if (pbr.baseColorTexture.index >= 0) {
    alpha = textures.texture(textureRef(pbr.baseColorTexture), TextureChannels::kAlpha,
                             vec3(factor), path + ".pbrMetallicRoughness.baseColorTexture");
  }
  const bool mask = m.alphaMode == "MASK";
  const float cutoff = float(m.alphaCutoff);
  if (alpha == kNoTexture) {
    // The factor alone: a surface wholly there, wholly cut away, or (BLEND) partly there.
    const bool whole = mask ? factor >= cutoff : factor >= 1.0f;
    if (whole) return;
    alpha = textures.constant(vec3(mask ? 0.0f : factor));
  } else if (mask) {
    t.flags |= kAlphaCutoff;
    t.alphaCutoff = cutoff;
  }
  t.alpha = alpha;
}

}  // namespace

MaterialTextures readMaterialTextures(const tinygltf::Model& model, int index,
                                      const Material& material,
                                      const MaterialExtensions& extensions, TextureReader& textures,
                                      Context& context, int& uvSet) {
  MaterialTextures t = noMaterialTextures();
  const std::string path = indexed("materials", std::size_t(index));
  const tinygltf::Material& m = model.materials[std::size_t(index)];
  const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
  const std::string pbrPath = path + ".pbrMetallicRoughness";
  const ExtensionTextureInfos extensionTextures = readExtensionTextureInfos(m, path, context);
  // The set of the first texture read (the emissive one only where it emits, an extension's
  // only where its factor is not 0).
  uvSet = 0;
  std::vector<TextureRef> refs = {
      textureRef(pbr.baseColorTexture), textureRef(pbr.metallicRoughnessTexture),
      textureRef(m.normalTexture),
      material.emission != vec3(0.0f) ? textureRef(m.emissiveTexture) : TextureRef{}};
  for (const TextureRef& ref : readExtensionTextureRefs(extensionTextures, extensions)) {
    refs.push_back(ref);
  }
  for (const TextureRef& ref : refs) {
    if (ref.index < 0) continue;
    const int set = TextureReader::texCoordOf(ref);
    uvSet = set == 1 ? 1 : 0;
    break;
  }
  textures.useSet(uvSet);
  if (pbr.baseColorTexture.index >= 0) {
    t.reflectance = textures.baseColor(pbr.baseColorTexture, material.reflectance,
                                       pbrPath + ".baseColorTexture");
  }
  if (pbr.metallicRoughnessTexture.index >= 0) {
    const std::string where = pbrPath + ".metallicRoughnessTexture";
    const TextureRef ref = textureRef(pbr.metallicRoughnessTexture);
    // Roughness from G, metallic from B, each times its factor; alpha = roughness^2 at the hit.
    t.uRoughness =
        textures.texture(ref, TextureChannels::kGreen, vec3(float(pbr.roughnessFactor)), where);
    t.vRoughness = t.uRoughness;
    if (t.uRoughness != kNoTexture) t.flags |= kSquareRoughness;
    t.thickness =
        textures.texture(ref, TextureChannels::kBlue, vec3(float(pbr.metallicFactor)), where);
  }
  // The emissive texture times emissiveFactor and KHR_materials_emissive_strength (material's
  // emission); with a factor of zero there is no emission to texture.
  if (m.emissiveTexture.index >= 0 && material.emission != vec3(0.0f)) {
    t.emission = textures.texture(textureRef(m.emissiveTexture), TextureChannels::kSrgb,
                                  material.emission, path + ".emissiveTexture");
  }
  if (m.normalTexture.index >= 0) {
    t.normalMap = textures.texture(textureRef(m.normalTexture), TextureChannels::kLinear,
                                   vec3(1.0f), path + ".normalTexture");
    if (!std::isfinite(m.normalTexture.scale)) {
      context.fail(path + ".normalTexture.scale", "expected a finite number");
    }
    t.normalScale = float(m.normalTexture.scale);
  }
  bindExtensionTextures(extensionTextures, extensions, textures, t);
  readAlpha(m, path, textures, t);
  return t;
}

}  // namespace pt::gltf
