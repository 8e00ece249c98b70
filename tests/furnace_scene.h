// The furnace that the light tests share: a convex diffuse cube of albedo 0.5 under an
// environment of radiance 1 renders 0.5 wherever it is seen (every ray that leaves it sees the
// environment) and 1 elsewhere.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "image/image.h"

namespace pt::test {

// The cube seen from (3, 4, 5), size x size pixels (box filter), `spp` samples, path depth 5,
// with `light` (pbrt-v4 directives) before it.
inline std::string furnaceScene(int size, int spp, const std::string& light) {
  return "Scale -1 1 1\nLookAt 3 4 5  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" [40]\n"
         "Film \"rgb\" \"integer xresolution\" [" +
         std::to_string(size) + "] \"integer yresolution\" [" + std::to_string(size) +
         "]\nPixelFilter \"box\"\nSampler \"zsobol\" \"integer pixelsamples\" [" +
         std::to_string(spp) + "]\nIntegrator \"path\" \"integer maxdepth\" [5]\nWorldBegin\n" +
         light +
         "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
         "Shape \"trianglemesh\" \"point3 P\" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1"
         "  1 1 1  -1 1 1]\n  \"integer indices\" [0 2 1 0 3 2  4 5 6 4 6 7  0 1 5 0 5 4"
         "  1 2 6 1 6 5  2 3 7 2 7 6  3 0 4 3 4 7]\n";
}

// The pixels that show only the object: no pixel within two of them shows the environment
// (exactly 1: every sample's camera ray missed), so that none is on the silhouette.
inline std::vector<size_t> objectPixels(const Image& image) {
  std::vector<size_t> inside;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      bool clear = true;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          const int u = std::clamp(x + dx, 0, image.width - 1);
          const int v = std::clamp(y + dy, 0, image.height - 1);
          clear &= image.at(u, v) != vec3(1.0f);
        }
      }
      if (clear) inside.push_back(size_t(y) * size_t(image.width) + size_t(x));
    }
  }
  return inside;
}

// The object's pixels are independent estimates of 0.5: their mean within four standard errors,
// the standard error below `maxError` (green channel).
inline void expectFurnaceMean(const Image& image, double maxError) {
  const std::vector<size_t> inside = objectPixels(image);
  ASSERT_GT(inside.size(), 60u);
  double sum = 0.0, sumSquares = 0.0;
  for (size_t i : inside) {
    const double v = image.pixels[i].y;
    sum += v;
    sumSquares += v * v;
  }
  const double n = double(inside.size());
  const double mean = sum / n;
  const double standardError = std::sqrt(std::max(0.0, sumSquares / n - mean * mean) / n);
  EXPECT_LT(standardError, maxError);
  EXPECT_NEAR(mean, 0.5, 4.0 * standardError + 1e-4);
}

}  // namespace pt::test
