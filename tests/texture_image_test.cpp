// Tests of readTextureImage (host/image/texture_image.h): every format written small into a
// temporary directory (stb_image_write, tinyexr, writeImage or by hand) and read back with its
// channels, exact bytes or values and row order; and every kind of bad file refused with one
// line naming it.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <tinyexr.h>

// stb_image_write for the test files, with internal linkage like ptcore's copy. Not with
// STBI_WRITE_NO_STDIO: v1.16 then leaves out stbi_write_hdr_to_func.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include "common/check.h"
#include "image/image.h"
#include "image/texture_image.h"
#include "test_util.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

class TextureImageTest : public testing::Test {
 protected:
  test::TempDir dir_;
};

using TextureImagePng = TextureImageTest;
using TextureImageStb = TextureImageTest;
using TextureImageFloat = TextureImageTest;
using TextureImageErrors = TextureImageTest;

using test::writeBytes;

std::string readBytes(const fs::path& path) {
  return test::readFile(path);
}

// Distinct bytes per texel and channel, so swapped rows, columns or channels show.
std::vector<uint8_t> pattern(int width, int height, int channels) {
  std::vector<uint8_t> bytes(size_t(width) * size_t(height) * size_t(channels));
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = uint8_t((i * 37 + 11) % 251);
  return bytes;
}

void appendTo(void* context, void* data, int size) {
  auto* out = static_cast<std::string*>(context);
  out->append(static_cast<const char*>(data), size_t(size));
}

enum class StbFile { kPng, kBmp, kTga, kTgaRle, kJpeg };

// An 8-bit file from stb_image_write.
std::string encode(StbFile kind, int width, int height, int channels,
                   const std::vector<uint8_t>& texels) {
  std::string out;
  int ok = 0;
  switch (kind) {
    case StbFile::kPng:
      ok = stbi_write_png_to_func(appendTo, &out, width, height, channels, texels.data(),
                                  width * channels);
      break;
    case StbFile::kBmp:
      ok = stbi_write_bmp_to_func(appendTo, &out, width, height, channels, texels.data());
      break;
    case StbFile::kTga:
    case StbFile::kTgaRle:
      stbi_write_tga_with_rle = kind == StbFile::kTgaRle ? 1 : 0;
      ok = stbi_write_tga_to_func(appendTo, &out, width, height, channels, texels.data());
      break;
    case StbFile::kJpeg:
      ok = stbi_write_jpg_to_func(appendTo, &out, width, height, channels, texels.data(), 100);
      break;
  }
  EXPECT_TRUE(ok);
  return out;
}

std::string encodeHdr(int width, int height, const std::vector<float>& rgb) {
  std::string out;
  EXPECT_TRUE(stbi_write_hdr_to_func(appendTo, &out, width, height, 3, rgb.data()));
  return out;
}

// ---- A PNG by hand, for what stb_image_write cannot write: 16 bits, palettes, tRNS ----------

