// Image files: EXR via tinyexr, PFM by hand, PNG via stb_image_write, plus the sRGB curve.
// Every format is encoded to and decoded from memory, so file access and its errors live in one
// place (file_io.cpp); decoding is shared with the texture reader (texture_image.cpp).

#include "image/image.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <system_error>

#include <tinyexr.h>

// stb_image_write is compiled into this file only, with internal linkage: ptcore also links
// Debian's libstb, and static definitions keep the two copies from interposing on each other.
// It does not touch files: we do all file I/O ourselves. The decoders, stb_image's among them,
// are in texture_image.cpp.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>

#include "image/file_io.h"
#include "image/image_decode.h"

namespace pt {
namespace {

namespace fs = std::filesystem;
using image_detail::fail;
using image_detail::takeExrError;

// ---- sRGB -----------------------------------------------------------------------------------

double encodeSrgb(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double decodeSrgb(double encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

// ---- PFM ------------------------------------------------------------------------------------

// Header "PF\n<w> <h>\n-1.0\n" (negative scale: little-endian), then rows bottom to top.
Bytes encodePfm(const Image& image) {
  const std::string header =
      "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
  Bytes bytes(header.begin(), header.end());
  bytes.reserve(header.size() + image.pixels.size() * 12);
  for (int y = image.height - 1; y >= 0; --y) {
    for (int x = 0; x < image.width; ++x) {
      const glm::vec3& p = image.at(x, y);
      for (int c = 0; c < 3; ++c) {
        // Byte by byte, so the file is little-endian whatever the host is.
        const uint32_t bits = std::bit_cast<uint32_t>(p[c]);
        for (int b = 0; b < 4; ++b) bytes.push_back(static_cast<unsigned char>(bits >> (8 * b)));
      }
    }
  }
  return bytes;
}

// ---- EXR ------------------------------------------------------------------------------------

Bytes encodeExr(const Image& image, const fs::path& path) {
  // OpenEXR keeps channels sorted by name, so B, G, R is the order in the file; readers match
  // channels by name, so they still see R as red. tinyexr wants planar data in that order.
  const size_t n = image.pixels.size();
  std::vector<float> planes[3] = {std::vector<float>(n), std::vector<float>(n),
                                  std::vector<float>(n)};
  for (size_t i = 0; i < n; ++i) {
    planes[0][i] = image.pixels[i].b;
    planes[1][i] = image.pixels[i].g;
    planes[2][i] = image.pixels[i].r;
  }
  unsigned char* planePointers[3] = {reinterpret_cast<unsigned char*>(planes[0].data()),
                                     reinterpret_cast<unsigned char*>(planes[1].data()),
                                     reinterpret_cast<unsigned char*>(planes[2].data())};

  EXRChannelInfo channels[3] = {};
  std::strcpy(channels[0].name, "B");
  std::strcpy(channels[1].name, "G");
  std::strcpy(channels[2].name, "R");
  // Stored as 32-bit float, not half: renders are references and must round-trip exactly.
  int pixelTypes[3] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT};
  int storedTypes[3] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT};

  // The header and image point at our own arrays, so they are not passed to FreeEXR*.
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = 3;
  header.channels = channels;
  header.pixel_types = pixelTypes;
  header.requested_pixel_types = storedTypes;
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;  // lossless
  EXRImage exr;
  InitEXRImage(&exr);
  exr.num_channels = 3;
  exr.images = planePointers;
  exr.width = image.width;
  exr.height = image.height;

  unsigned char* memory = nullptr;
  const char* err = nullptr;
  const size_t size = SaveEXRImageToMemory(&exr, &header, &memory, &err);
  if (size == 0 || !memory) {
    std::free(memory);
    fail(path, "cannot encode EXR: " + takeExrError(err));
  }
  Bytes bytes(memory, memory + size);
  std::free(memory);
  return bytes;
}

// ---- PNG ------------------------------------------------------------------------------------

Bytes encodePng(const Image& image, const fs::path& path) {
  Bytes rgb(image.pixels.size() * 3);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) rgb[3 * i + size_t(c)] = linearToSrgb8(image.pixels[i][c]);
  }
  Bytes png;
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<Bytes*>(context);
    const auto* bytes = static_cast<const unsigned char*>(data);
    out->insert(out->end(), bytes, bytes + size);
  };
  if (uint64_t(image.width) * 3 > uint64_t(INT_MAX) ||
      !stbi_write_png_to_func(append, &png, image.width, image.height, 3, rgb.data(),
                              image.width * 3)) {
    fail(path, "cannot encode PNG");
  }
  return png;
}

}  // namespace

