// Error tiers (docs/errors.md): a failed internal check exits with kExitInternal and one
// line; PT_DCHECK is compiled out of Release builds; films that cannot fit in memory are
// refused with the numbers before anything is allocated.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>

#include "common/check.h"
#include "common/memory.h"
#include "image/image.h"
#include "sanitizer_build.h"
#include "test_util.h"

namespace pt {
namespace {

struct ShellRun {
  int status = -1;  // -1 when killed by a signal
  std::string err;
};

ShellRun runShell(const std::string& command) {
  const test::TempDir dir;
  const std::string errFile = (dir / "stderr.txt").string();
  const int raw = std::system(("(" + command + ") 2>" + errFile).c_str());
  ShellRun run;
  run.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(errFile);
  run.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return run;
}

TEST(ErrorTiers, FailedCheckExitsWithTheInternalStatusAndOneLine) {
  const ShellRun r = runShell(std::string(PT_CHECK_FAIL_BINARY) + " >/dev/null");
  EXPECT_EQ(r.status, kExitInternal) << r.err;
  EXPECT_NE(r.err.find("internal error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("check failed: argc < 0: failed on purpose"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(ErrorTiers, DebugCheckIsCompiledOutUnderNdebug) {
  const ShellRun r = runShell(std::string(PT_CHECK_FAIL_BINARY) + " dcheck >/dev/null");
#ifdef NDEBUG
  EXPECT_EQ(r.status, 0) << r.err;
  int evaluated = 0;
  PT_DCHECK(++evaluated < 0, "never evaluated");
  EXPECT_EQ(evaluated, 0);
#else
  EXPECT_EQ(r.status, kExitInternal) << r.err;
  EXPECT_NE(r.err.find("debug-only check"), std::string::npos) << r.err;
#endif
}

TEST(MemoryLimit, RefusalGivesTheNumbers) {
  const std::uint64_t gib = std::uint64_t(1) << 30;
  EXPECT_NO_THROW(checkFitsInMemory(gib, "a thing", "detail", 2 * gib));
  try {
    checkFitsInMemory(40 * gib, "a 16384x16384 film", "160 bytes per pixel", 3 * gib / 2);
    FAIL() << "not refused";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "a 16384x16384 film needs 40.0 GiB (160 bytes per pixel), but only 1.5 GiB of "
                 "memory is available");
  }
}

TEST(MemoryLimit, AvailableMemoryIsPlausible) {
  const std::uint64_t available = availableMemoryBytes();
  EXPECT_GT(available, std::uint64_t(1) << 20);  // this test itself runs in it
}

// The sanitizers reserve terabytes of address space, so `ulimit -v` cannot apply to them.

TEST(MemoryLimit, HugeFilmIsRefusedBeforeAllocating) {
#if PT_TEST_SANITIZED
  GTEST_SKIP() << "ulimit -v does not work under AddressSanitizer";
#else
  // 16384 x 16384 pixels at well over 40 bytes each: tens of GiB, refused under a 2 GiB
  // address-space limit (the check reads RLIMIT_AS) with exit status 2 and the numbers.
  const test::TempDir dir;
  const std::string out = (dir / "huge.exr").string();
  const ShellRun r =
      runShell("ulimit -v 2097152 && " + std::string(PT_BINARY) + " render " +
               (test::kConfigs / "cornell-box.json").string() +
               " --backend cpu --spp 1 --width 16384 --height 16384 --out " + out + " >/dev/null");
  EXPECT_EQ(r.status, kExitInputError) << r.err;
  // The line names the scene and that the size came from the options.
  EXPECT_NE(r.err.find("cornell-box.json: with --width/--height, a 16384x16384 film needs "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("bytes per pixel), but only "), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
#endif
}

TEST(MemoryLimit, HugeFilmFromTheSceneNamesTheScene) {
#if PT_TEST_SANITIZED
  GTEST_SKIP() << "ulimit -v does not work under AddressSanitizer";
#else
  // The size written in the scene file (16384 is the most it accepts): refused before the BVH
  // build under a 2 GiB address-space limit, naming the file.
  const test::TempDir dir;
  std::ifstream in(test::kConfigs / "cornell-box.json");
  std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const std::string key : {"\"width\": 256", "\"height\": 256"}) {
    const size_t at = json.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    json.replace(at, key.size(), key.substr(0, key.size() - 3) + "16384");
  }
  const std::string scene = dir.write("huge.json", json).string();
  const std::string out = (dir / "huge.exr").string();
  const ShellRun r = runShell("ulimit -v 2097152 && " + std::string(PT_BINARY) + " render " +
                              scene + " --backend cpu --spp 1 --out " + out + " >/dev/null");
  EXPECT_EQ(r.status, kExitInputError) << r.err;
  EXPECT_NE(r.err.find("huge.json: a 16384x16384 film needs "), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
#endif
}

TEST(MemoryLimit, SppmStateIsCountedWithTheFilm) {
#if PT_TEST_SANITIZED
  GTEST_SKIP() << "ulimit -v does not work under AddressSanitizer";
#else
  // A 2048x2048 film alone fits under a 2 GiB address-space limit (about 0.6 GiB); with the
  // state sppm keeps per pixel (about 2.5 GiB in all) it does not: refused with status 2 and
  // one line naming the scene, before the BVH build and before either is allocated.
  const test::TempDir dir;
  const std::string out = (dir / "sppm.exr").string();
  const std::string command = std::string(PT_BINARY) + " render " +
                              (test::kConfigs / "cornell-box.json").string() +
                              " --backend cpu --spp 1 --width 2048 --height 2048 --out " + out;
  const ShellRun r = runShell("ulimit -v 2097152 && " + command + " --integrator sppm >/dev/null");
  EXPECT_EQ(r.status, kExitInputError) << r.err;
  EXPECT_NE(
      r.err.find("cornell-box.json: with --width/--height, sppm with a 2048x2048 film needs "),
      std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("bytes per pixel: the film and sppm's state), but only "), std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The path tracer's film of the same size passes the same limit's check.
  const ShellRun path = runShell("ulimit -v 2097152 && " + command + " --max-depth 1 >/dev/null");
  EXPECT_EQ(path.err.find("memory is available"), std::string::npos) << path.err;
#endif
}

TEST(MemoryLimit, FilmConstructorRefusesWhatCannotFit) {
  // In process: 2^20 x 2^14 pixels at over 40 bytes each is over 640 GiB, more than any test
  // machine has; refused before anything is allocated.
  EXPECT_THROW(Film(1 << 20, 1 << 14), InputError);
}

}  // namespace
}  // namespace pt