uint32_t crc32(const std::string& bytes) {
  uint32_t crc = 0xffffffffu;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::string big32(uint32_t v) {
  return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

std::string chunk(const std::string& type, const std::string& data) {
  return big32(uint32_t(data.size())) + type + data + big32(crc32(type + data));
}

// A PNG of `rows` (each already with its filter byte), stored in one uncompressed deflate
// block. `extra` chunks (PLTE, tRNS) go between IHDR and IDAT.
std::string handPng(int width, int height, int depth, int colourType, const std::string& rows,
                    const std::string& extra = "") {
  std::string ihdr = big32(uint32_t(width)) + big32(uint32_t(height));
  ihdr += {char(depth), char(colourType), 0, 0, 0};
  std::string zlib = {0x78, 0x01, 0x01};  // zlib header; a final stored block
  const uint16_t length = uint16_t(rows.size());
  zlib +=
      {char(length & 0xff), char(length >> 8), char(~length & 0xff), char((~length >> 8) & 0xff)};
  zlib += rows;
  uint32_t a = 1, b = 0;
  for (unsigned char c : rows) a = (a + c) % 65521, b = (b + a) % 65521;
  zlib += big32(b << 16 | a);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + extra + chunk("IDAT", zlib) +
         chunk("IEND", "");
}

std::string big16(uint16_t v) {
  return {char(v >> 8), char(v & 0xff)};
}

TextureImage readTexture(const fs::path& path) {
  return readTextureImage(path);
}

using test::inputErrorOf;

void expectRefused(const fs::path& path, const std::string& expected = "") {
  const std::string message = inputErrorOf([&] { readTextureImage(path); });
  EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
  EXPECT_NE(message.find(expected), std::string::npos) << message;
}

// ---- 8-bit files: PNG, TGA, BMP exactly; JPEG within a tolerance --------------------------

TEST_F(TextureImagePng, EightBitKeepsChannelsBytesAndRowOrder) {
  const int width = 5, height = 3;
  for (int channels : {1, 3, 4}) {
    SCOPED_TRACE(channels);
    const std::vector<uint8_t> texels = pattern(width, height, channels);
    const fs::path path = dir_ / ("c" + std::to_string(channels) + ".png");
    writeBytes(path, encode(StbFile::kPng, width, height, channels, texels));
    const TextureImage image = readTexture(path);
    EXPECT_EQ(image.width, width);
    EXPECT_EQ(image.height, height);
    EXPECT_EQ(image.channels, channels);
    EXPECT_TRUE(image.eightBit());
    EXPECT_TRUE(image.floats.empty());
    EXPECT_EQ(image.bytes, texels);  // row 0 of the file first: the top
  }
}

TEST_F(TextureImagePng, GreyAlphaBecomesRgbaWithGreyReplicated) {
  const std::vector<uint8_t> texels = pattern(3, 2, 2);
  const fs::path path = dir_ / "ga.PNG";  // any case
  writeBytes(path, encode(StbFile::kPng, 3, 2, 2, texels));
  const TextureImage image = readTexture(path);
  ASSERT_EQ(image.channels, 4);
  ASSERT_EQ(image.bytes.size(), 3u * 2u * 4u);
  for (size_t i = 0; i < 6; ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(image.bytes[4 * i + size_t(c)], texels[2 * i]) << i;
    EXPECT_EQ(image.bytes[4 * i + 3], texels[2 * i + 1]) << i;
  }
}

TEST_F(TextureImagePng, SixteenBitIsValueOver65535StillEncoded) {
  struct Case {
    int colourType, fileChannels, channels;
  };
  for (const Case c : {Case{0, 1, 1}, Case{2, 3, 3}, Case{4, 2, 4}, Case{6, 4, 4}}) {
    SCOPED_TRACE(c.colourType);
    const int width = 3, height = 2;
    std::string rows;
    std::vector<uint16_t> values;
    for (int y = 0; y < height; ++y) {
      rows += '\0';  // filter: none
      for (int i = 0; i < width * c.fileChannels; ++i) {
        const uint16_t v = uint16_t((y * 977 + i * 12345 + 1) % 65536);
        values.push_back(v);
        rows += big16(v);
      }
    }
    const fs::path path = dir_ / ("16-" + std::to_string(c.colourType) + ".png");
    writeBytes(path, handPng(width, height, 16, c.colourType, rows));
    const TextureImage image = readTexture(path);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    ASSERT_EQ(image.channels, c.channels);
    EXPECT_FALSE(image.eightBit());
    EXPECT_TRUE(image.floatsEncoded);
    ASSERT_EQ(image.floats.size(), size_t(width * height * c.channels));
    for (int t = 0; t < width * height; ++t) {
      std::vector<float> expected;
      auto v = [&](int k) { return float(values[size_t(t * c.fileChannels + k)]) / 65535.0f; };
      if (c.colourType == 4) {
        expected = {v(0), v(0), v(0), v(1)};
      } else {
        for (int k = 0; k < c.fileChannels; ++k) expected.push_back(v(k));
      }
      for (int k = 0; k < c.channels; ++k) {
        EXPECT_EQ(image.floats[size_t(t * c.channels + k)], expected[size_t(k)]) << t << " " << k;
      }
    }
  }
}

TEST_F(TextureImagePng, PaletteBecomesRgbAndTransparencyAddsAlpha) {
  // A 2x2 palette image: indices 0 1 / 2 0.
  const std::string palette = std::string("\x10\x20\x30\x40\x50\x60\x70\x80\x90", 9);
  const std::string rows = std::string("\0\x00\x01\0\x02\x00", 6);
  writeBytes(dir_ / "palette.png", handPng(2, 2, 8, 3, rows, chunk("PLTE", palette)));
  TextureImage image = readTexture(dir_ / "palette.png");
  ASSERT_EQ(image.channels, 3);
  EXPECT_EQ(image.bytes, (std::vector<uint8_t>{0x10, 0x20, 0x30, 0x40, 0x50, 0x60, 0x70, 0x80, 0x90,
                                               0x10, 0x20, 0x30}));
  // Entry 1 half transparent, the others opaque.
  writeBytes(dir_ / "palette-trns.png",
             handPng(2, 2, 8, 3, rows, chunk("PLTE", palette) + chunk("tRNS", "\xff\x80")));
  image = readTexture(dir_ / "palette-trns.png");
  ASSERT_EQ(image.channels, 4);
  EXPECT_EQ(image.bytes, (std::vector<uint8_t>{0x10, 0x20, 0x30, 255, 0x40, 0x50, 0x60, 0x80, 0x70,
                                               0x80, 0x90, 255, 0x10, 0x20, 0x30, 255}));
  // RGB with a transparent colour key.
  const std::string rgbRows = std::string("\0\x01\x02\x03\x04\x05\x06", 7);
  writeBytes(dir_ / "rgb-trns.png",
             handPng(2, 1, 8, 2, rgbRows, chunk("tRNS", std::string("\0\x04\0\x05\0\x06", 6))));
  image = readTexture(dir_ / "rgb-trns.png");
  ASSERT_EQ(image.channels, 4);
  EXPECT_EQ(image.bytes, (std::vector<uint8_t>{1, 2, 3, 255, 4, 5, 6, 0}));
  // readImage still reads them as RGB.
  EXPECT_EQ(readImage(dir_ / "palette-trns.png").width, 2);
}

TEST_F(TextureImageStb, TgaAndBmpKeepBytesAndRowOrder) {
  const int width = 7, height = 3;  // odd width: BMP rows are padded
  struct Case {
    StbFile kind;
    const char* name;
    int channels;
  };
  const Case cases[] = {
      {StbFile::kTga, "raw1.tga", 1},    {StbFile::kTga, "raw3.tga", 3},
      {StbFile::kTga, "raw4.tga", 4},    {StbFile::kTgaRle, "rle1.tga", 1},
      {StbFile::kTgaRle, "rle3.TGA", 3}, {StbFile::kTgaRle, "rle4.tga", 4},
      {StbFile::kBmp, "rgb.bmp", 3},     {StbFile::kBmp, "rgba.Bmp", 4},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::vector<uint8_t> texels = pattern(width, height, c.channels);
    // Runs, so that RLE has something to compress.
    for (size_t i = 0; i + 4 < texels.size(); i += 9) texels[i + 1] = texels[i + 4] = texels[i];
    const fs::path path = dir_ / c.name;
    writeBytes(path, encode(c.kind, width, height, c.channels, texels));
    const TextureImage image = readTexture(path);
    EXPECT_EQ(image.width, width);
    EXPECT_EQ(image.height, height);
    EXPECT_EQ(image.channels, c.channels);
    EXPECT_EQ(image.bytes, texels);
  }
}

TEST_F(TextureImageStb, TgaGreyAlphaBecomesRgba) {
  const std::vector<uint8_t> texels = pattern(4, 2, 2);
  writeBytes(dir_ / "ga.tga", encode(StbFile::kTga, 4, 2, 2, texels));
  const TextureImage image = readTexture(dir_ / "ga.tga");
  ASSERT_EQ(image.channels, 4);
  ASSERT_EQ(image.bytes.size(), 32u);
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(image.bytes[4 * i], texels[2 * i]);
    EXPECT_EQ(image.bytes[4 * i + 2], texels[2 * i]);
    EXPECT_EQ(image.bytes[4 * i + 3], texels[2 * i + 1]);
  }
}

TEST_F(TextureImageStb, JpegWithinToleranceTopRowFirst) {
  // Top half red, bottom half blue, in blocks JPEG keeps well at quality 100.
  const int width = 16, height = 16;
  std::vector<uint8_t> texels(size_t(width * height * 3));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      uint8_t* t = &texels[size_t((y * width + x) * 3)];
      t[0] = y < 8 ? 220 : 20;
      t[1] = 60;
      t[2] = y < 8 ? 20 : 220;
    }
  }
  for (const char* name : {"a.jpg", "b.JPEG"}) {
    writeBytes(dir_ / name, encode(StbFile::kJpeg, width, height, 3, texels));
    const TextureImage image = readTexture(dir_ / name);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    ASSERT_EQ(image.channels, 3);
    ASSERT_EQ(image.bytes.size(), texels.size());
    for (size_t i = 0; i < texels.size(); ++i) {
      EXPECT_NEAR(int(image.bytes[i]), int(texels[i]), 12) << i;
    }
  }
}

