// The command-line contract: exit statuses, one-line errors, no half-written outputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"

namespace pt {
namespace {

using test::PtResult;
using test::runPt;

// The path of a scene file in configs/, for the command line.
std::string config(const std::string& name) {
  return (test::kConfigs / name).string();
}

int lineCount(const std::string& s) {
  return int(std::count(s.begin(), s.end(), '\n'));
}

TEST(Cli, RenderWritesEveryOutputAndOneStatsLine) {
  test::TempDir dir;
  const PtResult r = runPt("render " + config("cornell-box.json") +
                           " --backend cpu --spp 2 --width 32 --height 32 --threads 2 --out " +
                           (dir / "a.png").string() + " --out " + (dir / "a.exr").string() +
                           " --out " + (dir / "a.pfm").string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"a.png", "a.exr", "a.pfm"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  EXPECT_EQ(lineCount(r.out), 1) << r.out;
  for (const char* key : {"backend=cpu", "threads=2", "resolution=32x32", "spp=2", "seconds=",
                          "Mrays/s=", "invalid_samples=0", "effects=diffuse+nee+mis+rr"}) {
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " in " << r.out;
  }
  // The same render compared with itself agrees; against a different seed it does not.
  EXPECT_EQ(runPt("diff " + (dir / "a.exr").string() + " " + (dir / "a.pfm").string()).status, 0);
  ASSERT_EQ(runPt("render " + config("cornell-box.json") +
                  " --backend cpu --spp 2 --width 32 --height 32 --seed 9 --out " +
                  (dir / "b.exr").string())
                .status,
            0);
  const PtResult d = runPt("diff " + (dir / "a.exr").string() + " " + (dir / "b.exr").string() +
                           " --heatmap " + (dir / "heat.png").string());
  EXPECT_EQ(d.status, 1) << d.out;
  EXPECT_NE(d.out.find("rmse="), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "heat.png"));
}

struct BadCase {
  const char* name;
  std::string args;
  std::string expectInError;  // a substring the one-line error must contain
};

TEST(Cli, BadInputGivesOneLineAndStatus2WithoutOutput) {
  test::TempDir dir;
  dir.write("broken.json", "{ \"materials\": [ }");
  dir.write("typo.json", R"({"materials": [{"name": "m"}],
    "shapes": [{"type": "quad", "material": "m", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]}],
    "camera": {"widht": 10}})");
  // Scenes whose texture is a bad image: cut short, not what its extension says, a header
  // larger than its data, an unknown format.
  const auto textured = [&](const std::string& name, const std::string& image) {
    dir.write(name, R"({"textures": [{"name": "t", "type": "imagemap", "filename": ")" + image +
                        R"("}], "materials": [{"name": "m", "reflectance": "t"}],
      "shapes": [{"type": "quad", "material": "m", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]}]})");
    return (dir / name).string();
  };
  dir.write("cut.png", std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\0\x10", 20));
  dir.write("text.jpg", "this is not a JPEG");
  dir.write("short.pfm", "PF\n64 64\n-1.0\n0123456789");
  dir.write("image.xyz", "xyz");
  // A TGA header for 64x64 true colour with 3 bytes of data; a BMP and an HDR cut after their
  // headers; an EXR that is only its magic number.
  dir.write("cut.tga", std::string("\0\0\x02\0\0\0\0\0\0\0\0\0\x40\0\x40\0\x18\0abc", 21));
  dir.write("cut.bmp", std::string("BM\x46\0\0\0\0\0\0\0\x36\0\0\0", 14));
  dir.write("cut.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 64 +X 64\n");
  dir.write("cut.exr", std::string("\x76\x2f\x31\x01", 4));
  const std::string cutTga = textured("tga.json", "cut.tga");
  const std::string cutBmp = textured("bmp.json", "cut.bmp");
  const std::string cutHdr = textured("hdr.json", "cut.hdr");
  const std::string cutExr = textured("exr.json", "cut.exr");
  const std::string cutPng = textured("cut.json", "cut.png");
  const std::string textJpg = textured("jpg.json", "text.jpg");
  const std::string shortPfm = textured("pfm.json", "short.pfm");
  const std::string unknown = textured("xyz.json", "image.xyz");
  const std::string out = " --out " + (dir / "out.png").string();
  const std::string box = config("cornell-box.json");
  const std::vector<BadCase> cases = {
      {"missing scene", "render " + (dir / "nope.json").string() + out, "nope.json"},
      {"malformed json", "render " + (dir / "broken.json").string() + out, "broken.json"},
      {"misspelled key", "render " + (dir / "typo.json").string() + out, "camera.widht"},
      {"zero spp", "render " + box + " --spp 0" + out, "--spp: must be a positive number, not 0"},
      {"negative width", "render " + box + " --width -4" + out,
       "--width: must be a positive number, not -4"},
      {"unknown backend", "render " + box + " --backend nope" + out, "--backend"},
      {"samples per pass on the cpu", "render " + box + " --backend cpu --samples-per-pass 4" + out,
       "--samples-per-pass"},
      {"zero samples per pass", "render " + box + " --samples-per-pass 0" + out,
       "--samples-per-pass: must be a positive number, not 0"},
      {"unknown extension",
       "render " + box + " --spp 1 --width 8 --height 8 --out " + (dir / "out.bmp").string(),
       "out.bmp"},
      {"missing image", "diff " + (dir / "x.exr").string() + " " + (dir / "y.exr").string(),
       "x.exr"},
      {"truncated texture", "render " + cutPng + out, "cut.png"},
      {"texture not of its format", "render " + textJpg + out, "text.jpg"},
      {"texture smaller than its header", "render " + shortPfm + out, "short.pfm"},
      {"texture of an unknown format", "render " + unknown + out, "image.xyz"},
      {"truncated TGA texture", "render " + cutTga + out, "cut.tga"},
      {"truncated BMP texture", "render " + cutBmp + out, "cut.bmp"},
      {"truncated HDR texture", "render " + cutHdr + out, "cut.hdr"},
      {"truncated EXR texture", "render " + cutExr + out, "cut.exr"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    const PtResult r = runPt(c.args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.expectInError), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out.bmp"));
  }
  // Nothing but the inputs is left in the directory (no temporary files).
  EXPECT_EQ(dir.listing(),
            (std::vector<std::string>{"bmp.json", "broken.json", "cut.bmp", "cut.exr", "cut.hdr",
                                      "cut.json", "cut.png", "cut.tga", "exr.json", "hdr.json",
                                      "image.xyz", "jpg.json", "pfm.json", "short.pfm", "text.jpg",
                                      "tga.json", "typo.json", "xyz.json"}));
}

TEST(CliVulkan, RendersOnTheDefaultBackendWithValidation) {
  test::TempDir dir;
  const PtResult r =
      runPt("render " + config("cornell-mirror.json") +
            " --spp 2 --width 16 --height 16 --validation --out " + (dir / "v.exr").string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* key : {"backend=vulkan", "device=", "effects=diffuse+mirror+nee+mis+rr",
                          "invalid_samples=0", "Mrays/s="}) {
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " in " << r.out;
  }
  EXPECT_EQ(r.err.find("validation"), std::string::npos) << r.err;

  // `pt devices` lists every device as "INDEX: NAME (TYPE; DRIVER)", indices counting from 0,
  // and among them the device the render ran on: in CI lavapipe, listed as
  // "0: llvmpipe (LLVM 15.0.6, 256 bits) (cpu; llvmpipe Mesa 22.3.6 (LLVM 15.0.6))".
  std::smatch used;
  ASSERT_TRUE(std::regex_search(r.out, used, std::regex("device=\"([^\"]+)\""))) << r.out;
  const PtResult d = runPt("devices");
  ASSERT_EQ(d.status, 0) << d.err;
  const std::regex format(
      R"((\d+): (.+) \((discrete|integrated|virtual|cpu|other); (.+)\)( unsuitable: .+)?)");
  std::istringstream lines(d.out);
  int count = 0;
  bool listed = false;
  for (std::string line; std::getline(lines, line); ++count) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(line, m, format)) << line;
    EXPECT_EQ(m[1].str(), std::to_string(count)) << line;
    if (m[2].str() != used[1].str()) continue;
    listed = true;
    EXPECT_FALSE(m[5].matched) << "the render ran on it, yet: " << line;
    if (m[2].str().find("llvmpipe") != std::string::npos) {
      EXPECT_EQ(m[3].str(), "cpu") << line;
      EXPECT_NE(m[4].str().find("llvmpipe"), std::string::npos) << line;
    }
  }
  EXPECT_GE(count, 1);
  EXPECT_TRUE(listed) << "no line for " << used[1].str() << " in:\n" << d.out;
}

TEST(CliVulkan, NoDriverGivesItsOwnExitStatus) {
  test::TempDir dir;
  // Point the loader at a driver manifest that does not exist: no Vulkan driver at all.
  const std::string env = "VK_ICD_FILENAMES=" + (dir / "none.json").string() +
                          " VK_DRIVER_FILES=" + (dir / "none.json").string();
  const PtResult r = runPt(
      "render " + config("cornell-box.json") + " --spp 1 --out " + (dir / "x.png").string(), env);
  EXPECT_EQ(r.status, 3);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("Vulkan"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
}

}  // namespace
}  // namespace pt
