// libFuzzer target for the film state reader (fuzz/fuzz_entry.cpp): InputError is the one
// allowed failure, anything else (a crash, another exception, a leak, a hang) is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pt::fuzz::fuzzFilmState(data, size);
  return 0;
}