// ---- Float files: HDR, EXR, PFM -------------------------------------------------------------

TEST_F(TextureImageFloat, HdrFlatAndRunLengthRowsTopFirst) {
  // Values RGBE stores exactly (the largest channel a power of two times a byte).
  for (int width : {5, 20}) {  // stb_image_write writes narrow images flat, wide ones as runs
    SCOPED_TRACE(width);
    const int height = 3;
    std::vector<float> rgb;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const float top = float(1 << y);  // each row's largest channel
        rgb.insert(rgb.end(), {top, top * float(x % 4) / 4.0f, top * 0.5f});
      }
    }
    const fs::path path = dir_ / ("w" + std::to_string(width) + ".hdr");
    writeBytes(path, encodeHdr(width, height, rgb));
    const TextureImage image = readTexture(path);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    ASSERT_EQ(image.channels, 3);
    EXPECT_FALSE(image.eightBit());
    EXPECT_FALSE(image.floatsEncoded);
    ASSERT_EQ(image.floats.size(), rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i)
      EXPECT_NEAR(image.floats[i], rgb[i], 0.02f * rgb[i]) << i;
  }
}

// An EXR through tinyexr with the given channels (names in file order) of float planes.
void writeExr(const fs::path& path, const std::vector<std::string>& names,
              std::vector<std::vector<float>> planes, int width, int height) {
  std::vector<EXRChannelInfo> channels(names.size());
  std::vector<int> types(names.size(), TINYEXR_PIXELTYPE_FLOAT);
  std::vector<unsigned char*> pointers;
  for (size_t c = 0; c < names.size(); ++c) {
    std::strcpy(channels[c].name, names[c].c_str());
    pointers.push_back(reinterpret_cast<unsigned char*>(planes[c].data()));
  }
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = int(names.size());
  header.channels = channels.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  EXRImage image;
  InitEXRImage(&image);
  image.num_channels = int(names.size());
  image.images = pointers.data();
  image.width = width;
  image.height = height;
  const char* err = nullptr;
  ASSERT_EQ(SaveEXRImageToFile(&image, &header, path.c_str(), &err), TINYEXR_SUCCESS);
}

