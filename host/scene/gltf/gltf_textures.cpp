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

}  // namespace

uint TextureReader::baseColor(const tinygltf::TextureInfo& info, vec3 factor,
                              const std::string& where) {
  if (info.index < 0 || std::size_t(info.index) >= model_.textures.size()) {
    context_.fail(where + ".index", "texture " + std::to_string(info.index) +
                                        " out of range (the file has " +
                                        std::to_string(model_.textures.size()) + ")");
  }
  ImageTextureDesc desc;  // sRGB, as glTF's base colour is stored
  int texCoord = info.texCoord;
  const auto transform = info.extensions.find("KHR_texture_transform");
  if (transform != info.extensions.end()) {
    const std::string at = where + ".extensions.KHR_texture_transform";
    const tinygltf::Value& t = transform->second;
    if (!t.IsObject()) context_.fail(at, "expected an object");
    const auto offset = pair(t, "offset", {0.0, 0.0}, at, context_);
    const auto scale = pair(t, "scale", {1.0, 1.0}, at, context_);
    if (t.Has("rotation") && t.Get("rotation").IsNumber() &&
        t.Get("rotation").GetNumberAsDouble() != 0.0) {
      context_.warnOnce("texture rotation", at + ".rotation",
                        "rotated texture coordinates are not simulated: the texture is left out");
      return kNoTexture;
    }
    if (t.Has("texCoord") && t.Get("texCoord").IsNumber()) {
      texCoord = int(t.Get("texCoord").GetNumberAsDouble());
    }
    // glTF's v runs down the image and the renderer's t up (t = 1 - v): u' = su u + ou and
    // v' = sv v + ov become s = su u + ou, t' = sv t + (1 - sv - ov).
    desc.mapping =
        vec4(float(scale[0]), float(scale[1]), float(offset[0]), float(1.0 - scale[1] - offset[1]));
  }
  if (texCoord != 0) {
    context_.warnOnce("texcoord", where + ".texCoord",
                      "textures of a second texture coordinate set are not simulated: the "
                      "texture is left out");
    return kNoTexture;
  }
  const Key key{info.index,
                {factor.x, factor.y, factor.z},
                {desc.mapping.x, desc.mapping.y, desc.mapping.z, desc.mapping.w}};
  if (const auto it = built_.find(key); it != built_.end()) return it->second;
  const std::string texturePath = indexed("textures", std::size_t(info.index));
  const tinygltf::Texture& texture = model_.textures[std::size_t(info.index)];
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
  const tinygltf::Image& image = model_.images[imageIndex];
  const std::string extension = imageExtension(image);
  const std::string imagePath = indexed("images", imageIndex);
  if (extension.empty()) {
    context_.warnOnce("image format", imagePath,
                      "'" + image.mimeType + image.uri.substr(0, 40) +
                          "' is not an image format this reader decodes (PNG, JPEG): the "
                          "texture is left out");
    return built_[key] = kNoTexture;
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
  desc.filename = context_.file() + ": " + imagePath + extension;
  const TextureImage decoded = decodeTextureImage(bytes, desc.filename);
  const uint node = builder_.image(decoded, desc, false);
  scene_.textureNodes[node].value = factor;  // the image's scale, per channel
  return built_[key] = node;
}

}  // namespace pt::gltf
