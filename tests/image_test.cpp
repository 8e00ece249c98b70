// Tests of host/image: EXR/PFM/PNG round trips and file layout, error reporting, atomic
// writes, image comparison, the heatmap and the double-precision Film.

#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <tinyexr.h>

#include "common/check.h"
#include "image/image.h"
#include "test_util.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A fresh directory per test, named after it, removed afterwards.
class ImageTempDir : public testing::Test {
 protected:
  test::TempDir dir_;
};

using ImageExr = ImageTempDir;
using ImagePfm = ImageTempDir;
using ImagePng = ImageTempDir;
using ImageErrors = ImageTempDir;
using ImageWrite = ImageTempDir;

using test::readFile;

using test::writeBytes;

// An image of awkward float values: denormals, the extremes, signed zero, and distinct values
// per channel and pixel so that swapped channels, rows or columns show.
Image awkwardImage(bool withNonFinite) {
  const float specials[] = {0.0f,     -0.0f,   FLT_TRUE_MIN, FLT_MIN,     1e-40f, 1e-30f, 1e-8f,
                            0.1f,     0.5f,    1.0f,         3.14159265f, 1e10f,  1e30f,  FLT_MAX,
                            -FLT_MAX, -1e-20f, 0.1f + 1e-8f, 65504.f,     65520.f};
  Image image(7, 5);
  size_t k = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      glm::vec3& p = image.at(x, y);
      for (int c = 0; c < 3; ++c) {
        // Cycle through the specials; scale by a per-position factor so that no two are alike.
        const float s = specials[k % std::size(specials)];
        p[c] = s * (1.0f + float(k) * 0x1p-20f);
        ++k;
      }
    }
  }
  if (withNonFinite) {
    image.at(1, 0) = glm::vec3(kInf, -kInf, kNaN);
    image.at(0, 4).g = kNaN;
  }
  return image;
}

// Bit-for-bit equality, so -0 vs 0 and NaN payloads count too.
void expectBitIdentical(const Image& actual, const Image& expected) {
  ASSERT_EQ(actual.width, expected.width);
  ASSERT_EQ(actual.height, expected.height);
  for (int y = 0; y < expected.height; ++y) {
    for (int x = 0; x < expected.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(std::bit_cast<uint32_t>(actual.at(x, y)[c]),
                  std::bit_cast<uint32_t>(expected.at(x, y)[c]))
            << "pixel (" << x << ", " << y << ") channel " << c << ": " << actual.at(x, y)[c]
            << " vs " << expected.at(x, y)[c];
      }
    }
  }
}

using test::inputErrorOf;

void expectMessageStartsWithPath(const std::string& message, const fs::path& path) {
  EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
}

// ---- EXR ------------------------------------------------------------------------------------

TEST_F(ImageExr, RoundTripIsBitExactIncludingTinyHugeAndNonFinite) {
  const Image image = awkwardImage(true);
  const fs::path path = dir_ / "a.exr";
  writeImage(image, path);
  expectBitIdentical(readImage(path), image);
}

TEST_F(ImageExr, StoresFloatChannelsThatOtherReadersSeeAsRgb) {
  Image image(3, 2);
  image.at(0, 0) = glm::vec3(1.0f, 0.25f, 0.125f);  // top-left
  image.at(2, 1) = glm::vec3(0.5f, 2.0f, 3.0f);     // bottom-right
  const fs::path path = dir_ / "rgb.exr";
  writeImage(image, path);

  // The header: three FLOAT (not HALF) channels named B, G, R.
  EXRVersion version;
  ASSERT_EQ(ParseEXRVersionFromFile(&version, path.c_str()), TINYEXR_SUCCESS);
  EXRHeader header;
  InitEXRHeader(&header);
  const char* err = nullptr;
  ASSERT_EQ(ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err), TINYEXR_SUCCESS);
  ASSERT_EQ(header.num_channels, 3);
  std::vector<std::string> names;
  for (int c = 0; c < 3; ++c) {
    names.push_back(header.channels[c].name);
    EXPECT_EQ(header.pixel_types[c], TINYEXR_PIXELTYPE_FLOAT) << names.back();
  }
  EXPECT_EQ(names, (std::vector<std::string>{"B", "G", "R"}));
  FreeEXRHeader(&header);

  // tinyexr's own reader, independent of ours, matches channels by name: R must be red.
  float* rgba = nullptr;
  int width = 0, height = 0;
  ASSERT_EQ(LoadEXR(&rgba, &width, &height, path.c_str(), &err), TINYEXR_SUCCESS);
  ASSERT_EQ(width, 3);
  ASSERT_EQ(height, 2);
  EXPECT_EQ(rgba[0], 1.0f);
  EXPECT_EQ(rgba[1], 0.25f);
  EXPECT_EQ(rgba[2], 0.125f);
  const size_t last = 4 * (1 * 3 + 2);
  EXPECT_EQ(rgba[last + 0], 0.5f);
  EXPECT_EQ(rgba[last + 1], 2.0f);
  EXPECT_EQ(rgba[last + 2], 3.0f);
  std::free(rgba);
}

