// The MIP map of an image texture, as pbrt-v4 builds it (Image::GeneratePyramid): an image
// whose sides are not powers of two is first resampled up to the next ones (a Lanczos
// windowed sinc of radius 2, separable, negative results clamped to zero, texels beyond the
// edges as the wrap mode says); then each level is the previous one's 2 x 2 averages, down to
// 1 x 1. Texture lookups choose levels by the ray's footprint (shaders/texture.h).
#pragma once

#include <vector>

#include "common/shared.h"

namespace pt {

// An image of linear float channels (1, 3 or 4 per texel), rows from the top.
struct FloatImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> values;  // width * height * channels

  // Empties values and reserves room for width * height * channels (advised for huge pages),
  // for the producer to push them in order.
  void reserveValues();

  float at(int x, int y, int c) const {
    return values[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels) +
                  std::size_t(c)];
  }
};

// Whether n is a power of two (n > 0), and the smallest power of two at least n.
bool isPowerOfTwo(int n);
int roundUpPowerOfTwo(int n);

// The image resampled up to newWidth x newHeight (each at least the image's) by pbrt-v4's
// Image::FloatResizeUp, texels beyond the edges read by `wrap` (kWrap*).
FloatImage resizeUp(const FloatImage& image, int newWidth, int newHeight, uint wrap);

// The levels of the image's MIP map: level 0 the image (resized up to powers of two where its
// sides are not), 1 + log2 of the larger side levels in all.
std::vector<FloatImage> mipPyramid(FloatImage image, uint wrap);

}  // namespace pt
