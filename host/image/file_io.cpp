// Whole-file reads and atomic writes (see file_io.h), with a record of the temporary files
// of writes under way so that a process ended at once by a signal can remove them.
#include "image/file_io.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include <unistd.h>

#include "common/check.h"
#include "common/read_file.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

// Throws the one-line InputError every file failure uses: "<path>: <what>".
[[noreturn]] void fail(const fs::path& path, const std::string& what) {
  throw InputError(path.string() + ": " + what);
}

// Temporary files being written, for removeUnfinishedWrites(). A slot is claimed (kFilling)
// while its path is copied in and only then published (kReady), so a signal handler never
// reads a half-copied path. Writes beyond the slots still work; they are just not cleaned up.
enum SlotState : int { kFree, kFilling, kReady };
struct UnfinishedWrite {
  std::atomic<int> state{kFree};
  char path[PATH_MAX] = {};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the slots");
UnfinishedWrite gUnfinished[8];

// Records `tmp` as being written; returns its slot, or -1 when none is free.
int recordUnfinished(const fs::path& tmp) {
  const std::string& text = tmp.native();
  if (text.size() >= PATH_MAX) return -1;
  for (int i = 0; i < int(std::size(gUnfinished)); ++i) {
    int expected = kFree;
    if (gUnfinished[i].state.compare_exchange_strong(expected, kFilling)) {
      std::memcpy(gUnfinished[i].path, text.c_str(), text.size() + 1);
      gUnfinished[i].state.store(kReady);
      return i;
    }
  }
  return -1;
}

void forgetUnfinished(int slot) {
  if (slot >= 0) gUnfinished[slot].state.store(kFree);
}

}  // namespace

Bytes readWholeFile(const fs::path& path, std::string_view kind) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) fail(path, "not found");
  if (ec) fail(path, "cannot access: " + ec.message());
  if (fs::is_directory(status)) fail(path, "is a directory, not " + std::string(kind));
  Bytes bytes;
  const FileReadResult read = readFile(path, bytes);
  if (read.step == FileReadResult::kOpenFailed) {
    fail(path, std::string("cannot open: ") + std::strerror(read.error));
  }
  if (read.step == FileReadResult::kReadFailed) {
    fail(path, std::string("cannot read: ") + std::strerror(read.error));
  }
  return bytes;
}

// The counter keeps two threads of one process writing the same target from sharing a
// temporary file.
void writeFileAtomically(const fs::path& path, std::span<const unsigned char> bytes) {
  static std::atomic<unsigned> counter{0};
  fs::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);

  // Recorded before the file exists: a handler that runs before fopen() unlinks nothing.
  const int slot = recordUnfinished(tmp);
  // "wx" never opens something that already exists, so a stray file or directory of that name
  // is left alone and the failure is reported instead.
  std::FILE* file = std::fopen(tmp.c_str(), "wx");
  if (!file) {
    const int error = errno;
    forgetUnfinished(slot);
    fail(path, std::string("cannot write: ") + std::strerror(error));
  }
  int error = 0;
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size()) {
    error = errno;
  }
  if (std::fflush(file) != 0 && !error) error = errno;
  if (::fsync(::fileno(file)) != 0 && !error) error = errno;
  if (std::fclose(file) != 0 && !error) error = errno;
  std::error_code ec;
  if (error) {
    fs::remove(tmp, ec);
    forgetUnfinished(slot);
    fail(path, std::string("cannot write: ") + std::strerror(error));
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    forgetUnfinished(slot);
    fail(path, "cannot move the finished file into place: " + ec.message());
  }
  forgetUnfinished(slot);
}

void removeUnfinishedWrites() noexcept {
  for (UnfinishedWrite& w : gUnfinished) {
    if (w.state.load() == kReady) ::unlink(w.path);
  }
}

}  // namespace pt