// Writes a one-channel float EXR whose channel is called `name`, through tinyexr directly.
void writeSingleChannelExr(const fs::path& path, const char* name, std::vector<float> values,
                           int width, int height) {
  EXRChannelInfo channel = {};
  std::strcpy(channel.name, name);
  int types[1] = {TINYEXR_PIXELTYPE_FLOAT};
  int stored[1] = {TINYEXR_PIXELTYPE_FLOAT};
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = 1;
  header.channels = &channel;
  header.pixel_types = types;
  header.requested_pixel_types = stored;
  header.compression_type = TINYEXR_COMPRESSIONTYPE_NONE;
  unsigned char* planes[1] = {reinterpret_cast<unsigned char*>(values.data())};
  EXRImage image;
  InitEXRImage(&image);
  image.num_channels = 1;
  image.images = planes;
  image.width = width;
  image.height = height;
  const char* err = nullptr;
  ASSERT_EQ(SaveEXRImageToFile(&image, &header, path.c_str(), &err), TINYEXR_SUCCESS);
}

TEST_F(ImageExr, LuminanceOnlyFileIsReplicatedToRgb) {
  const fs::path path = dir_ / "y.exr";
  writeSingleChannelExr(path, "Y", {0.25f, 1.5f, 7.0f, 1e-30f}, 2, 2);
  const Image image = readImage(path);
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 2);
  EXPECT_EQ(image.at(0, 0), glm::vec3(0.25f));
  EXPECT_EQ(image.at(1, 0), glm::vec3(1.5f));
  EXPECT_EQ(image.at(0, 1), glm::vec3(7.0f));
  EXPECT_EQ(image.at(1, 1), glm::vec3(1e-30f));
}

TEST_F(ImageExr, HalfFloatFileIsWidened) {
  // Values exactly representable in half precision, so the expected result is exact.
  const std::vector<float> rgb = {0.5f, 2.0f, -4.0f, 0.0f, 1024.0f, 0.125f};
  const fs::path path = dir_ / "half.exr";
  const char* err = nullptr;
  ASSERT_EQ(SaveEXR(rgb.data(), 2, 1, 3, /*save_as_fp16=*/1, path.c_str(), &err), TINYEXR_SUCCESS);
  const Image image = readImage(path);
  ASSERT_EQ(image.width, 2);
  EXPECT_EQ(image.at(0, 0), glm::vec3(0.5f, 2.0f, -4.0f));
  EXPECT_EQ(image.at(1, 0), glm::vec3(0.0f, 1024.0f, 0.125f));
}

TEST_F(ImageExr, UppercaseExtensionIsAccepted) {
  const Image image = awkwardImage(false);
  const fs::path path = dir_ / "UPPER.EXR";
  writeImage(image, path);
  expectBitIdentical(readImage(path), image);
}

// ---- PFM ------------------------------------------------------------------------------------

TEST_F(ImagePfm, RoundTripIsBitExactIncludingTinyHugeAndNonFinite) {
  const Image image = awkwardImage(true);
  const fs::path path = dir_ / "a.pfm";
  writeImage(image, path);
  expectBitIdentical(readImage(path), image);
}

TEST_F(ImagePfm, StoresBottomRowFirstInLittleEndian) {
  Image image(2, 2);
  image.at(0, 0) = image.at(1, 0) = glm::vec3(1, 0, 0);  // top row red
  image.at(0, 1) = image.at(1, 1) = glm::vec3(0, 0, 1);  // bottom row blue
  const fs::path path = dir_ / "rows.pfm";
  writeImage(image, path);

  const std::string bytes = readFile(path);
  const std::string header = "PF\n2 2\n-1.0\n";
  ASSERT_EQ(bytes.size(), header.size() + 2 * 2 * 3 * 4);
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  // 1.0f is 0x3f800000: little-endian bytes 00 00 80 3f.
  const std::string zero(4, '\0');
  const std::string one("\x00\x00\x80\x3f", 4);
  const std::string blue = zero + zero + one, red = one + zero + zero;
  EXPECT_EQ(bytes.substr(header.size(), 24), blue + blue) << "first stored row must be the bottom";
  EXPECT_EQ(bytes.substr(header.size() + 24, 24), red + red);
}

