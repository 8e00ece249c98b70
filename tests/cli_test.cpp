// The command-line contract: exit statuses, one-line errors, no half-written outputs.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sys/wait.h>

#include "test_util.h"

namespace pt {
namespace {

const std::string kPt = PT_BINARY;
const std::string kConfigs = std::string(PT_SOURCE_DIR) + "/configs";

struct Result {
  int status = -1;
  std::string out, err;
};

// Runs `pt args`, capturing stdout and stderr through files.
Result runPt(const std::string& args, const test::TempDir& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = kPt + " " + args + " >" + out.string() + " 2>" + err.string();
  const int raw = std::system(cmd.c_str());
  Result r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  auto slurp = [](const std::filesystem::path& p) {
    std::ifstream f(p);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

int lineCount(const std::string& s) {
  return int(std::count(s.begin(), s.end(), '\n'));
}

TEST(Cli, RenderWritesEveryOutputAndOneStatsLine) {
  test::TempDir dir;
  const Result r = runPt("render " + kConfigs +
                             "/cornell-box.json --backend cpu --spp 2 --width 32 --height 32 " +
                             "--threads 2 --out " + (dir / "a.png").string() + " --out " +
                             (dir / "a.exr").string() + " --out " + (dir / "a.pfm").string(),
                         dir);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"a.png", "a.exr", "a.pfm"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  EXPECT_EQ(lineCount(r.out), 1) << r.out;
  for (const char* key : {"backend=cpu", "threads=2", "resolution=32x32", "spp=2", "seconds=",
                          "Mrays/s=", "invalid_samples=0", "effects=diffuse+nee+mis+rr"}) {
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " in " << r.out;
  }
  // The same render compared with itself agrees; against a different seed it does not.
  EXPECT_EQ(runPt("diff " + (dir / "a.exr").string() + " " + (dir / "a.pfm").string(), dir).status,
            0);
  ASSERT_EQ(runPt("render " + kConfigs +
                      "/cornell-box.json --backend cpu --spp 2 --width 32 --height 32 " +
                      "--seed 9 --out " + (dir / "b.exr").string(),
                  dir)
                .status,
            0);
  const Result d = runPt("diff " + (dir / "a.exr").string() + " " + (dir / "b.exr").string() +
                             " --heatmap " + (dir / "heat.png").string(),
                         dir);
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
  std::ofstream(dir / "broken.json") << "{ \"materials\": [ }";
  std::ofstream(dir / "typo.json") << R"({"materials": [{"name": "m"}],
    "shapes": [{"type": "quad", "material": "m", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]}],
    "camera": {"widht": 10}})";
  const std::string out = " --out " + (dir / "out.png").string();
  const std::string box = kConfigs + "/cornell-box.json";
  const std::vector<BadCase> cases = {
      {"missing scene", "render " + (dir / "nope.json").string() + out, "nope.json"},
      {"malformed json", "render " + (dir / "broken.json").string() + out, "broken.json"},
      {"misspelled key", "render " + (dir / "typo.json").string() + out, "camera.widht"},
      {"zero spp", "render " + box + " --spp 0" + out, "--spp"},
      {"negative width", "render " + box + " --width -4" + out, "--width"},
      {"unknown backend", "render " + box + " --backend nope" + out, "--backend"},
      {"samples per pass on the cpu", "render " + box + " --backend cpu --samples-per-pass 4" + out,
       "--samples-per-pass"},
      {"zero samples per pass", "render " + box + " --samples-per-pass 0" + out,
       "--samples-per-pass"},
      {"unknown extension",
       "render " + box + " --spp 1 --width 8 --height 8 --out " + (dir / "out.bmp").string(),
       "out.bmp"},
      {"missing image", "diff " + (dir / "x.exr").string() + " " + (dir / "y.exr").string(),
       "x.exr"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    const Result r = runPt(c.args, dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.expectInError), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out.bmp"));
  }
  // Nothing but the inputs and the captured streams is left in the directory (no temp files).
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "broken.json" || name == "typo.json" || name == "stdout.txt" ||
                name == "stderr.txt")
        << name;
  }
}

TEST(CliVulkan, RendersOnTheDefaultBackendWithValidation) {
  test::TempDir dir;
  const Result r =
      runPt("render " + kConfigs + "/cornell-mirror.json --spp 2 --width 16 --height 16 " +
                "--validation --out " + (dir / "v.exr").string(),
            dir);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* key : {"backend=vulkan", "device=", "effects=diffuse+mirror+nee+mis+rr",
                          "invalid_samples=0", "Mrays/s="}) {
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " in " << r.out;
  }
  EXPECT_EQ(r.err.find("validation"), std::string::npos) << r.err;
  const Result d = runPt("devices", dir);
  EXPECT_EQ(d.status, 0);
  EXPECT_GE(lineCount(d.out), 1);
}

TEST(CliVulkan, NoDriverGivesItsOwnExitStatus) {
  test::TempDir dir;
  // Point the loader at a driver manifest that does not exist: no Vulkan driver at all.
  const std::string env = "VK_ICD_FILENAMES=" + (dir / "none.json").string() +
                          " VK_DRIVER_FILES=" + (dir / "none.json").string() + " ";
  const auto out = dir / "o.txt", err = dir / "e.txt";
  const std::string cmd = env + kPt + " render " + kConfigs + "/cornell-box.json --spp 1 --out " +
                          (dir / "x.png").string() + " >" + out.string() + " 2>" + err.string();
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 3);
  std::ifstream f(err);
  const std::string text(std::istreambuf_iterator<char>(f), {});
  EXPECT_EQ(lineCount(text), 1) << text;
  EXPECT_NE(text.find("Vulkan"), std::string::npos) << text;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
}

}  // namespace
}  // namespace pt
