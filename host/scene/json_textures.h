// The JSON format's "textures" (docs/scene-format.md): pbrt-v4's texture classes (imagemap,
// checkerboard, constant, scale, mix) with its parameter names; a material parameter names a
// texture by a string in place of its value. A texture is built when first used, as a float or
// a spectrum texture (as the parameter needs), and once per kind.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>

#include "scene/json_reader.h"
#include "scene/textures.h"

namespace pt::scene_detail {

class JsonTextures {
 public:
  JsonTextures(Scene& scene, std::filesystem::path directory)
      : builder_(scene), directory_(std::move(directory)) {}

  // Reads the "textures" array: names, classes and keys are checked here, images are read
  // when a material first uses the texture.
  void read(const JsonNode& node);

  // The texture that `value` (a string) names, as a float or a spectrum texture.
  uint use(const JsonNode& value, bool isFloat);
  // A constant texture.
  uint constant(vec3 value) { return builder_.constant(value); }

 private:
  uint build(const JsonNode& def, bool isFloat, int depth);
  // An operand of a composite texture: a number, a colour or a texture's name; `fallback`
  // (pbrt-v4's default) when absent.
  uint operand(const JsonNode& def, std::string_view key, bool isFloat, vec3 fallback, int depth);
  uint named(const JsonNode& value, bool isFloat, int depth);

  TextureBuilder builder_;
  std::filesystem::path directory_;  // image paths are relative to the scene file
  std::map<std::string, JsonNode> defs_;
  std::map<std::pair<std::string, bool>, uint> built_;
};

}  // namespace pt::scene_detail
