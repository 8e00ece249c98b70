// Image files: EXR via tinyexr, PFM by hand, PNG via stb, plus the sRGB curve. Every format
// is encoded to and decoded from memory, so file access and its errors live in one place
// (file_io.cpp).

#include "image/image.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string_view>
#include <system_error>

#include <tinyexr.h>

// stb is compiled into this file only, with internal linkage: ptcore also links Debian's
// libstb, and static definitions keep the two copies from interposing on each other. Only the
// PNG decoder is built, and neither side touches files: we do all file I/O ourselves.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#include <stb/stb_image.h>
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>

#include "common/memory.h"
#include "image/file_io.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

// Throws the one-line InputError every image failure uses: "<path>: <what>". Library messages
// can contain newlines, which would break the one-line promise, so they become spaces.
[[noreturn]] void fail(const fs::path& path, std::string what) {
  std::replace(what.begin(), what.end(), '\n', ' ');
  while (!what.empty() && what.back() == ' ') what.pop_back();
  throw InputError(path.string() + ": " + what);
}

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

Image decodePfm(const Bytes& data, const fs::path& path) {
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
  Image image(width, height);
  const unsigned char* p = data.data() + pos;
  auto next = [&] {
    const uint32_t bits =
        littleEndian
            ? uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24
            : uint32_t(p[3]) | uint32_t(p[2]) << 8 | uint32_t(p[1]) << 16 | uint32_t(p[0]) << 24;
    p += 4;
    const float value = std::bit_cast<float>(bits);
    return factor == 1.0f ? value : value * factor;
  };
  for (int row = 0; row < height; ++row) {
    const int y = height - 1 - row;  // the file stores the bottom row first
    for (int x = 0; x < width; ++x) {
      glm::vec3& pixel = image.at(x, y);
      if (channels == 3) {
        pixel.r = next();
        pixel.g = next();
        pixel.b = next();
      } else {
        pixel = glm::vec3(next());
      }
    }
  }
  return image;
}

// ---- EXR ------------------------------------------------------------------------------------

std::string takeExrError(const char* err) {
  std::string message = err ? err : "unknown tinyexr error";
  if (err) FreeEXRErrorMessage(err);
  return message;
}

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

Image decodeExr(const Bytes& data, const fs::path& path) {
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
  const EXRHeader& header = exr.header;
  int r = -1, g = -1, b = -1, luminance = -1;
  std::string names;
  for (int c = 0; c < header.num_channels; ++c) {
    const std::string_view name = header.channels[c].name;
    if (name == "R") r = c;
    if (name == "G") g = c;
    if (name == "B") b = c;
    if (name == "Y") luminance = c;
    names += (c ? ", " : "") + std::string(name);
  }
  int source[3];
  if (r >= 0 && g >= 0 && b >= 0) {
    source[0] = r, source[1] = g, source[2] = b;
  } else if (luminance >= 0 || header.num_channels == 1) {
    const int c = luminance >= 0 ? luminance : 0;
    source[0] = source[1] = source[2] = c;
  } else {
    fail(path, "no R, G, B or Y channels (found: " + names + ")");
  }
  for (int c : source) {
    if (header.channels[c].x_sampling != 1 || header.channels[c].y_sampling != 1) {
      fail(path,
           "subsampled channel '" + std::string(header.channels[c].name) + "' is not supported");
    }
  }
  // The declared data window is checked before tinyexr allocates it, as for PNG: with no, RLE
  // or ZIP compression the channels cannot expand more than deflate's 1032:1 (RLE: 64:1), so a
  // header claiming more than that is corrupt; with any compression the decoded planes (4
  // bytes per channel once halves are widened) and the float image must fit in memory.
  {
    const EXRBox2i& window = header.data_window;
    const uint64_t width = uint64_t(int64_t(window.max_x) - int64_t(window.min_x) + 1);
    const uint64_t height = uint64_t(int64_t(window.max_y) - int64_t(window.min_y) + 1);
    if (window.max_x < window.min_x || window.max_y < window.min_y) {
      fail(path, "EXR data window is empty");
    }
    uint64_t storedBytesPerPixel = 0;
    for (int c = 0; c < header.num_channels; ++c) {
      storedBytesPerPixel += header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF ? 2 : 4;
    }
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    const int compression = header.compression_type;
    const bool boundedRatio =
        compression == TINYEXR_COMPRESSIONTYPE_NONE || compression == TINYEXR_COMPRESSIONTYPE_RLE ||
        compression == TINYEXR_COMPRESSIONTYPE_ZIPS || compression == TINYEXR_COMPRESSIONTYPE_ZIP;
    if (boundedRatio && width * height * storedBytesPerPixel / 1032 > data.size()) {
      fail(path, "header says " + size + " pixels, more than " + std::to_string(data.size()) +
                     " bytes of EXR can hold");
    }
    checkFitsInMemory(width * height * (4 * uint64_t(header.num_channels) + sizeof(glm::vec3)),
                      path.string() + ": a " + size + " EXR",
                      "decoded channels and the float image");
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
  Image image(loaded.width, loaded.height);
  // Loading replaced pixel_types with the requested types, so they say what the buffers hold.
  auto value = [&](unsigned char* const* planes, int c, size_t index) {
    if (header.pixel_types[c] == TINYEXR_PIXELTYPE_UINT) {
      return float(reinterpret_cast<const uint32_t*>(planes[c])[index]);
    }
    return reinterpret_cast<const float*>(planes[c])[index];
  };
  auto copyPixel = [&](unsigned char* const* planes, size_t index, int x, int y) {
    glm::vec3& pixel = image.at(x, y);
    for (int k = 0; k < 3; ++k) pixel[k] = value(planes, source[k], index);
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
          copyPixel(tile.images, size_t(j) * size_t(header.tile_size_x) + size_t(i), x, y);
        }
      }
    }
  } else {
    if (!loaded.images) fail(path, "EXR has no scanline data");
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        copyPixel(loaded.images, size_t(y) * size_t(image.width) + size_t(x), x, y);
      }
    }
  }
  return image;
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

