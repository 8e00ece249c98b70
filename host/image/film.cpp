// Film: the per-pixel double-precision radiance accumulator renderers add samples to.

#include "image/image.h"

namespace pt {

Film::Film(int w, int h) : width(w), height(h) {
  PT_CHECK(w >= 0 && h >= 0, "film size must not be negative");
  const size_t n = size_t(w) * size_t(h);
  sum.assign(n, glm::dvec3(0.0));
  sampleCount.assign(n, 0);
  invalidCount.assign(n, 0);
}

void Film::merge(const Film& other) {
  PT_CHECK(width == other.width && height == other.height, "merging films of different sizes");
  for (size_t i = 0; i < sum.size(); ++i) {
    sum[i] += other.sum[i];
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
  for (size_t i = 0; i < sum.size(); ++i) {
    // Divide in double and round once to float.
    if (sampleCount[i] > 0) image.pixels[i] = glm::vec3(sum[i] / double(sampleCount[i]));
  }
  return image;
}

}  // namespace pt
