// TextureReader (gltf_textures.h).
#include "scene/gltf/gltf_textures.h"

#include <cmath>
#include <vector>

#include "image/texture_image.h"
#include "scene/json_reader.h"

namespace pt::gltf {

namespace {

// The image file extension of a MIME type or a URI, or "" for formats not read.
std::string imageExtension(const tinygltf::Image& image) {
  std::string type = image.mimeType;
  if (type.empty() && image.uri.rfind("data:", 0) == 0) {
    type = image.uri.substr(
        5, image.uri.find(';') == std::string::npos ? std::string::npos : image.uri.find(';') - 5);
  }
  if (type == "image/png") return ".png";
  if (type == "image/jpeg") return ".jpg";
  if (!type.empty()) return "";
  const std::string ext = std::filesystem::path(image.uri).extension().string();
  if (ext == ".png" || ext == ".PNG") return ".png";
  if (ext == ".jpg" || ext == ".jpeg" || ext == ".JPG" || ext == ".JPEG") return ".jpg";
  return "";
}

// A two-number array of an extension object, or `fallback`.
std::array<double, 2> pair(const tinygltf::Value& object, const char* key,
                           std::array<double, 2> fallback, const std::string& where,
                           const Context& context) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber() ||
      !std::isfinite(v.Get(0).GetNumberAsDouble()) ||
      !std::isfinite(v.Get(1).GetNumberAsDouble())) {
    context.fail(where + "." + key, "expected 2 numbers");
  }
  return {v.Get(0).GetNumberAsDouble(), v.Get(1).GetNumberAsDouble()};
}

// One channel of an image (0 R, 1 G, 2 B, 3 A; a grey image's grey for R, G and B) as a grey
// image of the same kind (bytes or floats).
TextureImage gltfImageChannel(const TextureImage& image, int channel) {
  TextureImage out;
  out.width = image.width;
  out.height = image.height;
  out.channels = 1;
  out.floatsEncoded = image.floatsEncoded;
  const std::size_t texels = std::size_t(image.width) * std::size_t(image.height);
  const std::size_t c = std::size_t(image.channels);
  const std::size_t k = c == 1 ? 0 : std::size_t(channel);
  if (image.eightBit()) {
    out.bytes.resize(texels);
    for (std::size_t i = 0; i < texels; ++i) out.bytes[i] = image.bytes[i * c + k];
  } else {
    out.floats.resize(texels);
    for (std::size_t i = 0; i < texels; ++i) out.floats[i] = image.floats[i * c + k];
  }
  return out;
}

// Whether an image's alpha channel is there and not all ones.
bool gltfImageHasAlpha(const TextureImage& image) {
  if (image.channels != 4) return false;
  const std::size_t texels = std::size_t(image.width) * std::size_t(image.height);
  for (std::size_t i = 0; i < texels; ++i) {
    if (image.eightBit() ? image.bytes[4 * i + 3] != 255 : image.floats[4 * i + 3] != 1.0f) {
      return true;
    }
  }
  return false;
}

}  // namespace

const TextureImage* TextureReader::decoded(std::size_t imageIndex) {
  if (const auto it = images_.find(imageIndex); it != images_.end()) {
    return it->second ? &*it->second : nullptr;
  }
  std::optional<TextureImage>& slot = images_[imageIndex];
  const tinygltf::Image& image = model_.images[imageIndex];
  const std::string extension = imageExtension(image);
  const std::string imagePath = indexed("images", imageIndex);
  if (extension.empty()) {
    context_.warnOnce("image format", imagePath,
                      "'" + image.mimeType + image.uri.substr(0, 40) +
                          "' is not an image format this reader decodes (PNG, JPEG): the "
                          "texture is left out");
    return nullptr;
  }
  std::vector<unsigned char> bytes = image.image;
  if (image.bufferView >= 0) {
    if (std::size_t(image.bufferView) >= model_.bufferViews.size()) {
      context_.fail(imagePath + ".bufferView",
                    "buffer view " + std::to_string(image.bufferView) + " out of range");
    }
    const tinygltf::BufferView& view = model_.bufferViews[std::size_t(image.bufferView)];
    if (view.buffer < 0 || std::size_t(view.buffer) >= model_.buffers.size() ||
        view.byteOffset > model_.buffers[std::size_t(view.buffer)].data.size() ||
        view.byteLength > model_.buffers[std::size_t(view.buffer)].data.size() - view.byteOffset) {
      context_.fail(imagePath + ".bufferView", "buffer view " + std::to_string(image.bufferView) +
                                                   " is not inside its buffer");
    }
    const auto& data = model_.buffers[std::size_t(view.buffer)].data;
    bytes.assign(data.begin() + std::ptrdiff_t(view.byteOffset),
                 data.begin() + std::ptrdiff_t(view.byteOffset + view.byteLength));
  }
  // The image is named in messages by the glTF file and its JSON path.
  slot = decodeTextureImage(bytes, context_.file() + ": " + imagePath + extension);
  return &*slot;
}

int TextureReader::texCoordOf(const TextureRef& ref) {
  int texCoord = ref.texCoord;
  const auto transform = ref.extensions->find("KHR_texture_transform");
  if (transform != ref.extensions->end() && transform->second.IsObject() &&
      transform->second.Has("texCoord") && transform->second.Get("texCoord").IsNumber()) {
    const double n = transform->second.Get("texCoord").GetNumberAsDouble();
    if (n >= 0.0 && n <= 65535.0) texCoord = int(n);
  }
  return texCoord;
}