TEST_F(TextureImageFloat, ExrKeepsYRgbAndRgbaChannels) {
  const int width = 3, height = 2;
  std::vector<float> r, g, b, a, y;
  for (int i = 0; i < width * height; ++i) {
    r.push_back(float(i) + 0.25f);
    g.push_back(-float(i));
    b.push_back(1e-30f * float(i + 1));
    a.push_back(float(i) / 8.0f);
    y.push_back(100.0f + float(i));
  }
  struct Case {
    const char* name;
    std::vector<std::string> names;
    std::vector<std::vector<float>> planes;
    std::vector<const std::vector<float>*> expected;
  };
  const Case cases[] = {
      {"y.exr", {"Y"}, {y}, {&y}},
      {"rgb.exr", {"B", "G", "R"}, {b, g, r}, {&r, &g, &b}},
      {"rgba.exr", {"A", "B", "G", "R"}, {a, b, g, r}, {&r, &g, &b, &a}},
      {"ya.exr", {"A", "Y"}, {a, y}, {&y, &y, &y, &a}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    writeExr(dir_ / c.name, c.names, c.planes, width, height);
    const TextureImage image = readTexture(dir_ / c.name);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    ASSERT_EQ(image.channels, int(c.expected.size()));
    ASSERT_EQ(image.floats.size(), size_t(width * height) * c.expected.size());
    for (int t = 0; t < width * height; ++t) {  // tinyexr's planes are row 0 at the top too
      for (size_t k = 0; k < c.expected.size(); ++k) {
        EXPECT_EQ(image.floats[size_t(t) * c.expected.size() + k], (*c.expected[k])[size_t(t)]);
      }
    }
  }
  // readImage reads the RGBA file as RGB, as before.
  EXPECT_EQ(readImage(dir_ / "rgba.exr").at(1, 0), glm::vec3(r[1], g[1], b[1]));
}

TEST_F(TextureImageFloat, ExrAndPfmFromWriteImageAreBitExact) {
  Image rgb(4, 3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) rgb.at(x, y) = glm::vec3(float(x), float(y) * 0.1f, -1e-38f);
  }
  for (const char* name : {"w.exr", "w.pfm", "W.PFM"}) {
    SCOPED_TRACE(name);
    writeImage(rgb, dir_ / name);
    const TextureImage image = readTexture(dir_ / name);
    ASSERT_EQ(image.channels, 3);
    ASSERT_EQ(image.floats.size(), 36u);
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 4; ++x) {
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(std::bit_cast<uint32_t>(image.floats[size_t((y * 4 + x) * 3 + c)]),
                    std::bit_cast<uint32_t>(rgb.at(x, y)[c]));
        }
      }
    }
  }
}