TEST_F(ImagePfm, ReadsBigEndianGreyscaleWithRowsFlipped) {
  // "Pf", positive scale: big-endian, one channel. 2x2, stored bottom row (1, 2) first.
  auto be = [](float v) {
    const uint32_t bits = std::bit_cast<uint32_t>(v);
    return std::string{char(bits >> 24), char(bits >> 16), char(bits >> 8), char(bits)};
  };
  const fs::path path = dir_ / "grey.pfm";
  writeBytes(path, "Pf\n2 2\n1.0\n" + be(1) + be(2) + be(3) + be(4));
  const Image image = readImage(path);
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 2);
  EXPECT_EQ(image.at(0, 0), glm::vec3(3));
  EXPECT_EQ(image.at(1, 0), glm::vec3(4));
  EXPECT_EQ(image.at(0, 1), glm::vec3(1));
  EXPECT_EQ(image.at(1, 1), glm::vec3(2));
}

TEST_F(ImagePfm, ScaleMagnitudeMultipliesValues) {
  // Little-endian (negative scale) colour file, |scale| = 2, header fields on one line.
  const fs::path path = dir_ / "scaled.pfm";
  const float values[3] = {0.5f, 1.5f, -3.0f};
  writeBytes(path, "PF 1 1 -2.0\n" + std::string(reinterpret_cast<const char*>(values), 12));
  EXPECT_EQ(readImage(path).at(0, 0), glm::vec3(1.0f, 3.0f, -6.0f));
}

// ---- PNG ------------------------------------------------------------------------------------

TEST(ImageSrgb, CurveSpotValues) {
  EXPECT_EQ(linearToSrgb8(0.5f), 188);
  EXPECT_EQ(linearToSrgb8(0.18f), 118);      // 1.055 * 0.18^(1/2.4) - 0.055 = 0.4614
  EXPECT_EQ(linearToSrgb8(0.0031308f), 10);  // top of the linear segment: 0.04045
  EXPECT_EQ(linearToSrgb8(0.001f), 3);       // linear segment: 12.92 * 0.001 * 255 = 3.29
  EXPECT_EQ(linearToSrgb8(0.0f), 0);
  EXPECT_EQ(linearToSrgb8(1.0f), 255);
  EXPECT_EQ(linearToSrgb8(7.0f), 255);  // clamped
  EXPECT_EQ(linearToSrgb8(-1.0f), 0);   // clamped
  EXPECT_EQ(linearToSrgb8(kNaN), 0);    // NaN written as 0 in PNG
  EXPECT_EQ(linearToSrgb8(kInf), 255);
  EXPECT_NEAR(linearToSrgb(0.001f), 0.01292f, 1e-7f);
  EXPECT_NEAR(srgbToLinear(0.5f), 0.214041f, 1e-6f);
  EXPECT_NEAR(srgbToLinear(0.04045f), 0.04045f / 12.92f, 1e-9f);
  for (float v : {0.0f, 0.002f, 0.0031308f, 0.01f, 0.2f, 0.5f, 0.9f, 1.0f}) {
    EXPECT_NEAR(srgbToLinear(linearToSrgb(v)), v, 1e-6f) << v;
  }
}

TEST_F(ImagePng, RoundTripWithinOneCode) {
  // Every 8-bit code several times over, and out-of-range and NaN values.
  Image image(64, 17);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const float t = float(i) / float(image.pixels.size() - 1);
    image.pixels[i] = glm::vec3(t, t * t, 1.0f - t);
  }
  image.at(0, 0) = glm::vec3(2.0f, -0.5f, kNaN);
  const fs::path path = dir_ / "a.png";
  writeImage(image, path);
  const Image back = readImage(path);
  ASSERT_EQ(back.width, image.width);
  ASSERT_EQ(back.height, image.height);
  EXPECT_EQ(back.at(0, 0), glm::vec3(1.0f, 0.0f, 0.0f));
  for (size_t i = 1; i < image.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      // Compared in encoded units: quantisation to 8 bits moves a value at most half a code.
      const float expected = linearToSrgb(image.pixels[i][c]);
      EXPECT_NEAR(linearToSrgb(back.pixels[i][c]), expected, 0.5f / 255.0f + 1e-6f)
          << "pixel " << i << " channel " << c;
    }
  }
}

