// Available memory from /proc and the rlimits, and the one-line refusal of what cannot fit.
#include "common/memory.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include <sys/resource.h>
#include <unistd.h>

#include "common/check.h"

namespace pt {
namespace {

// The value of a "Key:   123 kB" line of a /proc file, in bytes; 0 when absent.
std::uint64_t procKibField(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) == 0 && line.size() > key.size() &&
        line[key.size()] == ':') {
      std::istringstream fields(line.substr(key.size() + 1));
      std::uint64_t kib = 0;
      if (fields >> kib) return kib * 1024;
    }
  }
  return 0;
}

std::string gib(std::uint64_t bytes) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.1f GiB", double(bytes) / double(1ull << 30));
  return text;
}

}  // namespace

std::uint64_t availableMemoryBytes() {
  std::uint64_t available = procKibField("/proc/meminfo", "MemAvailable");
  if (available == 0) {
    const long pages = ::sysconf(_SC_AVPHYS_PAGES), pageSize = ::sysconf(_SC_PAGESIZE);
    available = pages > 0 && pageSize > 0 ? std::uint64_t(pages) * std::uint64_t(pageSize)
                                          : std::numeric_limits<std::uint64_t>::max();
  }
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    const std::uint64_t used = procKibField("/proc/self/status", "VmSize");
    const std::uint64_t cap = std::uint64_t(limit.rlim_cur);
    available = std::min(available, cap > used ? cap - used : 0);
  }
  return available;
}

void checkFitsInMemory(std::uint64_t bytes, const std::string& what, const std::string& detail,
                       std::uint64_t available) {
  if (bytes <= available) return;
  throw InputError(what + " needs " + gib(bytes) + " (" + detail + "), but only " + gib(available) +
                   " of memory is available");
}

void checkFitsInMemory(std::uint64_t bytes, const std::string& what, const std::string& detail) {
  checkFitsInMemory(bytes, what, detail, availableMemoryBytes());
}

}  // namespace pt
