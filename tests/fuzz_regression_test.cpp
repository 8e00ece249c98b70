// Replays every input the fuzzers found a bug with (tests/data/fuzz-regressions/<target>/)
// and the seed corpora (fuzz/corpus/<target>/) through the fuzz entry points, without a
// fuzzing engine: each must be accepted or refused with an InputError, never crash.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include "common/check.h"
#include "fuzz/fuzz_entry.h"
#include "image/image.h"
#include "image/texture_image.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = PT_SOURCE_DIR;

// Replays the files under `root`/<target>/, returns how many there were.
int replay(const fs::path& root) {
  int count = 0;
  for (const fuzz::Target& target : fuzz::targets()) {
    const fs::path dir = root / target.name;
    if (!fs::is_directory(dir)) continue;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
      if (!entry.is_regular_file()) continue;
      std::ifstream in(entry.path(), std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
      SCOPED_TRACE(entry.path().string());
      EXPECT_NO_THROW(
          target.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
      ++count;
    }
  }
  return count;
}

TEST(FuzzRegressions, EveryFoundInputIsAcceptedOrRefusedCleanly) {
  const fs::path root = kSource / "tests" / "data" / "fuzz-regressions";
  ASSERT_TRUE(fs::is_directory(root));
  replay(root);
}

// The image fuzzer's out-of-memory: a 102-byte PNG whose IDAT chunk claims 2 GiB made
// stb_image reserve that much before reading. The chunk walk refuses it first.
TEST(FuzzRegressions, PngChunkLongerThanTheFileIsRefusedBeforeDecoding) {
  const fs::path png = kSource / "tests/data/fuzz-regressions/image/idat-length-2gib.png";
  try {
    readImage(png);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("idat-length-2gib.png: PNG chunk '"), std::string::npos) << m;
    EXPECT_NE(m.find("bytes, but the file ends at byte 102"), std::string::npos) << m;
  }
}

// The texture fuzzer's first findings: JPEG Huffman tables of more than 256 codes made
// stb_image write past its 257-byte code-size array, in stbi_info as well as when decoding.
// The table check refuses them first. (The inputs' first byte picks the format.)
TEST(FuzzRegressions, JpegHuffmanTableOfMoreThan256CodesIsRefused) {
  for (const char* name :
       {"jpeg-huffman-table-of-257-codes", "jpeg-huffman-table-before-the-frame"}) {
    SCOPED_TRACE(name);
    std::ifstream in(kSource / "tests/data/fuzz-regressions/texture" / name, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 1u);
    const fs::path jpeg = fs::temp_directory_path() /
                          ("pt-" + std::string(name) + "-" + std::to_string(::getpid()) + ".jpg");
    std::ofstream(jpeg, std::ios::binary) << bytes.substr(1);
    try {
      readTextureImage(jpeg);
      ADD_FAILURE() << "expected an InputError";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(jpeg.string() + ": bad JPEG Huffman table: ", 0), 0u) << m;
    }
    fs::remove(jpeg);
  }
}

TEST(FuzzRegressions, SeedCorporaAreAcceptedOrRefusedCleanly) {
  EXPECT_GT(replay(kSource / "fuzz" / "corpus"), 0);
}

}  // namespace
}  // namespace pt
