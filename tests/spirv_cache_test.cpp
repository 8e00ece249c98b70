// The disk cache of compiled shaders (vulkan/spirv_cache.h): an entry comes back only for its
// own key and only whole; what cannot be read or written is a miss, never an error; the least
// recently used entries go first. The last test runs `pt` on lavapipe with a damaged cache.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "image/film_state.h"
#include "test_util.h"
#include "vulkan/spirv_cache.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

// A module's first word is SPIR-V's magic number; the rest only has to come back unchanged.
std::vector<uint32_t> fakeSpirv(uint32_t seed, size_t words) {
  std::vector<uint32_t> spirv = {0x07230203};
  for (size_t i = 1; i < words; ++i) spirv.push_back(seed * 2654435761u + uint32_t(i));
  return spirv;
}

fs::path entryFile(const fs::path& dir, const std::string& key) {
  return dir / (hexHash(hashBytes(key.data(), key.size())) + ".spv");
}

TEST(SpirvCache, AnEntryComesBackForItsKeyOnly) {
  const test::TempDir tmp;
  const fs::path dir = tmp / "cache";  // made by the first write
  const std::vector<uint32_t> a = fakeSpirv(1, 1000), b = fakeSpirv(2, 10);
  EXPECT_FALSE(readCachedSpirv(dir, "key a"));
  writeCachedSpirv(dir, "key a", a);
  writeCachedSpirv(dir, "key b", b);
  EXPECT_EQ(readCachedSpirv(dir, "key a"), a);
  EXPECT_EQ(readCachedSpirv(dir, "key b"), b);
  EXPECT_FALSE(readCachedSpirv(dir, "key c"));
  // Rewriting replaces the entry.
  writeCachedSpirv(dir, "key a", b);
  EXPECT_EQ(readCachedSpirv(dir, "key a"), b);
  // An entry under another key's file name (as a hash collision would put it) is not taken:
  // the file holds its whole key.
  fs::copy_file(entryFile(dir, "key a"), entryFile(dir, "key d"));
  EXPECT_FALSE(readCachedSpirv(dir, "key d"));
}

TEST(SpirvCache, DamagedEntriesAreMisses) {
  const test::TempDir tmp;
  const std::string key = "pathtrace.comp\n#define PT_X 1\n";
  const std::vector<uint32_t> spirv = fakeSpirv(3, 64);
  writeCachedSpirv(tmp.path(), key, spirv);
  const fs::path file = entryFile(tmp.path(), key);
  const std::string whole = test::readFile(file);
  ASSERT_FALSE(whole.empty());
  ASSERT_EQ(readCachedSpirv(tmp.path(), key), spirv);
  // Every single flipped byte (header, key, words) and every truncation is a miss.
  for (size_t i = 0; i < whole.size(); ++i) {
    std::string flipped = whole;
    flipped[i] = char(flipped[i] ^ 0x10);
    test::writeBytes(file, flipped);
    EXPECT_FALSE(readCachedSpirv(tmp.path(), key)) << "byte " << i;
  }
  for (size_t size : {size_t(0), size_t(7), size_t(24), whole.size() - 4, whole.size() - 1}) {
    test::writeBytes(file, whole.substr(0, size));
    EXPECT_FALSE(readCachedSpirv(tmp.path(), key)) << size << " bytes";
  }
  test::writeBytes(file, whole + "tail");
  EXPECT_FALSE(readCachedSpirv(tmp.path(), key));
  // Written again, it is whole again.
  writeCachedSpirv(tmp.path(), key, spirv);
  EXPECT_EQ(readCachedSpirv(tmp.path(), key), spirv);
}

TEST(SpirvCache, AnUnusableDirectoryIsAMissNotAnError) {
  const test::TempDir tmp;
  const fs::path notADirectory = tmp.write("file", "x");
  EXPECT_NO_THROW(writeCachedSpirv(notADirectory, "k", fakeSpirv(4, 8)));
  EXPECT_FALSE(readCachedSpirv(notADirectory, "k"));
  EXPECT_NO_THROW(writeCachedSpirv(notADirectory / "below", "k", fakeSpirv(4, 8)));
  EXPECT_FALSE(readCachedSpirv(notADirectory / "below", "k"));
  EXPECT_NO_THROW(cleanUpSpirvCache(notADirectory, 0));
  EXPECT_NO_THROW(cleanUpSpirvCache(tmp / "missing", 0));
  EXPECT_EQ(test::readFile(notADirectory), "x");
}

