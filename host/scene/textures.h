// Builds a scene's textures (shaders/texture.h's programs and the image buffer they read) for
// the scene readers: pbrt-v4's Texture directives, the JSON format's "textures", MTL maps.
// Each image file is read and decoded once per colour encoding, however many textures use it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "image/texture_image.h"
#include "scene/scene.h"

namespace pt {

// An imagemap texture's parameters, pbrt-v4's names and defaults.
struct ImageTextureDesc {
  std::filesystem::path filename;
  // How 8-bit images are decoded: "sRGB" (pbrt-v4's default), "linear", or "gamma <g>". Float
  // images (EXR, PFM, HDR) are linear whatever it says; 16-bit PNGs are decoded by it too.
  std::string encoding = "sRGB";
  uint wrap = kWrapRepeat;
  uint filter = kTextureBilinear;
  float maxAnisotropy = 8.0f;  // the EWA filter's longest ellipse over its shortest
  float scale = 1.0f;
  bool invert = false;
  vec4 mapping{1.0f, 1.0f, 0.0f, 0.0f};  // uscale, vscale, udelta, vdelta
};

// The colour encodings pbrt-v4 accepts ("sRGB", "linear", "gamma <g>" with g > 0); false for
// anything else. gamma: 0 for sRGB, the exponent otherwise (1 for linear).
bool parseColorEncoding(const std::string& encoding, double& gamma);

// pbrt-v4's wrap mode names ("repeat", "clamp", "black"); false for anything else.
bool parseWrapMode(const std::string& name, uint& wrap);

// pbrt-v4's image filter names ("point", "bilinear", "trilinear", "ewa" or "EWA"); false for
// anything else.
bool parseTextureFilter(const std::string& name, uint& filter);

// A material's textures where it has none: every parameter its own value.
inline MaterialTextures noMaterialTextures() {
  MaterialTextures t{};
  t.reflectance = t.transmittance = t.uRoughness = t.vRoughness = kNoTexture;
  t.eta = t.k = t.displacement = t.alpha = t.thickness = t.g = kNoTexture;
  t.emission = t.normalMap = kNoTexture;
  t.transmission = t.clearcoat = t.clearcoatRoughness = t.specular = t.specularColour = kNoTexture;
  t.sheenColour = t.sheenRoughness = t.clearcoatNormal = kNoTexture;
  t.scale = 1.0f;
  t.normalScale = 1.0f;
  return t;
}

// Sets the textures of scene.materials[material], making scene.materialTextures parallel to
// scene.materials first (noMaterialTextures for the others) unless t has none.
void setMaterialTextures(Scene& scene, std::size_t material, const MaterialTextures& t);

// Makes scene.materialTextures parallel to scene.materials where some material has textures
// (the readers call it once the scene is read: materials added after the last textured one).
void padMaterialTextures(Scene& scene);

class TextureBuilder {
 public:
  explicit TextureBuilder(Scene& scene) : scene_(scene) {}

  // Each returns the texture's index (its program's first node in scene.textureNodes).
  uint constant(vec3 value);
  // Reads the image (once per file and encoding); InputError "<file>: <problem>" for an
  // unreadable or malformed image or an unknown encoding.
  uint image(const ImageTextureDesc& desc, bool isFloat);
  // The same for an image in memory (desc.filename only names it in messages), not cached.
  uint image(const TextureImage& image, const ImageTextureDesc& desc, bool isFloat);
  uint checkerboard(vec4 mapping, uint tex1, uint tex2);
  uint scale(uint tex, uint scale);
  uint mix(uint tex1, uint tex2, uint amount);

  // The deepest stack a program may need and the longest program, beyond which the
  // composite functions throw InputError (the caller names the texture).
  static constexpr uint kMaxProgram = 64;

 private:
  struct StoredImage {
    uint texels = 0;
    uint width = 0;
    uint height = 0;
    uint format = kTexel8;
    uint decode = 0;
    uint floatChannel = kFloatChannelFirst;
    uint levels = 0;      // the MIP map's table of level starts
    uint levelCount = 1;  // its levels
  };
  // Images are kept per file, encoding and wrap mode (which the MIP map's resampling reads).
  const StoredImage& storeImage(const std::filesystem::path& path, const std::string& encoding,
                                uint wrap);
  StoredImage storeDecoded(const TextureImage& image, const std::filesystem::path& path,
                           const std::string& encoding, uint wrap);
  // channels: the image's own (1, 3 or 4).
  void storeMipLevels(StoredImage& stored, int channels, double gamma, uint wrap);
  uint imageNode(const StoredImage& stored, const ImageTextureDesc& desc, bool isFloat);
  uint decodeTable(double gamma);
  uint composite(std::vector<uint> operands, TextureNode node);
  // The stack depth a program needs.
  uint stackDepth(uint first) const;

  Scene& scene_;
  std::map<std::tuple<std::string, std::string, uint>, StoredImage> images_;
  std::map<double, uint> decodeTables_;
};

}  // namespace pt
