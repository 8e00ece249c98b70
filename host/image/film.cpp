// Film: the per-pixel exact radiance accumulator renderers add samples to.

#include "image/image.h"

#include <algorithm>
#include <string>

#include "common/memory.h"

namespace pt {

size_t Film::bytesPerPixel() {
  // The resolved Image is counted too: it is allocated while the film is alive.
  return sizeof(decltype(sampleCount)::value_type) + sizeof(decltype(invalidCount)::value_type) +
         sizeof(decltype(exact)::value_type) + sizeof(decltype(Image::pixels)::value_type);
}

void Film::checkFitsInMemory(int w, int h, const std::string& what) {
  // Refused with the numbers before allocating, not killed by the OOM killer halfway.
  const size_t kBytesPerPixel = bytesPerPixel();
  const uint64_t n = uint64_t(std::max(w, 0)) * uint64_t(std::max(h, 0));
  pt::checkFitsInMemory(n * kBytesPerPixel,
                        what + "a " + std::to_string(w) + "x" + std::to_string(h) + " film",
                        std::to_string(kBytesPerPixel) + " bytes per pixel");
}

Film::Film(int w, int h) : width(w), height(h) {
  PT_CHECK(w >= 0 && h >= 0, "film size must not be negative");
  const size_t n = size_t(w) * size_t(h);
  checkFitsInMemory(w, h);
  sampleCount.assign(n, 0);
  invalidCount.assign(n, 0);
  exact.assign(n, {});
}

void Film::merge(const Film& other) {
  PT_CHECK(width == other.width && height == other.height, "merging films of different sizes");
  for (size_t i = 0; i < pixelCount(); ++i) {
    for (int c = 0; c < 3; ++c) exact[i][c].add(other.exact[i][c]);
    sampleCount[i] += other.sampleCount[i];
    invalidCount[i] += other.invalidCount[i];
  }
}

uint64_t Film::totalInvalid() const {
  uint64_t total = 0;
  for (uint64_t n : invalidCount) total += n;
  return total;
}

Image Film::resolve() const {
  Image image(width, height);
  for (size_t i = 0; i < pixelCount(); ++i) {
    // Divide in double and round once to float.
    if (sampleCount[i] > 0) image.pixels[i] = glm::vec3(sum(i) / double(sampleCount[i]));
  }
  return image;
}

}  // namespace pt
