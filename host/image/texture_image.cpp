// Image decoding for readImage (image_io.cpp) and readTextureImage: PNG, JPEG, TGA, BMP and
// Radiance HDR via stb_image, EXR via tinyexr, PFM by hand. Every decoder works on the whole
// file in memory (file_io.cpp reads it) and checks the header's size before it allocates.

#include "image/texture_image.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <optional>
#include <string_view>
#include <system_error>

#include <tinyexr.h>

// stb_image is compiled into this file only, with internal linkage: ptcore also links Debian's
// libstb, and static definitions keep the two copies from interposing on each other. Only the
// decoders a texture can use are built, and none touches files: we do all file I/O ourselves.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_ONLY_TGA
#define STBI_ONLY_BMP
#define STBI_ONLY_HDR
#define STBI_NO_STDIO
// stb_image 2.27's JPEG decoder shifts by more than 31 bits on corrupt entropy data (its bit
// count goes negative; later versions check it): harmless where it runs (x86 masks the count,
// the texels come out as garbage, and nothing is read or written out of bounds), but undefined,
// so UBSan stops the fuzzer on it. Clang builds exempt stb's own functions from the shift
// check, and only those.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((no_sanitize("shift"))), apply_to = function)
#endif
#include <stb/stb_image.h>
#if defined(__clang__)
#pragma clang attribute pop
#endif

#include "common/check.h"
#include "common/memory.h"
#include "image/image_decode.h"