TEST_F(TextureImageFloat, GreyPfmIsOneChannelBottomRowFirstInTheFile) {
  // 2x2, little-endian: the file's first row is the bottom one.
  std::string bytes = "Pf\n2 2\n-1.0\n";
  for (float v : {3.0f, 4.0f, 1.0f, 2.0f}) {
    const uint32_t bits = std::bit_cast<uint32_t>(v);
    for (int k = 0; k < 4; ++k) bytes += char(bits >> (8 * k));
  }
  writeBytes(dir_ / "grey.pfm", bytes);
  const TextureImage image = readTexture(dir_ / "grey.pfm");
  ASSERT_EQ(image.channels, 1);
  EXPECT_EQ(image.floats, (std::vector<float>{1.0f, 2.0f, 3.0f, 4.0f}));
}

// ---- Bad files ------------------------------------------------------------------------------

// A valid small file of each format, by name.
std::vector<std::pair<std::string, std::string>> goodFiles(const test::TempDir& dir) {
  const std::vector<uint8_t> texels = pattern(9, 5, 3);
  std::vector<float> floats(9 * 5 * 3);
  for (size_t i = 0; i < floats.size(); ++i) floats[i] = float(i % 7) + 0.5f;
  Image rgb(9, 5);
  writeImage(rgb, dir / "good.exr");
  writeImage(rgb, dir / "good.pfm");
  std::vector<std::pair<std::string, std::string>> files = {
      {"png", encode(StbFile::kPng, 9, 5, 3, texels)},
      {"jpg", encode(StbFile::kJpeg, 9, 5, 3, texels)},
      {"tga", encode(StbFile::kTga, 9, 5, 3, texels)},
      {"tga", encode(StbFile::kTgaRle, 9, 5, 3, std::vector<uint8_t>(texels.size(), 7))},
      {"bmp", encode(StbFile::kBmp, 9, 5, 3, texels)},
      {"hdr", encodeHdr(9, 5, floats)},  // runs
      {"hdr", encodeHdr(5, 9, floats)},  // flat
      {"exr", readBytes(dir / "good.exr")},
      {"pfm", readBytes(dir / "good.pfm")},
  };
  return files;
}

TEST_F(TextureImageErrors, TruncatedFilesAreRefusedAtEveryLength) {
  int n = 0;
  for (const auto& [ext, bytes] : goodFiles(dir_)) {
    const fs::path whole = dir_ / ("whole" + std::to_string(n++) + "." + ext);
    writeBytes(whole, bytes);
    ASSERT_NO_THROW(readTexture(whole)) << whole;
    // A few lengths near the start, in the middle and near the end.
    for (size_t length : {size_t(0), size_t(1), size_t(7), size_t(20), bytes.size() / 3,
                          bytes.size() / 2, bytes.size() - 5, bytes.size() - 1}) {
      SCOPED_TRACE(whole.string() + " cut to " + std::to_string(length));
      const fs::path path = dir_ / ("cut." + ext);
      writeBytes(path, bytes.substr(0, length));
      expectRefused(path);
    }
  }
}

