// The scene readers' growing arrays (scene/reader_helpers.h's reserveGeometric) and the huge
// pages they are given (common/huge_pages.h).
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/huge_pages.h"
#include "sanitizer_build.h"
#include "scene/reader_helpers.h"

namespace pt {
namespace {

// Appending in steps keeps every element in order, at least doubles the room each time it
// grows (amortized linear time), and leaves room that suffices alone.
TEST(ReserveGeometric, KeepsElementsAndGrowsGeometrically) {
  std::vector<uint32_t> v;
  std::size_t grew = 0;
  for (uint32_t step = 0; step < 200; ++step) {
    const std::size_t before = v.capacity();
    reserveGeometric(v, v.size() + 1000);
    if (v.capacity() != before) {
      ++grew;
      EXPECT_GE(v.capacity(), 2 * before);
    }
    EXPECT_GE(v.capacity(), v.size() + 1000);
    for (uint32_t i = 0; i < 1000; ++i) v.push_back(step * 1000 + i);
  }
  for (uint32_t i = 0; i < v.size(); ++i) ASSERT_EQ(v[i], i);
  EXPECT_LE(grew, 9u);  // 200,000 elements from 1,000: 2^8 < 200 < 2^9
  const std::size_t room = v.capacity();
  reserveGeometric(v, v.size());
  EXPECT_EQ(v.capacity(), room);
}

// A field of /proc/self/smaps for the mapping that holds `address` (e.g. THPeligible: 1 where
// the kernel may back it with transparent huge pages), or -1 where it cannot be read.
long smapsField(const void* address, const std::string& field) {
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= at && at < hi;
      continue;
    }
    if (inside && line.rfind(field + ":", 0) == 0) {
      std::istringstream kib(line.substr(field.size() + 1));
      long value = -1;
      kib >> value;
      return value;
    }
  }
  return -1;
}

// Where the kernel gives transparent huge pages on request only ("madvise", its default), the
// room reserveGeometric makes is eligible for them: the advice was given. (Whether a huge page
// is free to back it when touched is the kernel's affair, so that is not asserted.)
TEST(ReserveGeometric, RoomIsAdvisedHugePages) {
  std::ifstream enabled("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode;
  std::getline(enabled, mode);
  if (mode.find("[madvise]") == std::string::npos) {
    GTEST_SKIP() << "transparent huge pages are not given on request here: " << mode;
  }
  if (test::kSanitizerBuild) GTEST_SKIP() << "the sanitizers' allocator maps memory its own way";
  std::vector<uint32_t> v;
  reserveGeometric(v, std::size_t(16) << 20);  // 64 MiB
  v.resize(v.capacity(), 1u);
  const long eligible = smapsField(v.data() + v.size() / 2, "THPeligible");
  ASSERT_GE(eligible, 0) << "no mapping in /proc/self/smaps holds the array";
  EXPECT_EQ(eligible, 1) << "the array's mapping was not advised huge pages";
}

}  // namespace
}  // namespace pt