namespace pt {
namespace image_detail {

namespace fs = std::filesystem;

void fail(const fs::path& path, std::string what) {
  std::replace(what.begin(), what.end(), '\n', ' ');
  while (!what.empty() && what.back() == ' ') what.pop_back();
  throw InputError(path.string() + ": " + what);
}

std::string takeExrError(const char* err) {
  std::string message = err ? err : "unknown tinyexr error";
  if (err) FreeEXRErrorMessage(err);
  return message;
}

namespace {

std::string sizeText(uint64_t width, uint64_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The texel limit, checked from the header before anything is allocated.
void checkTexelCount(uint64_t width, uint64_t height, const fs::path& path,
                     const DecodeOptions& options) {
  if (options.limitTexels && width * height > uint64_t(kMaxTextureTexels)) {
    fail(path, "header says " + sizeText(width, height) + " texels, more than the " +
                   std::to_string(kMaxTextureTexels) + " a texture may have");
  }
}

// ---- PFM ------------------------------------------------------------------------------------

TextureImage decodePfm(const Bytes& data, const fs::path& path, const DecodeOptions& options) {
  if (data.size() < 2 || data[0] != 'P' || (data[1] != 'F' && data[1] != 'f')) {
    fail(path, "bad header: expected 'PF' or 'Pf'");
  }
  const int channels = data[1] == 'F' ? 3 : 1;
  size_t pos = 2;
  auto isSpace = [](unsigned char c) { return std::isspace(c) != 0; };
  // Header fields are separated by whitespace; returns the next field.
  auto field = [&](const char* what) {
    if (pos >= data.size() || !isSpace(data[pos])) {
      fail(path, std::string("bad header: expected whitespace before the ") + what);
    }
    while (pos < data.size() && isSpace(data[pos])) ++pos;
    const size_t start = pos;
    while (pos < data.size() && !isSpace(data[pos]) && pos - start < 64) ++pos;
    if (pos == start) fail(path, std::string("bad header: missing ") + what);
    return std::string_view(reinterpret_cast<const char*>(data.data()) + start, pos - start);
  };
  auto dimension = [&](const char* what) {
    const std::string_view text = field(what);
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || value <= 0) {
      fail(path, std::string("bad header: ") + what + " '" + std::string(text) +
                     "' is not a positive integer");
    }
    return value;
  };
  const int width = dimension("width");
  const int height = dimension("height");
  checkTexelCount(uint64_t(width), uint64_t(height), path, options);
  const std::string_view scaleText = field("scale");
  float scale = 0.0f;
  const auto [end, ec] =
      std::from_chars(scaleText.data(), scaleText.data() + scaleText.size(), scale);
  if (ec != std::errc() || end != scaleText.data() + scaleText.size() || !std::isfinite(scale) ||
      scale == 0.0f) {
    fail(path, "bad header: scale '" + std::string(scaleText) + "' is not a non-zero number");
  }
  // Exactly one whitespace character ends the header; pixel data may start with any byte.
  if (pos >= data.size() || !isSpace(data[pos])) {
    fail(path, "bad header: expected a newline after the scale");
  }
  ++pos;

  const uint64_t expected = uint64_t(width) * uint64_t(height) * uint64_t(channels) * 4;
  const uint64_t found = data.size() - pos;
  if (found < expected) {
    fail(path, "truncated pixel data: expected " + std::to_string(expected) + " bytes for " +
                   std::to_string(width) + "x" + std::to_string(height) + ", found " +
                   std::to_string(found));
  }
  if (found > expected) {
    fail(path, std::to_string(found - expected) + " unexpected bytes after the pixel data of " +
                   std::to_string(width) + "x" + std::to_string(height));
  }

  // The sign of the scale gives the byte order; its magnitude multiplies the values (as pbrt
  // does). Most files say 1, where the multiplication is skipped so values stay bit-exact.
  const bool littleEndian = scale < 0.0f;
  const float factor = std::fabs(scale);
  TextureImage image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.floats.resize(size_t(width) * size_t(height) * size_t(channels));
  const unsigned char* p = data.data() + pos;
  const size_t rowFloats = size_t(width) * size_t(channels);
  for (int row = 0; row < height; ++row) {
    float* out = image.floats.data() + size_t(height - 1 - row) * rowFloats;  // bottom row first
    for (size_t i = 0; i < rowFloats; ++i, p += 4) {
      const uint32_t bits =
          littleEndian
              ? uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24
              : uint32_t(p[3]) | uint32_t(p[2]) << 8 | uint32_t(p[1]) << 16 | uint32_t(p[0]) << 24;
      const float value = std::bit_cast<float>(bits);
      out[i] = factor == 1.0f ? value : value * factor;
    }
  }
  return image;
}

// ---- EXR ------------------------------------------------------------------------------------

// Owns what tinyexr allocates while reading, freed on every exit path.
struct ExrReadState {
  EXRHeader header;
  EXRImage image;
  bool headerParsed = false;
  bool imageLoaded = false;
  ExrReadState() {
    InitEXRHeader(&header);
    InitEXRImage(&image);
  }
  ~ExrReadState() {
    if (imageLoaded) FreeEXRImage(&image);
    if (headerParsed) FreeEXRHeader(&header);
  }
  ExrReadState(const ExrReadState&) = delete;
  ExrReadState& operator=(const ExrReadState&) = delete;
};

// tinyexr aborts on a few headers instead of returning an error (Debian builds it with its
// asserts on): a "type" attribute other than the four it knows or at odds with the version's
// tiled flag, a "tiles" attribute that is not 9 bytes, tile level mode 3 (as the fuzzer
// found). Those attributes are checked here first, read as tinyexr reads them: name and type
// as terminated strings, a 4-byte little-endian size, the value; a single 0 byte ends the
// header. Whatever else is wrong with the header is left to tinyexr to report.
void checkExrHeaderForTinyexr(const Bytes& data, bool tiled, const fs::path& path) {
  size_t at = 8;  // after the magic number and the version
  auto terminated = [&](size_t from) -> std::optional<std::string_view> {
    const auto* begin = reinterpret_cast<const char*>(data.data()) + from;
    const size_t length = strnlen(begin, data.size() - from);
    if (from + length >= data.size()) return std::nullopt;
    return std::string_view(begin, length);
  };
  while (at < data.size() && data[at] != 0) {
    const auto name = terminated(at);
    if (!name) return;
    const auto type = terminated(at + name->size() + 1);
    if (!type) return;
    const size_t sizeAt = at + name->size() + 1 + type->size() + 1;
    if (data.size() - sizeAt < 4) return;
    const uint32_t size = uint32_t(data[sizeAt]) | uint32_t(data[sizeAt + 1]) << 8 |
                          uint32_t(data[sizeAt + 2]) << 16 | uint32_t(data[sizeAt + 3]) << 24;
    const size_t valueAt = sizeAt + 4;
    if (data.size() - valueAt < size) return;
    const std::string_view value(reinterpret_cast<const char*>(data.data()) + valueAt, size);
    if (*name == "type" && !value.empty() && value[0] != 0) {
      const size_t end = value.find('\0');
      if (end == std::string_view::npos)
        fail(path, "EXR attribute 'type' is not a terminated string");
      const std::string_view kind = value.substr(0, end);
      if (kind != (tiled ? "tiledimage" : "scanlineimage")) {
        fail(path, "EXR image type '" + std::string(kind) + "' is not supported in a " +
                       (tiled ? "tiled" : "scanline") +
                       " file (only scanlineimage and tiledimage)");
      }
    }
    if (*name == "tiles" && tiled) {
      if (size != 9)
        fail(path, "EXR attribute 'tiles' has " + std::to_string(size) + " bytes, not 9");
      if ((uint8_t(value[8]) & 0x3) == 3) fail(path, "EXR tile level mode 3 is not defined");
    }
    at = valueAt + size;
  }
}

TextureImage decodeExr(const Bytes& data, const fs::path& path, const DecodeOptions& options) {
  EXRVersion version;
  if (ParseEXRVersionFromMemory(&version, data.data(), data.size()) != TINYEXR_SUCCESS) {
    fail(path, "not an OpenEXR file (bad magic number or version)");
  }
  if (version.multipart || version.non_image) {
    fail(path, "multi-part and deep EXR files are not supported");
  }
  checkExrHeaderForTinyexr(data, version.tiled != 0, path);
  ExrReadState exr;
  const char* err = nullptr;
  const int parsed =
      ParseEXRHeaderFromMemory(&exr.header, &version, data.data(), data.size(), &err);
  exr.headerParsed = true;  // tinyexr may have allocated parts of it even on failure
  if (parsed != TINYEXR_SUCCESS) fail(path, "bad EXR header: " + takeExrError(err));

  // Pick the channels by name: R, G, B; else a luminance Y; else a lone channel of any name.
  // An alpha channel A joins either (grey then replicated to RGB), unless options.rgbOnly.
  const EXRHeader& header = exr.header;
  int r = -1, g = -1, b = -1, luminance = -1, alpha = -1;
  std::string names;
  for (int c = 0; c < header.num_channels; ++c) {
    const std::string_view name = header.channels[c].name;
    if (name == "R") r = c;
    if (name == "G") g = c;
    if (name == "B") b = c;
    if (name == "Y") luminance = c;
    if (name == "A") alpha = c;
    names += (c ? ", " : "") + std::string(name);
  }
  std::vector<int> source;
  if (r >= 0 && g >= 0 && b >= 0) {
    source = {r, g, b};
    if (alpha >= 0 && !options.rgbOnly) source.push_back(alpha);
  } else if (luminance >= 0 || header.num_channels == 1) {
    const int c = luminance >= 0 ? luminance : 0;
    source = {c};
    if (alpha >= 0 && alpha != c && !options.rgbOnly) source = {c, c, c, alpha};
  } else {
    fail(path, "no R, G, B or Y channels (found: " + names + ")");
  }
  for (int c : source) {
    if (header.channels[c].x_sampling != 1 || header.channels[c].y_sampling != 1) {
      fail(path,
           "subsampled channel '" + std::string(header.channels[c].name) + "' is not supported");
    }
  }
  const int channels = int(source.size());
  // The declared data window is checked before tinyexr allocates it, as for PNG: with no, RLE
  // or ZIP compression the channels cannot expand more than deflate's 1032:1 (RLE: 64:1), so a
  // header claiming more than that is corrupt; with any compression the decoded planes (4
  // bytes per channel once halves are widened), the result and what the caller makes of it
  // must fit in memory.
  {
    const EXRBox2i& window = header.data_window;
    const uint64_t width = uint64_t(int64_t(window.max_x) - int64_t(window.min_x) + 1);
    const uint64_t height = uint64_t(int64_t(window.max_y) - int64_t(window.min_y) + 1);
    if (window.max_x < window.min_x || window.max_y < window.min_y) {
      fail(path, "EXR data window is empty");
    }
    checkTexelCount(width, height, path, options);
    uint64_t storedBytesPerPixel = 0;
    for (int c = 0; c < header.num_channels; ++c) {
      storedBytesPerPixel += header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF ? 2 : 4;
    }
    const std::string size = sizeText(width, height);
    const int compression = header.compression_type;
    const bool boundedRatio =
        compression == TINYEXR_COMPRESSIONTYPE_NONE || compression == TINYEXR_COMPRESSIONTYPE_RLE ||
        compression == TINYEXR_COMPRESSIONTYPE_ZIPS || compression == TINYEXR_COMPRESSIONTYPE_ZIP;
    if (boundedRatio && width * height * storedBytesPerPixel / 1032 > data.size()) {
      fail(path, "header says " + size + " pixels, more than " + std::to_string(data.size()) +
                     " bytes of EXR can hold");
    }
    checkFitsInMemory(width * height *
                          (4 * uint64_t(header.num_channels) + 4 * uint64_t(channels) +
                           options.callerBytesPerTexel),
                      path.string() + ": a " + size + " EXR",
                      std::string("decoded channels and ") + options.resultName);
  }
  // Half channels are widened to float while loading; float and uint are read as stored.
  for (int c = 0; c < header.num_channels; ++c) {
    if (header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF) {
      exr.header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
    }
  }
  // On a decoding error tinyexr frees the image itself, but only as many channel buffers as
  // image.num_channels says, which it sets only on success: preset it so nothing leaks. The
  // freed image is not marked loaded, so it is not freed a second time.
  exr.image.num_channels = header.num_channels;
  if (LoadEXRImageFromMemory(&exr.image, &exr.header, data.data(), data.size(), &err) !=
      TINYEXR_SUCCESS) {
    fail(path, "cannot decode EXR: " + takeExrError(err));
  }
  exr.imageLoaded = true;

  const EXRImage& loaded = exr.image;
  if (loaded.width <= 0 || loaded.height <= 0) fail(path, "EXR image is empty");
  TextureImage image;
  image.width = loaded.width;
  image.height = loaded.height;
  image.channels = channels;
  image.floats.resize(size_t(loaded.width) * size_t(loaded.height) * size_t(channels));
  // Loading replaced pixel_types with the requested types, so they say what the buffers hold.
  auto value = [&](unsigned char* const* planes, int c, size_t index) {
    if (header.pixel_types[c] == TINYEXR_PIXELTYPE_UINT) {
      return float(reinterpret_cast<const uint32_t*>(planes[c])[index]);
    }
    return reinterpret_cast<const float*>(planes[c])[index];
  };
  auto copyTexel = [&](unsigned char* const* planes, size_t index, int x, int y) {
    float* texel =
        image.floats.data() + (size_t(y) * size_t(image.width) + size_t(x)) * size_t(channels);
    for (int k = 0; k < channels; ++k) texel[k] = value(planes, source[size_t(k)], index);
  };
  if (header.tiled) {
    if (!loaded.tiles) fail(path, "tiled EXR without tiles");
    // Level 0 only. Tile offsets count tiles; every tile buffer is a full tile wide.
    for (int t = 0; t < loaded.num_tiles; ++t) {
      const EXRTile& tile = loaded.tiles[t];
      for (int j = 0; j < tile.height; ++j) {
        for (int i = 0; i < tile.width; ++i) {
          const int x = tile.offset_x * header.tile_size_x + i;
          const int y = tile.offset_y * header.tile_size_y + j;
          if (x >= image.width || y >= image.height) continue;
          copyTexel(tile.images, size_t(j) * size_t(header.tile_size_x) + size_t(i), x, y);
        }
      }
    }
  } else {
    if (!loaded.images) fail(path, "EXR has no scanline data");
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        copyTexel(loaded.images, size_t(y) * size_t(image.width) + size_t(x), x, y);
      }
    }
  }
  return image;
}

// ---- PNG ------------------------------------------------------------------------------------

// What the chunk walk learns of a PNG's layout: the colour type from IHDR (-1 if none) and
// whether a tRNS chunk adds alpha.
struct PngLayout {
  int colourType = -1;
  bool transparency = false;
};

// One walk over a PNG's chunks before stb_image sees them (both found by fuzzing):
//  - a chunk whose length runs past the end of the file is refused: stb_image reserves an
//    IDAT chunk's declared length before reading it, so a 100-byte file claiming 2 GiB made
//    it allocate 2 GiB;
//  - empty IDAT chunks, which are legal, are dropped: stb_image copies from a null buffer
//    for one that comes first (undefined behaviour).
// Returns the file without its empty IDAT chunks, and fills `layout`.
Bytes checkedPngChunks(const Bytes& data, const fs::path& path, PngLayout& layout) {
  constexpr size_t kSignature = 8;
  Bytes out(data.begin(), data.begin() + std::ptrdiff_t(std::min(data.size(), kSignature)));
  size_t at = kSignature;
  while (at + 8 <= data.size()) {
    const uint64_t length = uint64_t(data[at]) << 24 | uint64_t(data[at + 1]) << 16 |
                            uint64_t(data[at + 2]) << 8 | uint64_t(data[at + 3]);
    const std::string type(reinterpret_cast<const char*>(&data[at + 4]), 4);
    if (at + 12 + length > data.size()) {
      std::string printable;
      for (char c : type) printable += std::isalpha(static_cast<unsigned char>(c)) ? c : '?';
      fail(path, "PNG chunk '" + printable + "' at byte " + std::to_string(at) + " claims " +
                     std::to_string(length) + " bytes, but the file ends at byte " +
                     std::to_string(data.size()));
    }
    const size_t end = at + 12 + size_t(length);
    if (type == "IHDR" && length >= 13) layout.colourType = data[at + 8 + 9];
    if (type == "tRNS") layout.transparency = true;
    if (!(length == 0 && type == "IDAT")) {
      out.insert(out.end(), data.begin() + std::ptrdiff_t(at), data.begin() + std::ptrdiff_t(end));
    }
    at = end;
    if (type == "IEND") break;
  }
  out.insert(out.end(), data.begin() + std::ptrdiff_t(std::min(at, data.size())), data.end());
  return out;
}

// stb_image's reason for the last failure; it may have none (a null pointer).
std::string stbReason() {
  const char* reason = stbi_failure_reason();
  return reason && *reason ? reason : "corrupt or unsupported data";
}

// The channels a texture keeps of stb's `comp` (what the file holds): grey+alpha becomes RGBA.
int textureChannels(int comp) {
  return comp == 2 ? 4 : std::clamp(comp, 1, 4);
}

// Frees what stb_image returned on every exit path.
struct StbPixels {
  void* pixels = nullptr;
  ~StbPixels() { stbi_image_free(pixels); }
};

TextureImage decodePng(const Bytes& original, const fs::path& path, const DecodeOptions& options) {
  if (original.size() > size_t(INT_MAX)) fail(path, "PNG file too large");
  // Only PNG data reaches the PNG decoder through here: stb_image would otherwise try its other
  // decoders on it, without the checks below. The message is the one stb gives.
  constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (original.size() < 8 || std::memcmp(original.data(), kSignature, 8) != 0) {
    fail(path, "cannot decode PNG: unknown image type");
  }
  PngLayout layout;
  const Bytes data = checkedPngChunks(original, path, layout);
  const int size = int(data.size());
  const bool sixteen = stbi_is_16_bit_from_memory(data.data(), size) != 0;
  const uint64_t depth = sixteen ? 2 : 1;
  // Colour, grey and alpha variants come back as RGB for readImage (alpha dropped); a texture
  // keeps grey (1), RGB (3) or RGBA (4, also grey+alpha and any with a tRNS chunk). 16-bit
  // files keep their precision. Gamma and ICC chunks are ignored.
  int channels = 3;
  if (!options.rgbOnly) {
    switch (layout.colourType) {
      case 0:
        channels = layout.transparency ? 4 : 1;
        break;
      case 2:
      case 3:
        channels = layout.transparency ? 4 : 3;
        break;
      default:
        channels = 4;
    }
  }
  int width = 0, height = 0, channelsInFile = 0;
  // The header's size is checked before decoding: deflate expands at most 1032:1, so a PNG
  // whose rows, even at 1 bit per pixel, need more than that many times its own size is
  // corrupt, whatever it says; and what passes must still fit in memory (the decoded pixels,
  // the result and what the caller makes of it).
  if (stbi_info_from_memory(data.data(), size, &width, &height, &channelsInFile)) {
    const uint64_t minRawBytes = uint64_t(height) * (1 + (uint64_t(width) + 7) / 8);
    if (minRawBytes / 1032 > uint64_t(size)) {
      fail(path, "header says " + sizeText(width, height) + " pixels, more than " +
                     std::to_string(size) + " bytes of PNG can hold");
    }
    checkTexelCount(uint64_t(width), uint64_t(height), path, options);
    const uint64_t resultBytes = options.rgbOnly ? 0 : uint64_t(channels) * (sixteen ? 4 : 1);
    checkFitsInMemory(uint64_t(width) * uint64_t(height) *
                          (uint64_t(channels) * depth + resultBytes + options.callerBytesPerTexel),
                      path.string() + ": a " + sizeText(width, height) + " PNG",
                      std::string("decoded pixels and ") + options.resultName);
  }
  TextureImage image;
  image.channels = channels;
  StbPixels decoded;
  if (sixteen) {
    decoded.pixels =
        stbi_load_16_from_memory(data.data(), size, &width, &height, &channelsInFile, channels);
  } else {
    decoded.pixels =
        stbi_load_from_memory(data.data(), size, &width, &height, &channelsInFile, channels);
  }
  if (!decoded.pixels) fail(path, "cannot decode PNG: " + stbReason());
  image.width = width;
  image.height = height;
  const size_t count = size_t(width) * size_t(height) * size_t(channels);
  if (sixteen) {
    const auto* values = static_cast<const stbi_us*>(decoded.pixels);
    image.floats.resize(count);
    for (size_t i = 0; i < count; ++i) image.floats[i] = float(values[i]) / 65535.0f;
    image.floatsEncoded = true;
  } else {
    const auto* values = static_cast<const stbi_uc*>(decoded.pixels);
    image.bytes.assign(values, values + count);
  }
  return image;
}

// ---- JPEG, TGA, BMP, HDR (stb_image) --------------------------------------------------------

const char* formatName(FileFormat format) {
  switch (format) {
    case FileFormat::kPng:
      return "PNG";
    case FileFormat::kJpeg:
      return "JPEG";
    case FileFormat::kTga:
      return "TGA";
    case FileFormat::kBmp:
      return "BMP";
    case FileFormat::kHdr:
      return "Radiance HDR";
    case FileFormat::kExr:
      return "EXR";
    case FileFormat::kPfm:
      return "PFM";
  }
  return "image";
}

uint32_t little16(const Bytes& d, size_t at) {
  return uint32_t(d[at]) | uint32_t(d[at + 1]) << 8;
}
uint32_t little32(const Bytes& d, size_t at) {
  return little16(d, at) | little16(d, at + 2) << 16;
}

bool startsWith(const Bytes& data, std::string_view prefix) {
  return data.size() >= prefix.size() &&
         std::memcmp(data.data(), prefix.data(), prefix.size()) == 0;
}

// Whether the bytes start as `format` requires. stb_image picks a decoder by content, so this
// is what keeps a .jpg holding a PNG away from the PNG decoder without its checks, and each
// file with the decoder its extension names. TGA has no magic number, but its colour-map type
// (byte 1) is 0 or 1, which no other format's signature has there.
bool hasMagic(const Bytes& data, FileFormat format) {
  switch (format) {
    case FileFormat::kJpeg:
      return startsWith(data, "\xff\xd8");
    case FileFormat::kBmp:
      return startsWith(data, "BM");
    case FileFormat::kHdr:
      return startsWith(data, "#?RADIANCE\n") || startsWith(data, "#?RGBE\n");
    case FileFormat::kTga:
      return data.size() >= 18 && data[1] <= 1;
    default:
      return false;
  }
}

// The fewest bytes a file of `format` with the header's width x height texels can have,
// whatever its content: a bound that refuses a small file claiming a huge image before
// anything is allocated. 0 where the header cannot be read here (stb_image then refuses it).
uint64_t minimumFileBytes(const Bytes& data, FileFormat format, uint64_t width, uint64_t height) {
  const uint64_t texels = width * height;
  switch (format) {
    case FileFormat::kJpeg:
      // Each coded 8x8 block takes at least a bit in some scan; with 4x4 chroma subsampling
      // the smallest component has a sixteenth of the luma blocks.
      return texels / (64 * 16 * 8);
    case FileFormat::kTga: {
      const uint64_t idLength = data[0], imageType = data[2];
      const uint64_t paletteBytes = data[1] == 1 ? little16(data, 5) * ((data[7] + 7u) / 8) : 0;
      const uint64_t texelBytes = std::max(1u, (data[16] + 7u) / 8);
      const uint64_t header = 18 + idLength + paletteBytes;
      if (imageType >= 1 && imageType <= 3) return header + texels * texelBytes;
      // Run-length packets: a byte, then one texel for up to 128 of them.
      if (imageType >= 9 && imageType <= 11)
        return header + (texels + 127) / 128 * (1 + texelBytes);
      return 0;
    }
    case FileFormat::kBmp: {
      if (data.size() < 30) return 0;
      const uint64_t offset = little32(data, 10), headerSize = little32(data, 14);
      const uint64_t bits = headerSize == 12 ? little16(data, 24) : little16(data, 28);
      if (bits != 1 && bits != 4 && bits != 8 && bits != 16 && bits != 24 && bits != 32) return 0;
      const uint64_t rowBytes = (width * bits + 31) / 32 * 4;  // rows padded to 4 bytes
      return std::max(offset, 14 + headerSize) + height * rowBytes;
    }
    case FileFormat::kHdr: {
      // Scanlines are flat (4 bytes a texel) or run-length encoded: a 4-byte header, then
      // runs of up to 127 texels, two bytes each, per component. stb_image reads narrow and
      // very wide images flat only.
      const uint64_t flat = 4 * width;
      const uint64_t runs = 4 + 4 * 2 * ((width + 126) / 127);
      return height * (width < 8 || width >= 32768 ? flat : std::min(flat, runs));
    }
    default:
      return 0;
  }
}

// Feeds stb_image a file through its callbacks and notes whether decoding needed bytes past
// the end: stb_image reads zeros there from memory, so a truncated JPEG, TGA, BMP or HDR
// would decode silently. A refill (into stb's own buffer, filled first) reads ahead and may
// get less than it asks; any other read needs all it asks for.
struct CallbackReader {
  const Bytes& data;
  size_t at = 0;
  const char* refillBuffer = nullptr;
  bool pastEnd = false;