// One walk over a PNG's chunks before stb_image sees them (both found by fuzzing):
//  - a chunk whose length runs past the end of the file is refused: stb_image reserves an
//    IDAT chunk's declared length before reading it, so a 100-byte file claiming 2 GiB made
//    it allocate 2 GiB;
//  - empty IDAT chunks, which are legal, are dropped: stb_image copies from a null buffer
//    for one that comes first (undefined behaviour).
// Returns the file without its empty IDAT chunks.
Bytes checkedPngChunks(const Bytes& data, const fs::path& path) {
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

Image decodePng(const Bytes& original, const fs::path& path) {
  if (original.size() > size_t(INT_MAX)) fail(path, "PNG file too large");
  const Bytes data = checkedPngChunks(original, path);
  const int size = int(data.size());
  int width = 0, height = 0, channelsInFile = 0;
  // The header's size is checked before decoding: deflate expands at most 1032:1, so a PNG
  // whose rows, even at 1 bit per pixel, need more than that many times its own size is
  // corrupt, whatever it says; and what passes must still fit in memory (the decoded pixels
  // plus the float image).
  if (stbi_info_from_memory(data.data(), size, &width, &height, &channelsInFile)) {
    const uint64_t depth = stbi_is_16_bit_from_memory(data.data(), size) ? 2 : 1;
    const uint64_t minRawBytes = uint64_t(height) * (1 + (uint64_t(width) + 7) / 8);
    if (minRawBytes / 1032 > uint64_t(size)) {
      fail(path, "header says " + std::to_string(width) + "x" + std::to_string(height) +
                     " pixels, more than " + std::to_string(size) + " bytes of PNG can hold");
    }
    checkFitsInMemory(
        uint64_t(width) * uint64_t(height) * (3 * depth + sizeof(glm::vec3)),
        path.string() + ": a " + std::to_string(width) + "x" + std::to_string(height) + " PNG",
        "decoded pixels and the float image");
  }
  // Colour, grey and alpha variants all come back as RGB (alpha dropped). 16-bit files keep
  // their precision. Gamma and ICC chunks are ignored: PNG here means sRGB.
  if (stbi_is_16_bit_from_memory(data.data(), size)) {
    stbi_us* pixels =
        stbi_load_16_from_memory(data.data(), size, &width, &height, &channelsInFile, 3);
    if (!pixels) fail(path, "cannot decode PNG: " + stbReason());
    Image image(width, height);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        image.pixels[i][c] = srgbToLinear(float(pixels[3 * i + size_t(c)]) / 65535.0f);
      }
    }
    stbi_image_free(pixels);
    return image;
  }
  stbi_uc* pixels = stbi_load_from_memory(data.data(), size, &width, &height, &channelsInFile, 3);
  if (!pixels) fail(path, "cannot decode PNG: " + stbReason());
  float table[256];
  for (int v = 0; v < 256; ++v) table[v] = float(decodeSrgb(v / 255.0));
  Image image(width, height);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) image.pixels[i][c] = table[pixels[3 * i + size_t(c)]];
  }
  stbi_image_free(pixels);
  return image;
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
  const ImageFormat format = imageFormatOf(path);
  const Bytes bytes = readWholeFile(path, "an image file");
  switch (format) {
    case ImageFormat::kExr:
      return decodeExr(bytes, path);
    case ImageFormat::kPfm:
      return decodePfm(bytes, path);
    case ImageFormat::kPng:
      return decodePng(bytes, path);
  }
  PT_CHECK(false, "unhandled image format");
}

}  // namespace pt