float linearToSrgb(float linear) {
  return float(encodeSrgb(linear));
}

float srgbToLinear(float encoded) {
  return float(decodeSrgb(encoded));
}

ImageFormat imageFormatOf(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr") return ImageFormat::kExr;
  if (ext == ".pfm") return ImageFormat::kPfm;
  if (ext == ".png") return ImageFormat::kPng;
  if (ext.empty()) fail(path, "no image file extension (expected .exr, .pfm or .png)");
  fail(path, "unknown image file extension '" + path.extension().string() +
                 "' (expected .exr, .pfm or .png)");
}

uint8_t linearToSrgb8(float linear) {
  if (!(linear > 0.0f)) return 0;  // also NaN
  if (linear >= 1.0f) return 255;
  return uint8_t(encodeSrgb(linear) * 255.0 + 0.5);
}

void writeImage(const Image& image, const std::filesystem::path& path) {
  const ImageFormat format = imageFormatOf(path);
  PT_CHECK(image.width >= 0 && image.height >= 0 &&
               image.pixels.size() == size_t(image.width) * size_t(image.height),
           "image pixel count does not match its size");
  if (image.width == 0 || image.height == 0) fail(path, "cannot write an empty image");
  switch (format) {
    case ImageFormat::kExr:
      writeFileAtomically(path, encodeExr(image, path));
      break;
    case ImageFormat::kPfm:
      writeFileAtomically(path, encodePfm(image));
      break;
    case ImageFormat::kPng:
      writeFileAtomically(path, encodePng(image, path));
      break;
  }
}

Image readImage(const std::filesystem::path& path) {
  // Radiance RGBE (.hdr) is read, not written: it is not one of the ImageFormats.
  std::string ext = path.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  using image_detail::FileFormat;
  FileFormat fileFormat = FileFormat::kHdr;
  if (ext != ".hdr") {
    const ImageFormat format = imageFormatOf(path);
    fileFormat = format == ImageFormat::kExr   ? FileFormat::kExr
                 : format == ImageFormat::kPfm ? FileFormat::kPfm
                                               : FileFormat::kPng;
  }
  const Bytes bytes = readWholeFile(path, "an image file");
  image_detail::DecodeOptions options;
  options.rgbOnly = true;
  options.limitTexels = false;
  options.callerBytesPerTexel = sizeof(glm::vec3);
  options.resultName = "the float image";
  const TextureImage texels = image_detail::decode(bytes, path, fileFormat, options);
  // To linear RGB: grey replicated, alpha dropped; PNG decoded from sRGB (8-bit by a table).
  Image image(texels.width, texels.height);
  const size_t channels = size_t(texels.channels);
  float table[256];
  for (int v = 0; v < 256; ++v) table[v] = float(decodeSrgb(v / 255.0));
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    for (size_t c = 0; c < 3; ++c) {
      const size_t k = i * channels + (channels >= 3 ? c : 0);
      float value = 0.0f;
      if (texels.eightBit()) {
        value = table[texels.bytes[k]];
      } else if (texels.floatsEncoded) {
        value = srgbToLinear(texels.floats[k]);
      } else {
        value = texels.floats[k];
      }
      image.pixels[i][c] = value;
    }
  }
  return image;
}

}  // namespace pt
