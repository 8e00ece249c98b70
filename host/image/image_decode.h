// The image decoders readImage (image.h) and readTextureImage (texture_image.h) share, with
// stb_image and tinyexr behind them (texture_image.cpp). Internal to host/image.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "image/file_io.h"
#include "image/texture_image.h"

namespace pt::image_detail {

enum class FileFormat { kPng, kJpeg, kTga, kBmp, kHdr, kExr, kPfm };

// Throws the one-line InputError every image failure uses: "<path>: <what>" (newlines in
// library messages become spaces).
[[noreturn]] void fail(const std::filesystem::path& path, std::string what);

// tinyexr's message, which it then frees.
std::string takeExrError(const char* err);

struct DecodeOptions {
  // readImage's needs: PNG decoded to 3 channels as before; EXR alpha not read (so never
  // refused for it); no texel limit (memory alone bounds the image).
  bool rgbOnly = false;
  bool limitTexels = true;  // refuse more than kMaxTextureTexels texels
  // What the caller allocates per texel once the result is back, and its name, counted in the
  // memory check before decoding.
  uint64_t callerBytesPerTexel = 0;
  const char* resultName = "the texture";
};

// Decodes a whole file's bytes as `format`; InputError "<path>: ..." for anything malformed.
TextureImage decode(const Bytes& data, const std::filesystem::path& path, FileFormat format,
                    const DecodeOptions& options);

}  // namespace pt::image_detail