TEST_F(ImagePng, HalfLinearIsStoredAsCode188) {
  Image image(1, 1);
  image.at(0, 0) = glm::vec3(0.5f, 0.0f, 1.0f);
  const fs::path path = dir_ / "half.png";
  writeImage(image, path);
  const glm::vec3 back = readImage(path).at(0, 0);
  // Reading decodes code 188 exactly: 188/255 through the sRGB curve is 0.50289.
  EXPECT_NEAR(back.r, srgbToLinear(188.0f / 255.0f), 1e-6f);
  EXPECT_NEAR(back.r, 0.502886f, 1e-5f);
  EXPECT_EQ(back.g, 0.0f);
  EXPECT_EQ(back.b, 1.0f);
}

// ---- Errors ---------------------------------------------------------------------------------

TEST_F(ImageErrors, MissingFileNamesThePath) {
  for (const char* name : {"missing.exr", "missing.pfm", "missing.png"}) {
    const fs::path path = dir_ / name;
    const std::string message = inputErrorOf([&] { readImage(path); });
    expectMessageStartsWithPath(message, path);
    EXPECT_NE(message.find("not found"), std::string::npos) << message;
  }
}

TEST_F(ImageErrors, MalformedPfmNamesThePathAndTheProblem) {
  const std::string twelve(12, '\0');
  struct Case {
    std::string bytes, expected;
  };
  const Case cases[] = {
      {"", "expected 'PF'"},
      {"P6\n1 1\n255\n", "expected 'PF'"},
      {"PF", "width"},
      {"PF\n0 1\n-1.0\n" + twelve, "width '0'"},
      {"PF\n1 -1\n-1.0\n" + twelve, "height '-1'"},
      {"PF\n1 x\n-1.0\n" + twelve, "height 'x'"},
      {"PF\n1 1\n0\n" + twelve, "scale '0'"},
      {"PF\n1 1\nabc\n" + twelve, "scale 'abc'"},
      {"PF\n1 1\n-1.0", "newline after the scale"},
      {"PF\n2 2\n-1.0\n" + twelve, "truncated pixel data: expected 48 bytes for 2x2, found 12"},
      {"PF\n1 1\n-1.0\n" + twelve + "xx", "2 unexpected bytes"},
      {"Pf\n1 2\n-1.0\n" + std::string(7, '\0'), "truncated pixel data"},
  };
  int i = 0;
  for (const Case& c : cases) {
    const fs::path path = dir_ / ("bad" + std::to_string(i++) + ".pfm");
    writeBytes(path, c.bytes);
    const std::string message = inputErrorOf([&] { readImage(path); });
    expectMessageStartsWithPath(message, path);
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
  }
}

TEST_F(ImageErrors, MalformedExrAndPngNameThePath) {
  // Garbage, and valid files cut short.
  const Image image = awkwardImage(false);
  writeImage(image, dir_ / "good.exr");
  writeImage(image, dir_ / "good.png");
  const std::string exr = readFile(dir_ / "good.exr");
  const std::string png = readFile(dir_ / "good.png");
  const std::pair<const char*, std::string> files[] = {
      {"garbage.exr", "this is not an image"},          {"header-only.exr", exr.substr(0, 40)},
      {"truncated.exr", exr.substr(0, exr.size() / 2)}, {"garbage.png", "this is not an image"},
      {"truncated.png", png.substr(0, png.size() / 2)},
  };
  for (const auto& [name, bytes] : files) {
    const fs::path path = dir_ / name;
    writeBytes(path, bytes);
    expectMessageStartsWithPath(inputErrorOf([&] { readImage(path); }), path);
  }
}

