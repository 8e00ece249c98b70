// readExtensionTextureInfos, bindExtensionTextures (gltf_extension_textures.h).
#include "scene/gltf/gltf_extension_textures.h"

#include <cmath>

namespace pt::gltf {

namespace {

// A non-negative integer of a textureInfo object, or `fallback` where it is absent.
int textureInfoInteger(const tinygltf::Value& object, const char* key, int fallback,
                       const std::string& where, const Context& context) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  const double n = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
  if (!(n >= 0.0 && n <= 2147483647.0 && n == std::floor(n))) {
    context.fail(where + "." + key, "expected a non-negative integer");
  }
  return int(n);
}

// extension.key, a textureInfo, where the extension object has it.
ExtensionTextureInfo textureInfoOf(const tinygltf::Value& extension, const char* key,
                                   const std::string& where, const Context& context) {
  ExtensionTextureInfo info;
  if (!extension.IsObject() || !extension.Has(key)) return info;
  info.where = where + "." + key;
  const tinygltf::Value& object = extension.Get(key);
  if (!object.IsObject()) context.fail(info.where, "expected an object");
  if (!object.Has("index")) context.fail(info.where + ".index", "required");
  info.index = textureInfoInteger(object, "index", -1, info.where, context);
  info.texCoord = textureInfoInteger(object, "texCoord", 0, info.where, context);
  if (object.Has("scale")) {
    const tinygltf::Value& scale = object.Get("scale");
    if (!scale.IsNumber() || !std::isfinite(scale.GetNumberAsDouble())) {
      context.fail(info.where + ".scale", "expected a finite number");
    }
    info.scale = scale.GetNumberAsDouble();
  }
  if (object.Has("extensions")) {
    const tinygltf::Value& extensions = object.Get("extensions");
    if (!extensions.IsObject()) context.fail(info.where + ".extensions", "expected an object");
    for (const std::string& name : extensions.Keys()) info.extensions[name] = extensions.Get(name);
  }
  return info;
}

}  // namespace

ExtensionTextureInfos readExtensionTextureInfos(const tinygltf::Material& m,
                                                const std::string& path, const Context& context) {
  ExtensionTextureInfos infos;
  for (const auto& [name, value] : m.extensions) {
    const std::string where = path + ".extensions." + name;
    if (name == "KHR_materials_transmission") {
      infos.transmission = textureInfoOf(value, "transmissionTexture", where, context);
    } else if (name == "KHR_materials_clearcoat") {
      infos.clearcoat = textureInfoOf(value, "clearcoatTexture", where, context);
      infos.clearcoatRoughness = textureInfoOf(value, "clearcoatRoughnessTexture", where, context);
      infos.clearcoatNormal = textureInfoOf(value, "clearcoatNormalTexture", where, context);
    } else if (name == "KHR_materials_specular") {
      infos.specular = textureInfoOf(value, "specularTexture", where, context);
      infos.specularColour = textureInfoOf(value, "specularColorTexture", where, context);
    } else if (name == "KHR_materials_sheen") {
      infos.sheenColour = textureInfoOf(value, "sheenColorTexture", where, context);
      infos.sheenRoughness = textureInfoOf(value, "sheenRoughnessTexture", where, context);
    }
  }
  return infos;
}

namespace {

// Each extension texture with its factor, and whether it is read (present, the factor not 0).
struct ExtensionTextureUse {
  const ExtensionTextureInfo* info;
  bool read;
};
std::vector<ExtensionTextureUse> extensionTextureUses(const ExtensionTextureInfos& infos,
                                                      const MaterialExtensions& f) {
  const bool coated = f.clearcoat > 0.0;
  const bool sheen = (f.flags & kGltfSheen) != 0u;
  return {
      {&infos.transmission, infos.transmission.index >= 0 && f.transmission > 0.0},
      {&infos.clearcoat, infos.clearcoat.index >= 0 && coated},
      {&infos.clearcoatRoughness,
       infos.clearcoatRoughness.index >= 0 && coated && f.clearcoatRoughness > 0.0},
      {&infos.specular, infos.specular.index >= 0 && f.specular > 0.0},
      {&infos.specularColour, infos.specularColour.index >= 0 && f.specularColour != vec3(0.0f)},
      {&infos.sheenColour, infos.sheenColour.index >= 0 && sheen},
      {&infos.sheenRoughness, infos.sheenRoughness.index >= 0 && sheen && f.sheenRoughness > 0.0},
      {&infos.clearcoatNormal, infos.clearcoatNormal.index >= 0 && coated}};
}

}  // namespace

std::vector<TextureRef> readExtensionTextureRefs(const ExtensionTextureInfos& infos,
                                                 const MaterialExtensions& factors) {
  std::vector<TextureRef> refs;
  for (const ExtensionTextureUse& use : extensionTextureUses(infos, factors)) {
    if (use.read) refs.push_back(use.info->ref());
  }
  return refs;
}

void bindExtensionTextures(const ExtensionTextureInfos& infos, const MaterialExtensions& f,
                           TextureReader& textures, MaterialTextures& t) {
  const std::vector<ExtensionTextureUse> uses = extensionTextureUses(infos, f);
  const auto bind = [&](const ExtensionTextureUse& use, TextureChannels channels, vec3 factor) {
    if (!use.read) return kNoTexture;
    return textures.texture(use.info->ref(), channels, factor, use.info->where);
  };
  // transmissionFactor x R, clearcoatFactor x R, clearcoatRoughnessFactor x G (squared to the
  // coat's alpha at the hit), specularFactor x A (an image without alpha: the factor alone),
  // specularColorFactor x RGB (sRGB).
  t.transmission = bind(uses[0], TextureChannels::kRed, vec3(float(f.transmission)));
  t.clearcoat = bind(uses[1], TextureChannels::kRed, vec3(float(f.clearcoat)));
  t.clearcoatRoughness = bind(uses[2], TextureChannels::kGreen, vec3(float(f.clearcoatRoughness)));
  t.specular = bind(uses[3], TextureChannels::kAlpha, vec3(float(f.specular)));
  t.specularColour = bind(uses[4], TextureChannels::kSrgb, f.specularColour);
  // sheenColorFactor x RGB (sRGB), sheenRoughnessFactor x A, the coat's normal map as the core
  // normalTexture is read (RGB, linear; texture.h's normalMappedNormal, its scale in t.scale).
  t.sheenColour = bind(uses[5], TextureChannels::kSrgb, f.sheenColour);
  t.sheenRoughness = bind(uses[6], TextureChannels::kAlpha, vec3(float(f.sheenRoughness)));
  t.clearcoatNormal = bind(uses[7], TextureChannels::kLinear, vec3(1.0f));
  if (t.clearcoatNormal != kNoTexture) t.scale = float(infos.clearcoatNormal.scale);
}

}  // namespace pt::gltf