  static int read(void* user, char* out, int size) {
    auto& r = *static_cast<CallbackReader*>(user);
    if (!r.refillBuffer) r.refillBuffer = out;
    const size_t wanted = size_t(std::max(size, 0));
    const size_t count = std::min(wanted, r.data.size() - r.at);
    if (count > 0) std::memcpy(out, r.data.data() + r.at, count);
    r.at += count;
    if (out == r.refillBuffer ? count == 0 : count < wanted) r.pastEnd = true;
    return int(count);
  }
  static void skip(void* user, int n) {
    auto& r = *static_cast<CallbackReader*>(user);
    if (n < 0) return;
    if (size_t(n) > r.data.size() - r.at) {
      r.pastEnd = true;
      r.at = r.data.size();
    } else {
      r.at += size_t(n);
    }
  }
  static int eof(void* user) {
    const auto& r = *static_cast<CallbackReader*>(user);
    return r.at >= r.data.size() ? 1 : 0;
  }
};

// JPEG Huffman tables checked before stb_image 2.27 builds them: it writes a table's code
// sizes into 257 bytes and its symbols into 256 without checking that the 16 counts sum to at
// most 256 (the fuzzer found it). Up to the first scan the segments are walked as stb walks
// them (bytes between segments skipped one by one, fill bytes before a marker); after it, where
// stb resumes depends on the entropy decoder, so every FF C4 there is taken for a table.
void checkJpegHuffmanTables(const Bytes& data, const fs::path& path) {
  // As stb reads a DHT segment, zeros past the end of the file included.
  auto byte = [&](size_t at) -> unsigned { return at < data.size() ? data[at] : 0; };
  auto checkTables = [&](size_t at) {  // at: the segment's 2-byte length
    int64_t left = int64_t((byte(at) << 8) | byte(at + 1)) - 2;
    for (at += 2; left > 0;) {
      const unsigned tableClass = byte(at) >> 4, id = byte(at) & 15;
      if (tableClass > 1 || id > 3) return;  // stb refuses it
      size_t symbols = 0;
      for (size_t i = 1; i <= 16; ++i) symbols += byte(at + i);
      if (symbols > 256) {
        fail(path, "bad JPEG Huffman table: " + std::to_string(symbols) + " codes (at most 256)");
      }
      at += 17 + symbols;
      left -= int64_t(17 + symbols);
    }
  };
  size_t at = 2;  // after SOI
  while (at + 1 < data.size()) {
    if (data[at] != 0xff) {
      ++at;
      continue;
    }
    while (at < data.size() && data[at] == 0xff) ++at;
    if (at + 2 >= data.size()) return;
    const unsigned marker = data[at++];
    if (marker == 0xda) break;  // the first scan
    if (marker == 0xd8 || marker == 0xd9 || (marker >= 0xd0 && marker <= 0xd7)) continue;
    if (marker == 0xc4) checkTables(at);
    at += (size_t(data[at]) << 8) | data[at + 1];
  }
  for (; at + 1 < data.size(); ++at) {
    if (data[at] == 0xff && data[at + 1] == 0xc4) checkTables(at + 2);
  }
}

// Radiance HDR data walked as stb_image 2.27 reads it, before it does: it loops forever on a
// literal run of length 0 (which a truncated file would feed it as zeros), and reads the
// missing texels of a truncated flat file as zeros. Whatever else is wrong is left to it.
void checkHdrData(const Bytes& data, uint64_t width, uint64_t height, const fs::path& path) {
  // The header is lines up to an empty one, then the resolution line.
  const std::string_view text(reinterpret_cast<const char*>(data.data()), data.size());
  const size_t empty = text.find("\n\n");
  const size_t resolutionEnd = empty == std::string_view::npos ? empty : text.find('\n', empty + 2);
  if (resolutionEnd == std::string_view::npos) fail(path, "truncated Radiance HDR header");
  size_t at = resolutionEnd + 1;
  auto need = [&](uint64_t bytes) {
    if (data.size() - at < bytes) {
      fail(path, "truncated Radiance HDR file: " + std::to_string(bytes) +
                     " more bytes needed at byte " + std::to_string(at) +
                     ", but the file ends at byte " + std::to_string(data.size()));
    }
  };
  if (width < 8 || width >= 32768) return need(4 * width * height);
  for (uint64_t row = 0; row < height; ++row) {
    need(4);
    if (data[at] != 2 || data[at + 1] != 2 || (data[at + 2] & 0x80) != 0) {
      return need(4 * width * height);  // not run-length encoded: stb reads it all flat
    }
    at += 4;
    for (int component = 0; component < 4; ++component) {
      for (uint64_t i = 0; i < width;) {
        need(1);
        uint64_t count = data[at++];
        const bool run = count > 128;
        if (run) count -= 128;
        if (count == 0) {
          fail(path, "bad Radiance HDR data: a run of length 0 in scanline " + std::to_string(row));
        }
        if (count > width - i) return;  // stb refuses it
        const uint64_t bytes = run ? 1 : count;
        need(bytes);
        at += bytes;
        i += count;
      }
    }
  }
}

TextureImage decodeWithStb(const Bytes& data, const fs::path& path, FileFormat format,
                           const DecodeOptions& options) {
  const std::string name = formatName(format);
  if (data.size() > size_t(INT_MAX)) fail(path, name + " file too large");
  if (!hasMagic(data, format)) fail(path, "not a " + name + " file");
  if (format == FileFormat::kJpeg) checkJpegHuffmanTables(data, path);  // stbi_info reads them
  int width = 0, height = 0, comp = 0;
  if (!stbi_info_from_memory(data.data(), int(data.size()), &width, &height, &comp)) {
    fail(path, "bad " + name + " header: " + stbReason());
  }
  if (width <= 0 || height <= 0) fail(path, name + " image is empty");
  checkTexelCount(uint64_t(width), uint64_t(height), path, options);
  const uint64_t minimum = minimumFileBytes(data, format, uint64_t(width), uint64_t(height));
  if (minimum > data.size()) {
    fail(path, "header says " + sizeText(width, height) + " texels, which need at least " +
                   std::to_string(minimum) + " bytes of " + name + ", but the file has " +
                   std::to_string(data.size()));
  }
  const bool hdr = format == FileFormat::kHdr;
  if (hdr) checkHdrData(data, uint64_t(width), uint64_t(height), path);
  const int channels = hdr ? 3 : textureChannels(comp);
  // stb_image's output and its working copies (a converted copy, JPEG's component planes and
  // coefficients), the result and what the caller makes of it.
  const uint64_t outputBytes = uint64_t(channels) * (hdr ? 4 : 1);
  checkFitsInMemory(
      uint64_t(width) * uint64_t(height) * (3 * outputBytes + 8 + options.callerBytesPerTexel),
      path.string() + ": a " + sizeText(width, height) + " " + name,
      std::string("decoded pixels and ") + options.resultName);

  CallbackReader reader{data};
  const stbi_io_callbacks callbacks{&CallbackReader::read, &CallbackReader::skip,
                                    &CallbackReader::eof};
  int decodedWidth = 0, decodedHeight = 0, decodedComp = 0;
  StbPixels decoded;
  if (hdr) {
    decoded.pixels = stbi_loadf_from_callbacks(&callbacks, &reader, &decodedWidth, &decodedHeight,
                                               &decodedComp, channels);
  } else {
    decoded.pixels = stbi_load_from_callbacks(&callbacks, &reader, &decodedWidth, &decodedHeight,
                                              &decodedComp, channels);
  }
  if (reader.pastEnd) fail(path, "truncated " + name + " file: its data runs past the end");
  if (!decoded.pixels) fail(path, "cannot decode " + name + ": " + stbReason());
  if (decodedWidth != width || decodedHeight != height) {
    fail(path, "cannot decode " + name + ": header and data disagree on the size");
  }
  TextureImage image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  const size_t count = size_t(width) * size_t(height) * size_t(channels);
  if (hdr) {
    const auto* values = static_cast<const float*>(decoded.pixels);
    image.floats.assign(values, values + count);
  } else {
    const auto* values = static_cast<const stbi_uc*>(decoded.pixels);
    image.bytes.assign(values, values + count);
  }
  return image;
}

// The format an extension (any case) names, or none.
std::optional<FileFormat> textureFormatOf(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return FileFormat::kPng;
  if (ext == ".jpg" || ext == ".jpeg") return FileFormat::kJpeg;
  if (ext == ".tga") return FileFormat::kTga;
  if (ext == ".bmp") return FileFormat::kBmp;
  if (ext == ".hdr") return FileFormat::kHdr;
  if (ext == ".exr") return FileFormat::kExr;
  if (ext == ".pfm") return FileFormat::kPfm;
  return std::nullopt;
}

}  // namespace

