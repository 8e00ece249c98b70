// Image files as textures and environment maps need them: the texels as stored (8-bit, still
// encoded) or as floats, with the file's channel count. readImage (image.h) reads the same
// files as linear RGB.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace pt {

// An image file as a texture or an environment map reads it, row 0 at the top, texels
// row-major, channels interleaved.
struct TextureImage {
  int width = 0;
  int height = 0;
  int channels = 0;            // 1 (grey), 3 (RGB) or 4 (RGBA); grey+alpha files become 4
  std::vector<uint8_t> bytes;  // 8-bit files (PNG of 8 bits or less, JPEG, TGA, BMP): as encoded
  std::vector<float> floats;   // EXR, PFM, HDR: linear; 16-bit PNG: value / 65535, still encoded
  bool floatsEncoded = false;  // true for 16-bit PNG: the caller applies the colour encoding
  bool eightBit() const { return !bytes.empty(); }
};

// Reads by extension (any case): .png, .jpg/.jpeg, .tga, .bmp, .hdr, .exr, .pfm. InputError
// "<path>: <reason>" (one line) for an unknown extension, a missing, truncated or malformed
// file, or one larger than kMaxTextureTexels texels (checked from the header before decoding).
TextureImage readTextureImage(const std::filesystem::path& path);

// The same for a file's bytes already in memory (an image inside a glTF buffer or data URI):
// `name` stands for the file in messages, and its extension picks the format.
TextureImage decodeTextureImage(const std::vector<unsigned char>& bytes,
                                const std::filesystem::path& name);
inline constexpr int64_t kMaxTextureTexels = int64_t(1) << 28;

}  // namespace pt
