// libFuzzer target for the texture reader (fuzz/fuzz_entry.cpp): the first byte picks the
// format (PNG, JPEG, TGA, BMP, HDR, EXR, PFM), the rest is the file. InputError is the one
// allowed failure, anything else (a crash, another exception, a leak, a hang) is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pt::fuzz::fuzzTexture(data, size);
  return 0;
}
