// The file: "PTSPIRV1", the key's length and the SPIR-V's word count (uint32 each), a hash of
// the key and the words (uint64), then the key's bytes and the words, little-endian as the
// machine that wrote it (a cache is not carried between machines).
#include "vulkan/spirv_cache.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <span>
#include <system_error>

#include "common/check.h"
#include "common/read_file.h"
#include "image/file_io.h"
#include "image/film_state.h"  // hashBytes, hexHash

namespace pt {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'P', 'T', 'S', 'P', 'I', 'R', 'V', '1'};
constexpr size_t kHeaderSize = sizeof(kMagic) + 4 + 4 + 8;
constexpr uint32_t kSpirvMagic = 0x07230203;

fs::path entryPath(const fs::path& dir, const std::string& key) {
  return dir / (hexHash(hashBytes(key.data(), key.size())) + ".spv");
}

uint64_t entryChecksum(const std::string& key, std::span<const uint32_t> words) {
  return hashBytes(words.data(), words.size_bytes(), hashBytes(key.data(), key.size()));
}

template <typename T>
void append(Bytes& out, const T& value) {
  const auto* p = reinterpret_cast<const unsigned char*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

template <typename T>
T load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

}  // namespace

std::optional<fs::path> spirvCacheDirectory() {
  if (const char* dir = std::getenv("PT_SHADER_CACHE_DIR")) {
    if (*dir == '\0') return std::nullopt;
    return fs::path(dir);
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg == '/') {
    return fs::path(xdg) / "pt";
  }
  if (const char* home = std::getenv("HOME"); home && *home == '/') {
    return fs::path(home) / ".cache" / "pt";
  }
  return std::nullopt;
}

std::optional<std::vector<uint32_t>> readCachedSpirv(const fs::path& dir, const std::string& key) {
  const fs::path path = entryPath(dir, key);
  Bytes bytes;
  if (readFile(path, bytes).step != FileReadResult::kDone) return std::nullopt;
  if (bytes.size() < kHeaderSize || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return std::nullopt;
  }
  const auto keySize = load<uint32_t>(bytes.data() + 8);
  const auto wordCount = load<uint32_t>(bytes.data() + 12);
  const auto checksum = load<uint64_t>(bytes.data() + 16);
  if (keySize != key.size() || wordCount == 0 ||
      bytes.size() != kHeaderSize + size_t(keySize) + size_t(wordCount) * 4) {
    return std::nullopt;
  }
  const unsigned char* keyBytes = bytes.data() + kHeaderSize;
  if (std::memcmp(keyBytes, key.data(), keySize) != 0) return std::nullopt;
  std::vector<uint32_t> words(wordCount);
  std::memcpy(words.data(), keyBytes + keySize, size_t(wordCount) * 4);
  if (words[0] != kSpirvMagic || entryChecksum(key, words) != checksum) return std::nullopt;
  std::error_code ignored;
  fs::last_write_time(path, fs::file_time_type::clock::now(), ignored);
  return words;
}

void writeCachedSpirv(const fs::path& dir, const std::string& key,
                      const std::vector<uint32_t>& spirv) {
  PT_CHECK(!spirv.empty() && key.size() <= UINT32_MAX && spirv.size() <= UINT32_MAX,
           "writeCachedSpirv: no SPIR-V, or a key or a module too large");
  Bytes bytes;
  bytes.reserve(kHeaderSize + key.size() + spirv.size() * 4);
  bytes.insert(bytes.end(), kMagic, kMagic + sizeof(kMagic));
  append(bytes, uint32_t(key.size()));
  append(bytes, uint32_t(spirv.size()));
  append(bytes, entryChecksum(key, spirv));
  bytes.insert(bytes.end(), key.begin(), key.end());
  const auto* words = reinterpret_cast<const unsigned char*>(spirv.data());
  bytes.insert(bytes.end(), words, words + spirv.size() * 4);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return;
  try {
    writeFileAtomically(entryPath(dir, key), bytes);
  } catch (const InputError&) {
    // A cache that cannot be written only costs the next process a compile.
  }
}

void cleanUpSpirvCache(const fs::path& dir, size_t maxEntries) {
  std::error_code ec;
  std::vector<std::pair<fs::file_time_type, fs::path>> entries;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().extension() != ".spv") continue;
    std::error_code timeError;
    const fs::file_time_type time = it->last_write_time(timeError);
    if (!timeError) entries.emplace_back(time, it->path());
  }
  if (ec || entries.size() <= maxEntries) return;
  std::sort(entries.begin(), entries.end());
  for (size_t i = 0; i + maxEntries < entries.size(); ++i) fs::remove(entries[i].second, ec);
}

}  // namespace pt