TEST_F(TextureImageErrors, WrongMagicIsRefused) {
  const auto files = goodFiles(dir_);
  const std::string png = files[0].second, jpeg = files[1].second, bmp = files[4].second;
  const std::pair<const char*, std::string> cases[] = {
      {"png-as.jpg", png},
      {"jpeg-as.png", jpeg},
      {"bmp-as.tga", bmp},
      {"png-as.tga", png},
      {"png-as.bmp", png},
      {"png-as.hdr", png},
      {"text.hdr", "#?NOTRADIANCE\n\n-Y 1 +X 1\n"},
      {"jpeg-as.exr", jpeg},
      {"png-as.pfm", png},
  };
  for (const auto& [name, bytes] : cases) {
    SCOPED_TRACE(name);
    writeBytes(dir_ / name, bytes);
    expectRefused(dir_ / name);
  }
}

// Sets a little-endian field of `bytes`.
void put(std::string& bytes, size_t at, uint64_t value, int size) {
  for (int k = 0; k < size; ++k) bytes[at + size_t(k)] = char(value >> (8 * k));
}

TEST_F(TextureImageErrors, HeaderClaimingHugeSizeIsRefusedBeforeDecoding) {
  const auto files = goodFiles(dir_);
  struct Case {
    std::string name, bytes, expected;
  };
  std::vector<Case> cases;
  // Over the texel limit (2^28).
  const std::string limit = "more than the 268435456 a texture may have";
  cases.push_back({"huge.pfm", "PF\n20000 20000\n-1\n", limit});
  cases.push_back({"huge.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 20000 +X 20000\n", limit});
  std::string tga = files[2].second;
  put(tga, 12, 65535, 2);
  put(tga, 14, 65535, 2);
  cases.push_back({"huge.tga", tga, limit});
  std::string bmp = files[4].second;
  put(bmp, 18, 30000, 4);
  put(bmp, 22, 30000, 4);
  cases.push_back({"huge.bmp", bmp, limit});
  // Under the limit, but more than the file can hold.
  const std::string bound = "bytes of";
  put(bmp, 18, 16000, 4);
  put(bmp, 22, 16000, 4);
  cases.push_back({"big.bmp", bmp, bound});
  put(tga, 12, 16000, 2);
  put(tga, 14, 16000, 2);
  cases.push_back({"big.tga", tga, bound});
  cases.push_back({"big.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16000 +X 16000\n", bound});
  std::string jpeg = files[1].second;
  const size_t sof = jpeg.find("\xff\xc0");
  ASSERT_NE(sof, std::string::npos);
  jpeg[sof + 5] = char(16000 >> 8), jpeg[sof + 6] = char(16000 & 0xff);  // height, big-endian
  jpeg[sof + 7] = char(16000 >> 8), jpeg[sof + 8] = char(16000 & 0xff);  // width
  cases.push_back({"big.jpg", jpeg, bound});
  std::string png = files[0].second;
  png.replace(16, 8, big32(16000) + big32(16000));  // IHDR's width and height (CRC unchecked)
  cases.push_back({"big.png", png, "bytes of PNG can hold"});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    writeBytes(dir_ / c.name, c.bytes);
    expectRefused(dir_ / c.name, c.expected);
  }
}

TEST_F(TextureImageErrors, UnknownExtensionMissingFileAndDirectory) {
  for (const char* name : {"x.gif", "x.psd", "noextension", "x.png.txt"}) {
    SCOPED_TRACE(name);
    writeBytes(dir_ / name, encode(StbFile::kPng, 1, 1, 3, {1, 2, 3}));
    expectRefused(dir_ / name, "extension");
  }
  for (const char* name : {"missing.png", "missing.jpg", "missing.tga", "missing.bmp",
                           "missing.hdr", "missing.exr", "missing.pfm"}) {
    SCOPED_TRACE(name);
    expectRefused(dir_ / name, "not found");
  }
  fs::create_directory(dir_ / "folder.png");
  expectRefused(dir_ / "folder.png");
}

}  // namespace
}  // namespace pt
