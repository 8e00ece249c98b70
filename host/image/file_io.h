// Whole files in and out, for the image formats and the film state: one-line InputErrors
// naming the file, and writes that never leave a half-written file behind.
#pragma once

#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

namespace pt {

using Bytes = std::vector<unsigned char>;

// The whole file. InputError "<path>: not found" (and the like) on failure; `kind` names
// what the file should have been, e.g. "an image file", for a directory given instead.
Bytes readWholeFile(const std::filesystem::path& path, std::string_view kind);

// Writes to "<name>.tmp-<pid>-<n>" beside the target, flushes it to disk and renames it over
// the target. rename() within one directory is atomic, so readers (and a crash) see either
// the old file or the complete new one, never a partial one. InputError on failure, with the
// temporary file removed.
void writeFileAtomically(const std::filesystem::path& path, std::span<const unsigned char> bytes);

// Removes the temporary files of writes under way. Only calls unlink(), so a signal handler
// that ends the process at once may call it: nothing is left behind even then.
void removeUnfinishedWrites() noexcept;

}  // namespace pt
