// Reading a whole file into memory, the one low-level read under the scene readers and the
// image formats: it says at which step it failed and errno there, and leaves the wording of
// the message, and which files to refuse before reading, to the caller.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace pt {

// How a readFile() went: kDone, or the step that failed with errno at that moment.
struct FileReadResult {
  enum Step { kDone, kOpenFailed, kReadFailed };
  Step step = kDone;
  int error = 0;  // errno of the failed step; 0 when kDone
};

// Replaces `out` with the file's bytes, read until end of file (so a FIFO is read until its
// writer closes it, and a device such as /dev/zero never ends: refuse those beforehand).
// `out` is left as it was when the file cannot be opened and holds what was read when a read
// fails.
FileReadResult readFile(const std::filesystem::path& path, std::string& out);
FileReadResult readFile(const std::filesystem::path& path, std::vector<unsigned char>& out);

}  // namespace pt
