// glTF textures as the renderer's image textures (shaders/texture.h): a material's base colour
// texture, its image decoded by the texture readers that exist (PNG, JPEG) from a file, a data
// URI or a buffer view, its sampler's wrap mode and KHR_texture_transform's offset and scale,
// times the base colour factor. What the renderer cannot do (mirrored repeat, different wraps
// on the two axes, a rotation, a second texture coordinate set, image formats other than PNG
// and JPEG) is warned and the texture left out.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>

#include "scene/gltf/gltf_context.h"
#include "scene/gltf/tinygltf.h"
#include "scene/scene.h"
#include "scene/textures.h"

namespace pt::gltf {

class TextureReader {
 public:
  TextureReader(const tinygltf::Model& model, Scene& scene, Context& context)
      : model_(model), builder_(scene), scene_(scene), context_(context) {}

  // The texture `info` (at the JSON path `where`) times `factor`, or kNoTexture where it is left
  // out (warned). Built once per texture, factor and transform.
  uint baseColor(const tinygltf::TextureInfo& info, vec3 factor, const std::string& where);

 private:
  const tinygltf::Model& model_;
  TextureBuilder builder_;
  Scene& scene_;
  Context& context_;
  // A texture built: its index, the factor and the mapping (KHR_texture_transform).
  using Key = std::tuple<int, std::array<float, 3>, std::array<float, 4>>;
  std::map<Key, uint> built_;
};

}  // namespace pt::gltf
