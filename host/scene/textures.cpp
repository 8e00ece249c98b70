#include "scene/textures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "common/check.h"
#include "image/texture_image.h"
#include "scene/mip_pyramid.h"
#include "scene/reader_helpers.h"
#include "texture.h"

namespace pt {

namespace {

uint floatWord(float f) {
  uint w;
  std::memcpy(&w, &f, sizeof w);
  return w;
}

// The sRGB curve's decoding (IEC 61966-2-1), in double.
double srgbDecode(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// A value of an encoded channel in [0, 1] made linear: sRGB (gamma 0) or the power gamma.
double decodeEncoded(double c, double gamma) {
  return gamma == 0.0 ? srgbDecode(c) : std::pow(c, gamma);
}

// A linear value encoded to a byte, as pbrt-v4 stores its 8-bit MIP levels: rounded in the
// encoded domain (sRGB, gamma 0, or the power gamma), 0 and 255 beyond [0, 1]. The byte is the
// number of thresholds at or below v: thresholds[b - 1] is where round(255 encode(v)) reaches
// b, the linear value of the encoded (b - 1/2) / 255.
// Rather than search all 255 thresholds, the count starts from what it is at the smallest
// float sharing v's top 17 bits (start, by those bits, for the floats below the last
// threshold, which all lie below 1) and steps up from there: the same count.
struct ByteEncoder {
  static constexpr int kKeyShift = 15;
  std::array<float, 255> thresholds{};
  std::vector<uint8_t> start;
  explicit ByteEncoder(double gamma) {
    for (int b = 1; b <= 255; ++b) {
      thresholds[std::size_t(b - 1)] = float(decodeEncoded((b - 0.5) / 255.0, gamma));
    }
    const uint keys = (floatWord(thresholds[254]) >> kKeyShift) + 1u;
    start.resize(keys);
    std::size_t below = 0;  // thresholds at or below the key's smallest float
    for (uint key = 0; key < keys; ++key) {
      const float smallest = uintBitsToFloat(key << kKeyShift);
      while (below < 255 && thresholds[below] <= smallest) ++below;
      start[key] = uint8_t(below);
    }
  }
  uint operator()(float v) const {
    if (!(v > 0.0f)) return 0u;
    if (v >= thresholds[254]) return 255u;
    uint b = start[floatWord(v) >> kKeyShift];
    while (thresholds[b] <= v) ++b;
    return b;
  }
};

}  // namespace

bool parseColorEncoding(const std::string& encoding, double& gamma) {
  if (encoding == "sRGB") {
    gamma = 0.0;
    return true;
  }
  if (encoding == "linear") {
    gamma = 1.0;
    return true;
  }
  if (encoding.rfind("gamma ", 0) == 0) {
    const std::string number = encoding.substr(6);
    char* end = nullptr;
    const double g = std::strtod(number.c_str(), &end);
    if (end != number.c_str() && *end == '\0' && std::isfinite(g) && g > 0.0) {
      gamma = g;
      return true;
    }
  }
  return false;
}

bool parseWrapMode(const std::string& name, uint& wrap) {
  if (name == "repeat") {
    wrap = kWrapRepeat;
  } else if (name == "clamp") {
    wrap = kWrapClamp;
  } else if (name == "black") {
    wrap = kWrapBlack;
  } else {
    return false;
  }
  return true;
}

bool parseTextureFilter(const std::string& name, uint& filter) {
  if (name == "point") {
    filter = kTexturePoint;
  } else if (name == "bilinear") {
    filter = kTextureBilinear;
  } else if (name == "trilinear") {
    filter = kTextureTrilinear;
  } else if (name == "ewa" || name == "EWA") {
    filter = kTextureEwa;
  } else {
    return false;
  }
  return true;
}

void setMaterialTextures(Scene& scene, std::size_t material, const MaterialTextures& t) {
  PT_CHECK(material < scene.materials.size(), "textures for a material that does not exist");
  if (scene.materialTextures.empty() && !anyTexture(t)) return;
  scene.materialTextures.resize(scene.materials.size(), noMaterialTextures());
  scene.materialTextures[material] = t;
}

void padMaterialTextures(Scene& scene) {
  if (scene.materialTextures.empty()) return;
  scene.materialTextures.resize(scene.materials.size(), noMaterialTextures());
}

uint TextureBuilder::constant(vec3 value) {
  TextureNode node{};
  node.type = kTextureConstant;
  node.value = value;
  node.count = 1;
  scene_.textureNodes.push_back(node);
  return uint(scene_.textureNodes.size() - 1);
}

// One table of 256 floats per encoding, in the image buffer: what each byte value decodes to.
uint TextureBuilder::decodeTable(double gamma) {
  const auto found = decodeTables_.find(gamma);
  if (found != decodeTables_.end()) return found->second;
  const uint at = uint(scene_.imageWords.size());
  for (int b = 0; b < 256; ++b) {
    scene_.imageWords.push_back(floatWord(float(decodeEncoded(b / 255.0, gamma))));
  }
  decodeTables_.emplace(gamma, at);
  return at;
}

const TextureBuilder::StoredImage& TextureBuilder::storeImage(const std::filesystem::path& path,
                                                              const std::string& encoding,
                                                              uint wrap) {
  double gamma = 0.0;
  if (!parseColorEncoding(encoding, gamma)) {
    throw InputError(path.string() + ": unknown colour encoding '" + encoding +
                     "' (expected \"sRGB\", \"linear\" or \"gamma <g>\" with g > 0)");
  }
  const auto key = std::make_tuple(path.lexically_normal().string(), encoding, wrap);
  const auto found = images_.find(key);
  if (found != images_.end()) return found->second;
  return images_.emplace(key, storeDecoded(readTextureImage(path), path, encoding, wrap))
      .first->second;
}

TextureBuilder::StoredImage TextureBuilder::storeDecoded(const TextureImage& image,
                                                         const std::filesystem::path& path,
                                                         const std::string& encoding, uint wrap) {
  double gamma = 0.0;
  if (!parseColorEncoding(encoding, gamma)) {
    throw InputError(path.string() + ": unknown colour encoding '" + encoding +
                     "' (expected \"sRGB\", \"linear\" or \"gamma <g>\" with g > 0)");
  }
  PT_CHECK(image.width > 0 && image.height > 0, "an image reader returned an empty image");
  PT_CHECK(image.channels == 1 || image.channels == 3 || image.channels == 4,
           "an image reader returned " + std::to_string(image.channels) + " channels");
  const std::size_t texels = std::size_t(image.width) * std::size_t(image.height);
  const std::size_t c = std::size_t(image.channels);
  StoredImage stored;
  stored.width = uint(image.width);
  stored.height = uint(image.height);
  // What a float texture reads (pbrt-v4's MIPMap): the grey channel, the alpha where some
  // texel is not opaque (it drops an alpha channel of ones), else the average of R, G, B.
  bool opaque = true;
  if (c == 4) {
    for (std::size_t i = 0; i < texels && opaque; ++i) {
      opaque = image.eightBit() ? image.bytes[4 * i + 3] == 255 : image.floats[4 * i + 3] == 1.0f;
    }
  }
  stored.floatChannel = c == 1                ? kFloatChannelFirst
                        : (c == 4 && !opaque) ? kFloatChannelAlpha
                                              : kFloatChannelAverage;
  const std::size_t words = image.eightBit() ? texels : texels * (c == 1 ? 1 : c == 3 ? 3 : 4);
  if (scene_.imageWords.size() + words + 256 > std::size_t(UINT32_MAX)) {
    throw InputError(path.string() + ": the scene's images exceed 2^32 words (16 GiB)");
  }
  if (image.eightBit()) {
    stored.format = kTexel8;
    stored.decode = decodeTable(gamma);
    stored.texels = uint(scene_.imageWords.size());
    reserveGeometric(scene_.imageWords, scene_.imageWords.size() + texels);
    for (std::size_t i = 0; i < texels; ++i) {
      const uint8_t* t = &image.bytes[c * i];
      const uint r = t[0];
      const uint g = c >= 3 ? t[1] : t[0];
      const uint b = c >= 3 ? t[2] : t[0];
      const uint a = c == 4 ? t[3] : 255u;
      scene_.imageWords.push_back(r | g << 8 | b << 16 | a << 24);
    }
  } else {
    stored.format = c == 1 ? kTexelFloat1 : c == 3 ? kTexelFloat3 : kTexelFloat4;
    stored.texels = uint(scene_.imageWords.size());
    reserveGeometric(scene_.imageWords, scene_.imageWords.size() + texels * c);
    for (std::size_t i = 0; i < texels * c; ++i) {
      float v = image.floats[i];
      // 16-bit PNGs hold encoded values, decoded here as pbrt-v4 decodes them (to half floats;
      // we keep floats).
      if (image.floatsEncoded) v = float(decodeEncoded(std::clamp(double(v), 0.0, 1.0), gamma));
      if (!std::isfinite(v)) {
        throw InputError(path.string() + ": texel " + std::to_string(i / c) + " (row " +
                         std::to_string(i / c / std::size_t(image.width)) +
                         ") is not a finite number");
      }
      scene_.imageWords.push_back(floatWord(v));
    }
  }
  storeMipLevels(stored, int(c), gamma, wrap);
  return stored;
}

// The MIP map of the image just stored at stored.texels (mip_pyramid.h), its levels after it
// in the same format (8-bit levels encoded as the image is, as pbrt-v4 keeps them), then the
// table of where each level starts. An image whose sides are powers of two keeps its texels
// as level 0; another's level 0 is its resampled image.
void TextureBuilder::storeMipLevels(StoredImage& stored, int channels, double gamma, uint wrap) {
  const bool eightBit = stored.format == kTexel8;
  FloatImage image;
  image.width = int(stored.width);
  image.height = int(stored.height);
  // The channels the image has (an 8-bit grey or RGB image's words repeat grey and hold an
  // alpha of 255, which its levels repeat likewise).
  image.channels = channels;
  image.reserveValues();
  const std::size_t texels = std::size_t(stored.width) * std::size_t(stored.height);
  for (std::size_t i = 0; i < texels; ++i) {
    if (eightBit) {
      const uint w = scene_.imageWords[stored.texels + i];
      for (int c = 0; c < channels; ++c) {
        image.values.push_back(
            uintBitsToFloat(scene_.imageWords[stored.decode + ((w >> (8 * c)) & 0xFFu)]));
      }
    } else {
      for (int c = 0; c < channels; ++c) {
        image.values.push_back(uintBitsToFloat(
            scene_.imageWords[stored.texels + i * std::size_t(channels) + std::size_t(c)]));
      }
    }
  }
  const bool resized = !isPowerOfTwo(image.width) || !isPowerOfTwo(image.height);
  std::vector<FloatImage> pyramid = mipPyramid(std::move(image), wrap);
  std::size_t words = pyramid.size();
  for (std::size_t level = resized ? 0 : 1; level < pyramid.size(); ++level) {
    words += pyramid[level].values.size() / (eightBit ? std::size_t(channels) : 1);
  }
  if (scene_.imageWords.size() + words > std::size_t(UINT32_MAX)) {
    throw InputError("the scene's images and their MIP maps exceed 2^32 words (16 GiB)");
  }
  reserveGeometric(scene_.imageWords, scene_.imageWords.size() + words);
  std::vector<uint> starts(pyramid.size(), stored.texels);
  const ByteEncoder encode(gamma);
  for (std::size_t level = resized ? 0 : 1; level < pyramid.size(); ++level) {
    const FloatImage& l = pyramid[level];
    starts[level] = uint(scene_.imageWords.size());
    if (eightBit) {
      const std::size_t c = std::size_t(channels);
      for (std::size_t i = 0; i < l.values.size(); i += c) {
        const uint r = encode(l.values[i]);
        const uint g = c >= 3 ? encode(l.values[i + 1]) : r;
        const uint b = c >= 3 ? encode(l.values[i + 2]) : r;
        const uint a = c == 4 ? encode(l.values[i + 3]) : 255u;
        scene_.imageWords.push_back(r | g << 8 | b << 16 | a << 24);
      }
    } else {
      for (float v : l.values) scene_.imageWords.push_back(floatWord(v));
    }
  }
  stored.texels = starts[0];
  stored.width = uint(pyramid[0].width);
  stored.height = uint(pyramid[0].height);
  stored.levelCount = uint(pyramid.size());
  stored.levels = uint(scene_.imageWords.size());
  scene_.imageWords.insert(scene_.imageWords.end(), starts.begin(), starts.end());
}

uint TextureBuilder::image(const ImageTextureDesc& desc, bool isFloat) {
  return imageNode(storeImage(desc.filename, desc.encoding, desc.wrap), desc, isFloat);
}

uint TextureBuilder::image(const TextureImage& image, const ImageTextureDesc& desc, bool isFloat) {
  return imageNode(storeDecoded(image, desc.filename, desc.encoding, desc.wrap), desc, isFloat);
}

uint TextureBuilder::imageNode(const StoredImage& stored, const ImageTextureDesc& desc,
                               bool isFloat) {
  TextureNode node{};
  node.type = kTextureImage;
  node.value = vec3(desc.scale);
  node.mapping = desc.mapping;
  node.texels = stored.texels;
  node.width = stored.width;
  node.height = stored.height;
  node.decode = stored.decode;
  node.flags = stored.format | desc.wrap << 4 | desc.filter << 8 | stored.floatChannel << 12 |
               (desc.invert ? kTextureInvert : 0u) | (isFloat ? kTextureFloat : 0u) |
               stored.levelCount << kTextureLevelsShift;
  node.levels = stored.levels;
  node.maxAnisotropy = desc.maxAnisotropy;
  node.count = 1;
  scene_.textureNodes.push_back(node);
  return uint(scene_.textureNodes.size() - 1);
}

uint TextureBuilder::composite(std::vector<uint> operands, TextureNode node) {
  std::vector<TextureNode> program;
  for (uint first : operands) {
    PT_CHECK(first < scene_.textureNodes.size(), "a texture index beyond the nodes");
    const uint count = scene_.textureNodes[first].count;
    for (uint i = 0; i < count; ++i) {
      TextureNode copy = scene_.textureNodes[first + i];
      copy.count = 0;
      program.push_back(copy);
    }
  }
  program.push_back(node);
  if (program.size() > kMaxProgram) {
    throw InputError("the texture combines more than " + std::to_string(kMaxProgram) + " textures");
  }
  program.front().count = uint(program.size());
  const uint first = uint(scene_.textureNodes.size());
  scene_.textureNodes.insert(scene_.textureNodes.end(), program.begin(), program.end());
  if (stackDepth(first) > kTextureStackSize) {
    scene_.textureNodes.resize(first);
    throw InputError("the texture nests textures more than " + std::to_string(kTextureStackSize) +
                     " deep");
  }
  return first;
}

uint TextureBuilder::stackDepth(uint first) const {
  uint top = 0;
  uint deepest = 0;
  const uint count = scene_.textureNodes[first].count;
  for (uint i = 0; i < count; ++i) {
    const uint type = scene_.textureNodes[first + i].type;
    const uint pops = type == kTextureCheckerboard || type == kTextureScale ? 2
                      : type == kTextureMix                                 ? 3
                                                                            : 0;
    PT_CHECK(top >= pops, "a texture program pops more than it pushed");
    top = top - pops + 1;
    deepest = std::max(deepest, top);
  }
  PT_CHECK(top == 1, "a texture program leaves other than one value");
  return deepest;
}

uint TextureBuilder::checkerboard(vec4 mapping, uint tex1, uint tex2) {
  TextureNode node{};
  node.type = kTextureCheckerboard;
  node.mapping = mapping;
  return composite({tex1, tex2}, node);
}

uint TextureBuilder::scale(uint tex, uint scale) {
  TextureNode node{};
  node.type = kTextureScale;
  return composite({tex, scale}, node);
}

uint TextureBuilder::mix(uint tex1, uint tex2, uint amount) {
  TextureNode node{};
  node.type = kTextureMix;
  return composite({tex1, tex2, amount}, node);
}

}  // namespace pt