TEST(SpirvCache, TheLeastRecentlyUsedEntriesGoFirst) {
  const test::TempDir tmp;
  const auto now = fs::file_time_type::clock::now();
  for (int i = 0; i < 5; ++i) {
    const std::string key = "key " + std::to_string(i);
    writeCachedSpirv(tmp.path(), key, fakeSpirv(i, 8));
    // Written an hour apart, key 0 first.
    fs::last_write_time(entryFile(tmp.path(), key), now - std::chrono::hours(5 - i));
  }
  tmp.write("other-file", "kept");                    // not an entry
  ASSERT_TRUE(readCachedSpirv(tmp.path(), "key 0"));  // used now: the most recent
  cleanUpSpirvCache(tmp.path(), 3);
  std::vector<std::string> expected = {entryFile(tmp.path(), "key 0").filename().string(),
                                       entryFile(tmp.path(), "key 3").filename().string(),
                                       entryFile(tmp.path(), "key 4").filename().string(),
                                       "other-file"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(tmp.listing(), expected);
  cleanUpSpirvCache(tmp.path(), 3);  // at the limit: nothing more goes
  EXPECT_EQ(tmp.listing(), expected);
}

// Sets an environment variable (or unsets it: nullopt) for the scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, std::optional<std::string> value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      ::setenv(name, value->c_str(), 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(SpirvCache, TheDirectoryComesFromTheEnvironment) {
  {
    const ScopedEnv dir("PT_SHADER_CACHE_DIR", "/some/where");
    EXPECT_EQ(spirvCacheDirectory(), fs::path("/some/where"));
  }
  {
    const ScopedEnv dir("PT_SHADER_CACHE_DIR", "");
    EXPECT_EQ(spirvCacheDirectory(), std::nullopt);
  }
  const ScopedEnv dir("PT_SHADER_CACHE_DIR", std::nullopt);
  {
    const ScopedEnv xdg("XDG_CACHE_HOME", "/xdg");
    EXPECT_EQ(spirvCacheDirectory(), fs::path("/xdg/pt"));
  }
  const ScopedEnv xdg("XDG_CACHE_HOME", "relative");  // not absolute: ignored, as XDG says
  {
    const ScopedEnv home("HOME", "/home/u");
    EXPECT_EQ(spirvCacheDirectory(), fs::path("/home/u/.cache/pt"));
  }
  const ScopedEnv home("HOME", std::nullopt);
  EXPECT_EQ(spirvCacheDirectory(), std::nullopt);
}

// `pt` on lavapipe: the first render fills the cache; a render with every entry damaged
// compiles again, gives the same image and repairs the entries; no cache gives it too.
TEST(SpirvCacheOnVulkan, ADamagedCacheIsCompiledAgainToTheSameImage) {
  const test::TempDir tmp;
  const fs::path cache = tmp / "cache";
  const std::string render = "render " + (test::kConfigs / "cornell-box.json").string() +
                             " --backend vulkan --width 16 --height 12 --spp 2 --out ";
  const std::string env = "PT_SHADER_CACHE_DIR=" + cache.string();
  const test::PtResult first = test::runPt(render + (tmp / "a.pfm").string(), env);
  ASSERT_EQ(first.status, 0) << first.err;
  std::vector<fs::path> entries;
  for (const auto& e : fs::directory_iterator(cache)) entries.push_back(e.path());
  ASSERT_FALSE(entries.empty());
  std::vector<std::string> whole;
  for (const fs::path& e : entries) {
    whole.push_back(test::readFile(e));
    std::string damaged = whole.back();
    damaged[damaged.size() / 2] = char(damaged[damaged.size() / 2] ^ 1);
    test::writeBytes(e, damaged);
  }
  const test::PtResult second = test::runPt(render + (tmp / "b.pfm").string(), env);
  ASSERT_EQ(second.status, 0) << second.err;
  EXPECT_EQ(test::readFile(tmp / "a.pfm"), test::readFile(tmp / "b.pfm"));
  for (size_t i = 0; i < entries.size(); ++i) EXPECT_EQ(test::readFile(entries[i]), whole[i]);
  const test::PtResult uncached =
      test::runPt(render + (tmp / "c.pfm").string(), "PT_SHADER_CACHE_DIR=");
  ASSERT_EQ(uncached.status, 0) << uncached.err;
  EXPECT_EQ(test::readFile(tmp / "a.pfm"), test::readFile(tmp / "c.pfm"));
}

}  // namespace
}  // namespace pt
