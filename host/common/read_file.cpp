// Whole-file reads (see read_file.h): one fopen/fread loop for either kind of byte buffer.
#include "common/read_file.h"

#include <cerrno>
#include <cstdio>

namespace pt {
namespace {

template <class Buffer>
FileReadResult readInto(const std::filesystem::path& path, Buffer& out) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return {FileReadResult::kOpenFailed, errno};
  out.clear();
  char chunk[1 << 16];
  std::size_t n;
  while ((n = std::fread(chunk, 1, sizeof chunk, file)) > 0) {
    out.insert(out.end(), chunk, chunk + n);
  }
  FileReadResult result;
  if (std::ferror(file)) result = {FileReadResult::kReadFailed, errno};
  std::fclose(file);
  return result;
}

}  // namespace

FileReadResult readFile(const std::filesystem::path& path, std::string& out) {
  return readInto(path, out);
}

FileReadResult readFile(const std::filesystem::path& path, std::vector<unsigned char>& out) {
  return readInto(path, out);
}

}  // namespace pt
