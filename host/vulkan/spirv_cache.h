// Compiled shaders kept on disk between processes: each `pt render` on a Vulkan device, and
// each test, would otherwise run glslang and SPIRV-Tools again on a variant an earlier process
// compiled (0.3-1.2 s each on 2 cores, up to half of a small render on lavapipe). Lavapipe keeps
// its own cache of what it makes of the SPIR-V (Mesa's shader cache); this one is the step before.
//
// One file per variant, named by a hash of its key; the file holds the whole key, so two keys
// of the same hash never mix, and a checksum, so that a damaged or truncated file is a miss
// (then compiled again and rewritten), never a shader. Written atomically, so processes
// compiling the same variant at once leave one whole file. The cache is an optimization: a
// directory that cannot be made or written is a miss every time, not an error.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace pt {

// The directory: $PT_SHADER_CACHE_DIR when set (empty: no cache), else $XDG_CACHE_HOME/pt or
// $HOME/.cache/pt; nullopt where none applies.
std::optional<std::filesystem::path> spirvCacheDirectory();

// The SPIR-V stored under `key` in `dir`, or nullopt: none, or a file that is not a whole
// entry for exactly this key. A hit marks the file as used now, for cleanUpSpirvCache().
std::optional<std::vector<uint32_t>> readCachedSpirv(const std::filesystem::path& dir,
                                                     const std::string& key);

// Stores `spirv` under `key` (the directory made when missing); failures are ignored.
void writeCachedSpirv(const std::filesystem::path& dir, const std::string& key,
                      const std::vector<uint32_t>& spirv);

// Removes the least recently used entries while more than `maxEntries` are stored.
void cleanUpSpirvCache(const std::filesystem::path& dir, size_t maxEntries);

}  // namespace pt