TEST_F(ImageErrors, ExrWhoseDataWindowClaimsTooMuchIsRefusedBeforeDecoding) {
  // A valid 4x4 ZIP-compressed EXR whose dataWindow attribute is edited to claim 8,000,000 x
  // 1000 pixels (tinyexr accepts up to 8M per side and would allocate 96 GB): refused from the
  // header, as more than its bytes can hold, without decoding.
  writeImage(Image(4, 4), dir_ / "small.exr");
  std::string bytes = readFile(dir_ / "small.exr");
  const std::string attribute("dataWindow\0box2i\0", 17);
  const size_t at = bytes.find(attribute);
  ASSERT_NE(at, std::string::npos);
  const size_t box = at + attribute.size() + 4;        // after the attribute's 4-byte size
  const int32_t claimed[4] = {0, 0, 7999999, 999};     // min x, min y, max x, max y
  std::memcpy(&bytes[box], claimed, sizeof(claimed));  // EXR is little-endian, like x86
  const fs::path path = dir_ / "huge-window.exr";
  writeBytes(path, bytes);
  const std::string message = inputErrorOf([&] { readImage(path); });
  expectMessageStartsWithPath(message, path);
  EXPECT_NE(message.find("header says 8000000x1000 pixels, more than"), std::string::npos)
      << message;
}