uint TextureReader::texture(const TextureRef& ref, TextureChannels channels, vec3 factor,
                            const std::string& where) {
  if (ref.index < 0 || std::size_t(ref.index) >= model_.textures.size()) {
    context_.fail(where + ".index", "texture " + std::to_string(ref.index) +
                                        " out of range (the file has " +
                                        std::to_string(model_.textures.size()) + ")");
  }
  ImageTextureDesc desc;
  desc.encoding = channels == TextureChannels::kSrgb ? "sRGB" : "linear";
  int texCoord = ref.texCoord;
  std::string texCoordWhere = where + ".texCoord";  // where the set is named
  vec2 skew(0.0f);  // the mapping's cross terms (TextureNode::skew), where it rotates
  const auto transform = ref.extensions->find("KHR_texture_transform");
  if (transform != ref.extensions->end()) {
    const std::string at = where + ".extensions.KHR_texture_transform";
    const tinygltf::Value& t = transform->second;
    if (!t.IsObject()) context_.fail(at, "expected an object");
    const auto offset = pair(t, "offset", {0.0, 0.0}, at, context_);
    const auto scale = pair(t, "scale", {1.0, 1.0}, at, context_);
    double rotation = 0.0;
    if (t.Has("rotation")) {
      const tinygltf::Value& r = t.Get("rotation");
      if (!r.IsNumber() || !std::isfinite(r.GetNumberAsDouble())) {
        context_.fail(at + ".rotation", "expected a number");
      }
      rotation = r.GetNumberAsDouble();
    }
    if (t.Has("texCoord")) {
      const tinygltf::Value& c = t.Get("texCoord");
      const double n = c.IsNumber() ? c.GetNumberAsDouble() : -1.0;
      if (!(n >= 0.0 && n <= 65535.0 && n == std::floor(n))) {
        context_.fail(at + ".texCoord", "expected a non-negative integer");
      }
      texCoord = int(n);
      texCoordWhere = at + ".texCoord";
    }
    // The extension's u' = a u + b v + ou, v' = d u + e v + ov, its matrix T R S (a = su cos r,
    // b = -sv sin r, d = su sin r, e = sv cos r). glTF's v runs down the image and the
    // renderer's t up (t = 1 - v): s = a u - b t + (b + ou), t' = -d u + e t + (1 - e - ov).
    const double c = std::cos(rotation), sn = std::sin(rotation);
    const double a = scale[0] * c, b = -scale[1] * sn, d = scale[0] * sn, e = scale[1] * c;
    desc.mapping = vec4(float(a), float(e), float(b + offset[0]), float(1.0 - e - offset[1]));
    if (rotation != 0.0) skew = vec2(float(-b), float(-d));
  }
  if (texCoord > 1) {
    context_.warnOnce("texcoord", texCoordWhere,
                      "texture coordinate sets beyond TEXCOORD_1 are not read: the texture is "
                      "left out");
    return kNoTexture;
  }
  if (texCoord != uvSet_) {
    context_.warnOnce("texcoord sets", texCoordWhere,
                      "the material's textures read different texture coordinate sets, and "
                      "the renderer keeps one per triangle (TEXCOORD_" +
                          std::to_string(uvSet_) + "): the texture is left out");
    return kNoTexture;
  }
  const Key key{ref.index,
                int(channels),
                {factor.x, factor.y, factor.z},
                {desc.mapping.x, desc.mapping.y, desc.mapping.z, desc.mapping.w, skew.x, skew.y}};
  if (const auto it = built_.find(key); it != built_.end()) return it->second;
  const std::string texturePath = indexed("textures", std::size_t(ref.index));
  const tinygltf::Texture& texture = model_.textures[std::size_t(ref.index)];
  if (texture.source < 0 || std::size_t(texture.source) >= model_.images.size()) {
    context_.warnOnce("image format", texturePath + ".source",
                      "no image in a format this reader decodes (PNG, JPEG): the texture is "
                      "left out");
    return built_[key] = kNoTexture;
  }
  if (texture.sampler >= 0) {
    if (std::size_t(texture.sampler) >= model_.samplers.size()) {
      context_.fail(texturePath + ".sampler",
                    "sampler " + std::to_string(texture.sampler) + " out of range");
    }
    const tinygltf::Sampler& s = model_.samplers[std::size_t(texture.sampler)];
    if (s.wrapS != s.wrapT || s.wrapS == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) {
      context_.warnOnce("wrap", indexed("samplers", std::size_t(texture.sampler)),
                        "mirrored repeat, or different wrap modes along s and t, are not "
                        "simulated: repeat is used");
    } else if (s.wrapS == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) {
      desc.wrap = kWrapClamp;
    }
    if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) desc.filter = kTexturePoint;
  }
  const std::size_t imageIndex = std::size_t(texture.source);
  const TextureImage* image = decoded(imageIndex);
  if (image == nullptr) return built_[key] = kNoTexture;
  desc.filename = context_.file() + ": " + indexed("images", imageIndex);
  uint node = kNoTexture;
  if (channels == TextureChannels::kSrgb || channels == TextureChannels::kLinear) {
    node = builder_.image(*image, desc, false);
  } else if (channels == TextureChannels::kAlpha) {
    if (!gltfImageHasAlpha(*image)) return built_[key] = kNoTexture;
    node = builder_.image(gltfImageChannel(*image, 3), desc, true);
  } else {
    const int channel = channels == TextureChannels::kRed     ? 0
                        : channels == TextureChannels::kGreen ? 1
                                                              : 2;
    node = builder_.image(gltfImageChannel(*image, channel), desc, true);
  }
  scene_.textureNodes[node].value = factor;  // the image's scale, per channel
  if (skew != vec2(0.0f)) {
    scene_.textureNodes[node].skew = skew;
    scene_.textureNodes[node].flags |= kTextureSkewed;
  }
  return built_[key] = node;
}

}  // namespace pt::gltf