TextureImage decode(const Bytes& data, const fs::path& path, FileFormat format,
                    const DecodeOptions& options) {
  switch (format) {
    case FileFormat::kExr:
      return decodeExr(data, path, options);
    case FileFormat::kPfm:
      return decodePfm(data, path, options);
    case FileFormat::kPng:
      return decodePng(data, path, options);
    case FileFormat::kJpeg:
    case FileFormat::kTga:
    case FileFormat::kBmp:
    case FileFormat::kHdr:
      return decodeWithStb(data, path, format, options);
  }
  PT_CHECK(false, "unhandled image format");
}

}  // namespace image_detail

namespace {

// The format the extension of `path` names; InputError naming the file where none.
image_detail::FileFormat textureFormatOrFail(const std::filesystem::path& path) {
  using namespace image_detail;
  const std::optional<FileFormat> format = textureFormatOf(path);
  constexpr const char* kExpected = "(expected .png, .jpg, .jpeg, .tga, .bmp, .hdr, .exr or .pfm)";
  if (!format) {
    if (path.extension().empty()) fail(path, std::string("no image file extension ") + kExpected);
    fail(path, "unknown image file extension '" + path.extension().string() + "' " + kExpected);
  }
  return *format;
}

}  // namespace

TextureImage readTextureImage(const std::filesystem::path& path) {
  const image_detail::FileFormat format = textureFormatOrFail(path);
  return image_detail::decode(readWholeFile(path, "an image file"), path, format,
                              image_detail::DecodeOptions{});
}

TextureImage decodeTextureImage(const std::vector<unsigned char>& bytes,
                                const std::filesystem::path& name) {
  const image_detail::FileFormat format = textureFormatOrFail(name);
  return image_detail::decode(bytes, name, format, image_detail::DecodeOptions{});
}

}  // namespace pt