TEST_F(ImageErrors, ExrHeadersThatWouldAbortTinyexrAreRefused) {
  // tinyexr asserts (aborts the process) on a "type" attribute it does not know or that
  // disagrees with the tiled flag, and on a "tiles" attribute that is not 9 bytes: each is
  // refused with one line first. A valid EXR gets the attribute inserted after its version.
  writeImage(Image(4, 4), dir_ / "small.exr");
  const std::string valid = readFile(dir_ / "small.exr");
  struct Case {
    const char* name;
    std::string attribute;
    bool tiled;
    const char* expected;
  };
  auto attribute = [](std::string_view name, std::string_view type, std::string_view value) {
    std::string a = std::string(name) + '\0' + std::string(type) + '\0';
    const uint32_t size = uint32_t(value.size());
    a.append(reinterpret_cast<const char*>(&size), 4);  // little-endian, like x86
    return a + std::string(value);
  };
  const Case cases[] = {
      {"deep type", attribute("type", "string", std::string_view("deepscanline\0", 13)), false,
       "EXR image type 'deepscanline' is not supported"},
      {"unknown type", attribute("type", "string", std::string_view("Window\0", 7)), false,
       "EXR image type 'Window' is not supported"},
      {"tiled type in a scanline file", attribute("type", "string", "tiledimage"), false,
       "EXR attribute 'type' is not a terminated string"},
      {"short tiles", attribute("tiles", "tiledesc", std::string(8, '\1')), true,
       "EXR attribute 'tiles' has 8 bytes, not 9"},
      {"tile level mode 3", attribute("tiles", "tiledesc", std::string(8, '\1') + '\3'), true,
       "EXR tile level mode 3 is not defined"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::string bytes = valid;
    if (c.tiled) bytes[5] = char(bytes[5] | 0x02);  // the version's tiled bit (bit 9)
    bytes.insert(8, c.attribute);
    const fs::path path = dir_ / "odd.exr";
    writeBytes(path, bytes);
    const std::string message = inputErrorOf([&] { readImage(path); });
    expectMessageStartsWithPath(message, path);
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
  }
}

TEST_F(ImageErrors, UnknownExtensionNamesTheFile) {
  const Image image(2, 2);
  for (const char* name : {"x.bmp", "x.jpg", "noextension"}) {
    const fs::path path = dir_ / name;
    const std::string writeMessage = inputErrorOf([&] { writeImage(image, path); });
    expectMessageStartsWithPath(writeMessage, path);
    EXPECT_NE(writeMessage.find("extension"), std::string::npos) << writeMessage;
    EXPECT_FALSE(fs::exists(path));
    writeBytes(path, "data");
    expectMessageStartsWithPath(inputErrorOf([&] { readImage(path); }), path);
  }
}

TEST_F(ImageErrors, EmptyImageIsNotWritten) {
  const fs::path path = dir_ / "empty.pfm";
  expectMessageStartsWithPath(inputErrorOf([&] { writeImage(Image(), path); }), path);
  EXPECT_TRUE(dir_.listing().empty());
}

// ---- Atomic writes --------------------------------------------------------------------------

TEST_F(ImageWrite, IntoMissingDirectoryThrowsAndLeavesNothing) {
  for (const char* name : {"a.exr", "a.pfm", "a.png"}) {
    const fs::path path = dir_ / "no-such-dir" / name;
    const std::string message = inputErrorOf([&] { writeImage(awkwardImage(false), path); });
    expectMessageStartsWithPath(message, path);
    EXPECT_NE(message.find("cannot write"), std::string::npos) << message;
  }
  EXPECT_TRUE(dir_.listing().empty());
}

TEST_F(ImageWrite, OverwriteReplacesTheFileAndLeavesNoTemporaries) {
  for (const char* name : {"a.exr", "a.pfm", "a.png"}) {
    Image first(3, 3), second(3, 3);
    first.at(1, 1) = glm::vec3(0.25f);
    second.at(2, 2) = glm::vec3(1.0f);
    writeImage(first, dir_ / name);
    writeImage(second, dir_ / name);
    const Image back = readImage(dir_ / name);
    EXPECT_EQ(back.at(1, 1), glm::vec3(0.0f)) << name;
    EXPECT_EQ(back.at(2, 2), glm::vec3(1.0f)) << name;
  }
  EXPECT_EQ(dir_.listing(), (std::vector<std::string>{"a.exr", "a.pfm", "a.png"}));
}

TEST_F(ImageWrite, FailedWriteMidFileKeepsTheExistingFile) {
  // The new file fails part-way through (a file size limit makes the write fail with EFBIG);
  // the old file must survive untouched and the temporary file must be gone. Run in a child
  // process so that the limit does not leak into other tests.
  const fs::path path = dir_ / "keep.pfm";
  Image old(2, 2);
  old.at(1, 0) = glm::vec3(0.75f);
  writeImage(old, path);
  const std::string before = readFile(path);

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // report EFBIG instead of killing the process
    const rlimit limit = {4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    int code = 1;  // 1: no exception
    try {
      writeImage(Image(64, 64), path);  // about 49 KB, well over the limit
    } catch (const InputError& e) {
      const std::string message = e.what();
      code = message.rfind(path.string() + ": cannot write", 0) == 0 ? 0 : 2;
    } catch (...) {
      code = 3;
    }
    std::_Exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: no error, 2: wrong message, 3: other exception";
  EXPECT_EQ(readFile(path), before);
  EXPECT_EQ(dir_.listing(), std::vector<std::string>{"keep.pfm"});
}

TEST_F(ImageWrite, FailedRenameKeepsTheTargetAndRemovesTheTemporary) {
  // A non-empty directory where the file should go: everything is written, the final rename
  // fails, and the temporary file must be cleaned up.
  const fs::path path = dir_ / "target.exr";
  fs::create_directory(path);
  writeBytes(path / "inside", "x");
  const std::string message = inputErrorOf([&] { writeImage(Image(4, 4), path); });
  expectMessageStartsWithPath(message, path);
  EXPECT_EQ(dir_.listing(), std::vector<std::string>{"target.exr"});
  EXPECT_EQ(readFile(path / "inside"), "x");
}

// ---- Diff -----------------------------------------------------------------------------------

TEST(DiffStats, HandComputedValues) {
  // a against reference b; per-channel differences (0, 0, 2), (-0.5, 0, 0), (3, 0, 0).
  Image a(3, 1), b(3, 1);
  a.at(0, 0) = glm::vec3(1, 2, 3);
  b.at(0, 0) = glm::vec3(1, 2, 1);
  a.at(1, 0) = glm::vec3(0, 0, 0);
  b.at(1, 0) = glm::vec3(0.5f, 0, 0);
  a.at(2, 0) = glm::vec3(13, 0, 0);
  b.at(2, 0) = glm::vec3(10, 0, 0);

  const DiffStats s = diffImages(a, b, 0.4);
  EXPECT_EQ(s.pixelCount, 3u);
  EXPECT_EQ(s.nonFinitePixels, 0u);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt((4.0 + 0.25 + 9.0) / 9.0));
  EXPECT_DOUBLE_EQ(s.relMse, (4.0 / 1.01 + 0.25 / 0.26 + 9.0 / 100.01) / 9.0);
  EXPECT_DOUBLE_EQ(s.maxAbsError, 3.0);
  // Over when |a - b| > threshold * max(1, |b|). At 0.4: 2 > 0.4, 0.5 > 0.4, but 3 <= 4
  // because the third pixel's reference is 10.
  EXPECT_EQ(s.pixelsOverThreshold, 2u);
  // At 0.25: 2 > 0.25, 0.5 > 0.25, 3 > 2.5.
  EXPECT_EQ(diffImages(a, b, 0.25).pixelsOverThreshold, 3u);
  // At 0.5: 2 > 0.5 only (0.5 is not over 0.5, and 3 <= 5).
  EXPECT_EQ(diffImages(a, b, 0.5).pixelsOverThreshold, 1u);

  const DiffStats same = diffImages(a, a, 0.0);
  EXPECT_EQ(same.rmse, 0.0);
  EXPECT_EQ(same.relMse, 0.0);
  EXPECT_EQ(same.maxAbsError, 0.0);
  EXPECT_EQ(same.pixelsOverThreshold, 0u);
}

TEST(DiffStats, SizeMismatchThrows) {
  const std::string message =
      inputErrorOf([] { diffImages(Image(256, 256), Image(128, 128), 0.1); });
  EXPECT_EQ(message, "image sizes differ: 256x256 vs 128x128");
  EXPECT_THROW(diffImages(Image(2, 3), Image(3, 2), 0.1), InputError);
  EXPECT_THROW(diffHeatmap(Image(2, 3), Image(3, 2), 1.0), InputError);
}

TEST(DiffStats, NonFinitePixelsAreCountedAndFail) {
  Image a(4, 1), b(4, 1);
  a.at(0, 0).g = kNaN;                        // NaN in the image under test
  b.at(1, 0).r = kInf;                        // infinity in the reference
  a.at(2, 0) = b.at(2, 0) = glm::vec3(kInf);  // equal infinities are still not finite
  a.at(3, 0) = glm::vec3(0.5f, 0, 0);         // the one finite difference
  const DiffStats s = diffImages(a, b, 10.0);
  EXPECT_EQ(s.pixelCount, 4u);
  EXPECT_EQ(s.nonFinitePixels, 3u);
  EXPECT_EQ(s.pixelsOverThreshold, 3u);
  // The finite pixel alone makes the statistics, which stay finite.
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(0.25 / 3.0));
  EXPECT_DOUBLE_EQ(s.relMse, (0.25 / 0.01) / 3.0);
  EXPECT_DOUBLE_EQ(s.maxAbsError, 0.5);
}

