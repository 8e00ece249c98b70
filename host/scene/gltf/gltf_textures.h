// glTF textures as the renderer's image textures (shaders/texture.h): a material's textures,
// their images decoded by the texture readers that exist (PNG, JPEG) from a file, a data URI
// or a buffer view, their sampler's wrap mode and KHR_texture_transform (offset, scale,
// rotation), times a factor; RGB, or one channel as a float texture. What the renderer cannot
// do (mirrored repeat, different wraps on the two axes, one material's textures on different
// texture coordinate sets, sets beyond TEXCOORD_1, image formats other than PNG and JPEG) is
// warned and the texture left out.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <tuple>

#include "image/texture_image.h"
#include "scene/gltf/gltf_context.h"
#include "scene/gltf/tinygltf.h"
#include "scene/scene.h"
#include "scene/textures.h"

namespace pt::gltf {

// What a material reads of a texture's image: its RGB (decoded from sRGB or linear), or one
// channel, linear, as a float texture (the metallic-roughness texture's G and B, the base
// colour's alpha, the material extensions' R, G and A).
enum class TextureChannels { kSrgb, kLinear, kRed, kGreen, kBlue, kAlpha };

// A texture reference of a material: textureInfo's fields (normalTexture's too).
struct TextureRef {
  int index = -1;
  int texCoord = 0;
  const tinygltf::ExtensionMap* extensions = nullptr;
};
template <typename Info>
TextureRef textureRef(const Info& info) {
  return TextureRef{info.index, info.texCoord, &info.extensions};
}

class TextureReader {
 public:
  TextureReader(const tinygltf::Model& model, Scene& scene, Context& context)
      : model_(model), builder_(scene), scene_(scene), context_(context) {}

  // The texture `ref` (at the JSON path `where`) times `factor`, or kNoTexture where it is left
  // out (warned), or where `channels` is kAlpha and the image has no alpha channel, or one of
  // ones (the caller takes the factor alone). Built once per texture, channels, factor and
  // transform; each image decoded once.
  uint texture(const TextureRef& ref, TextureChannels channels, vec3 factor,
               const std::string& where);
  // The texture coordinate set `ref` reads: its texCoord, or its KHR_texture_transform's.
  static int texCoordOf(const TextureRef& ref);
  // The set the textures built next read (the material's, 0 or 1); a texture of another set is
  // left out (warned): the triangles keep one set.
  void useSet(int set) { uvSet_ = set; }
  // A constant texture.
  uint constant(vec3 value) { return builder_.constant(value); }
  // The base colour's RGB (sRGB).
  uint baseColor(const tinygltf::TextureInfo& info, vec3 factor, const std::string& where) {
    return texture(textureRef(info), TextureChannels::kSrgb, factor, where);
  }

 private:
  // images[index] decoded, or null where its format is not read (warned).
  const TextureImage* decoded(std::size_t index);

  const tinygltf::Model& model_;
  TextureBuilder builder_;
  Scene& scene_;
  Context& context_;
  // A texture built: its index, channels, the factor and the mapping (KHR_texture_transform).
  using Key = std::tuple<int, int, std::array<float, 3>, std::array<float, 6>>;
  std::map<Key, uint> built_;
  std::map<std::size_t, std::optional<TextureImage>> images_;
  int uvSet_ = 0;
};

}  // namespace pt::gltf