TEST(DiffHeatmap, RampStopsAndNonFiniteGreen) {
  // Errors of 0, scale/4, scale/2, 3 scale/4, scale, 3 scale, 3 scale/8 and a NaN.
  const double scale = 2.0;
  Image a(8, 1), b(8, 1);
  const float errors[7] = {0.0f, 0.5f, 1.0f, 1.5f, 2.0f, 6.0f, 0.75f};
  for (int x = 0; x < 7; ++x) {
    b.at(x, 0) = glm::vec3(1.0f);
    a.at(x, 0) = glm::vec3(1.0f, 1.0f - errors[x], 1.0f);  // max channel error = errors[x]
  }
  a.at(7, 0).b = kNaN;
  const Image h = diffHeatmap(a, b, scale);
  ASSERT_EQ(h.width, 8);
  EXPECT_EQ(h.at(0, 0), glm::vec3(0, 0, 0));     // black
  EXPECT_EQ(h.at(1, 0), glm::vec3(0, 0, 1));     // blue
  EXPECT_EQ(h.at(2, 0), glm::vec3(1, 0, 1));     // magenta
  EXPECT_EQ(h.at(3, 0), glm::vec3(1, 1, 0));     // yellow
  EXPECT_EQ(h.at(4, 0), glm::vec3(1, 1, 1));     // white
  EXPECT_EQ(h.at(5, 0), glm::vec3(1, 1, 1));     // clamped
  EXPECT_EQ(h.at(7, 0), glm::vec3(0, 1, 0));     // non-finite: pure green
  EXPECT_EQ(h.at(6, 0), glm::vec3(0.5f, 0, 1));  // half-way from blue to magenta, linear
  EXPECT_THROW(diffHeatmap(a, b, 0.0), InputError);
}

TEST(DiffHeatmap, BrightnessGrowsWithError) {
  const int n = 101;
  Image a(n, 1), b(n, 1);
  for (int x = 0; x < n; ++x) a.at(x, 0) = glm::vec3(float(x) / float(n - 1));
  const Image h = diffHeatmap(a, b, 1.0);
  auto luminance = [](glm::vec3 c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; };
  for (int x = 1; x < n; ++x) {
    EXPECT_GT(luminance(h.at(x, 0)), luminance(h.at(x - 1, 0))) << x;
  }
}

// ---- Film -----------------------------------------------------------------------------------

TEST(Film, MillionsOfSamplesDoNotDrift) {
  // 1e6 samples of 0.1f interleaved with 1e6 of 1e-8f into one pixel, as a long render would.
  // The tiny samples move the mean by 1e-7 relative: a float film loses them entirely.
  constexpr int kEach = 1'000'000;
  Film film(2, 1);
  float naive = 0.0f;  // what a float accumulator would do
  for (int i = 0; i < kEach; ++i) {
    film.add(1, 0, glm::vec3(0.1f));
    film.add(1, 0, glm::vec3(1e-8f));
    naive += 0.1f;
    naive += 1e-8f;
  }
  ASSERT_EQ(film.sampleCount[1], 2u * kEach);
  // The exact mean of the samples (each product and the sum round once).
  const double exact =
      (double(kEach) * double(0.1f) + double(kEach) * double(1e-8f)) / (2.0 * kEach);
  const double mean = film.sum(1).x / double(film.sampleCount[1]);
  // Recursive summation in double is off by at most (n - 1) * 2^-53 relative (2.2e-10 for
  // 2e6 terms); the 1e-8 samples contribute 1e-7, far above that, so losing them fails here.
  // (1e-12, tighter than that bound, is not guaranteed by plain double summation.)
  EXPECT_NEAR(mean, exact, exact * 2.5e-10);
  EXPECT_GT(std::fabs(mean - double(0.1f) / 2.0), exact * 5e-8) << "tiny samples were lost";
  // The float accumulator is off by far more: the test can tell the two apart.
  const double naiveMean = double(naive) / (2.0 * kEach);
  EXPECT_GT(std::fabs(naiveMean - exact), exact * 1e-3);
  // Resolving rounds the double mean to the nearest float.
  EXPECT_EQ(film.resolve().at(1, 0), glm::vec3(float(mean)));
  EXPECT_EQ(film.resolve().at(0, 0), glm::vec3(0.0f));  // no samples: 0
}

TEST(Film, InvalidSamplesAreCountedNotAdded) {
  Film film(2, 2);
  film.add(0, 0, glm::vec3(1.0f, 2.0f, 3.0f));
  film.add(0, 0, glm::vec3(kNaN, 0.0f, 0.0f));
  film.add(0, 0, glm::vec3(0.0f, kInf, 0.0f));
  film.add(0, 0, glm::vec3(3.0f, 4.0f, 5.0f));
  film.add(1, 1, glm::vec3(0.0f, 0.0f, -kInf));
  EXPECT_EQ(film.sampleCount[0], 2u);
  EXPECT_EQ(film.invalidCount[0], 2u);
  EXPECT_EQ(film.invalidCount[3], 1u);
  EXPECT_EQ(film.sampleCount[3], 0u);
  EXPECT_EQ(film.totalInvalid(), 3u);
  const Image image = film.resolve();
  EXPECT_EQ(image.at(0, 0), glm::vec3(2.0f, 3.0f, 4.0f));
  EXPECT_EQ(image.at(1, 1), glm::vec3(0.0f));  // only invalid samples: no value, still counted
}

TEST(Film, MergeAddsSumsAndCounts) {
  Film a(2, 1), b(2, 1);
  a.add(0, 0, glm::vec3(1.0f));
  b.add(0, 0, glm::vec3(3.0f));
  b.add(0, 0, glm::vec3(5.0f));
  b.add(1, 0, glm::vec3(kNaN));
  a.merge(b);
  EXPECT_EQ(a.sampleCount[0], 3u);
  EXPECT_EQ(a.sum(0), glm::dvec3(9.0));
  EXPECT_EQ(a.invalidCount[1], 1u);
  EXPECT_EQ(a.totalInvalid(), 1u);
  EXPECT_EQ(a.resolve().at(0, 0), glm::vec3(3.0f));
  // b is unchanged.
  EXPECT_EQ(b.sampleCount[0], 2u);
}

TEST(FilmDeathTest, MergeOfDifferentSizesIsAnInternalError) {
  Film a(2, 1), b(1, 2);
  EXPECT_DEATH(a.merge(b), "check failed");
}

TEST(Film, ConcurrentAddsToDisjointPixels) {
  // The renderers' pattern: each thread owns some rows. Counts must come out exact.
  constexpr int kThreads = 4, kWidth = 16, kSamples = 1000;
  Film film(kWidth, kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&film, t] {
      for (int s = 0; s < kSamples; ++s) {
        for (int x = 0; x < kWidth; ++x) film.add(x, t, glm::vec3(float(t)));
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  const Image image = film.resolve();
  for (int t = 0; t < kThreads; ++t) {
    for (int x = 0; x < kWidth; ++x) {
      EXPECT_EQ(film.sampleCount[size_t(t) * kWidth + size_t(x)], uint64_t(kSamples));
      EXPECT_EQ(image.at(x, t), glm::vec3(float(t)));
    }
  }
}

}  // namespace
}  // namespace pt
