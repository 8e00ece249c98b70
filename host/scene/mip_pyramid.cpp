#include "scene/mip_pyramid.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/check.h"
#include "common/huge_pages.h"

namespace pt {

namespace {

// sin(pi x) / (pi x).
float sinc(float x) {
  if (std::abs(x) < 1e-5f) return 1.0f;
  const float px = float(M_PI) * x;
  return std::sin(px) / px;
}

// pbrt-v4's WindowedSinc: a sinc windowed by a sinc tau times wider, zero beyond radius.
float windowedSinc(float x, float radius, float tau) {
  if (std::abs(x) > radius) return 0.0f;
  return sinc(x) * sinc(x / tau);
}

// pbrt-v4's Image::ResampleWeights: for each new texel, its first old texel and the weights of
// four, normalized.
struct ResampleWeight {
  int firstPixel = 0;
  std::array<float, 4> weight{};
};
std::vector<ResampleWeight> resampleWeights(int oldRes, int newRes) {
  PT_CHECK(newRes >= oldRes, "resampling down");
  std::vector<ResampleWeight> weights(static_cast<std::size_t>(newRes));
  const float radius = 2.0f;
  const float tau = 2.0f;
  for (int i = 0; i < newRes; ++i) {
    ResampleWeight& w = weights[std::size_t(i)];
    const float center = (float(i) + 0.5f) * float(oldRes) / float(newRes);
    w.firstPixel = int(std::floor((center - radius) + 0.5f));
    for (int j = 0; j < 4; ++j) {
      const float pos = float(w.firstPixel + j) + 0.5f;
      w.weight[std::size_t(j)] = windowedSinc(pos - center, radius, tau);
    }
    const float invSum = 1.0f / (w.weight[0] + w.weight[1] + w.weight[2] + w.weight[3]);
    for (float& x : w.weight) x *= invSum;
  }
  return weights;
}

// A texel index folded into [0, size) by the wrap mode; -1 for kWrapBlack outside.
int wrapIndex(int p, int size, uint wrap) {
  if (p >= 0 && p < size) return p;
  if (wrap == kWrapRepeat) return ((p % size) + size) % size;
  if (wrap == kWrapClamp) return std::clamp(p, 0, size - 1);
  return -1;
}

}  // namespace

void FloatImage::reserveValues() {
  const std::size_t n = std::size_t(width) * std::size_t(height) * std::size_t(channels);
  values.clear();
  values.reserve(n);
  adviseHugePages(values.data(), n * sizeof(float));
}

bool isPowerOfTwo(int n) {
  return n > 0 && (n & (n - 1)) == 0;
}

int roundUpPowerOfTwo(int n) {
  int p = 1;
  while (p < n) p *= 2;
  return p;
}

FloatImage resizeUp(const FloatImage& image, int newWidth, int newHeight, uint wrap) {
  const std::size_t c = std::size_t(image.channels);
  const std::vector<ResampleWeight> xWeights = resampleWeights(image.width, newWidth);
  const std::vector<ResampleWeight> yWeights = resampleWeights(image.height, newHeight);
  // Along x, every old row: each new texel's four old ones, wrapped once per column.
  std::vector<std::array<int, 4>> columns(std::size_t(newWidth), std::array<int, 4>{});
  for (int x = 0; x < newWidth; ++x) {
    for (int j = 0; j < 4; ++j) {
      columns[std::size_t(x)][std::size_t(j)] =
          wrapIndex(xWeights[std::size_t(x)].firstPixel + j, image.width, wrap);
    }
  }
  FloatImage rows;
  rows.width = newWidth;
  rows.height = image.height;
  rows.channels = image.channels;
  rows.reserveValues();
  rows.values.resize(std::size_t(newWidth) * std::size_t(image.height) * c);
  for (int y = 0; y < image.height; ++y) {
    const float* from = image.values.data() + std::size_t(y) * std::size_t(image.width) * c;
    float* to = rows.values.data() + std::size_t(y) * std::size_t(newWidth) * c;
    for (int x = 0; x < newWidth; ++x) {
      const ResampleWeight& w = xWeights[std::size_t(x)];
      const std::array<int, 4>& xi = columns[std::size_t(x)];
      for (std::size_t ch = 0; ch < c; ++ch) {
        float v[4];
        for (int j = 0; j < 4; ++j) v[j] = xi[j] < 0 ? 0.0f : from[std::size_t(xi[j]) * c + ch];
        to[std::size_t(x) * c + ch] =
            w.weight[0] * v[0] + w.weight[1] * v[1] + w.weight[2] * v[2] + w.weight[3] * v[3];
      }
    }
  }
  // Along y, clamped to zero: each new row from four whole rows (none beyond a black edge).
  FloatImage out;
  out.width = newWidth;
  out.height = newHeight;
  out.channels = image.channels;
  out.reserveValues();
  const std::size_t rowValues = std::size_t(newWidth) * c;
  out.values.resize(rowValues * std::size_t(newHeight));
  for (int y = 0; y < newHeight; ++y) {
    const ResampleWeight& w = yWeights[std::size_t(y)];
    const float* source[4];
    for (int j = 0; j < 4; ++j) {
      const int yi = wrapIndex(w.firstPixel + j, image.height, wrap);
      source[j] = yi < 0 ? nullptr : rows.values.data() + std::size_t(yi) * rowValues;
    }
    float* to = out.values.data() + std::size_t(y) * rowValues;
    for (std::size_t k = 0; k < rowValues; ++k) {
      float v[4];
      for (int j = 0; j < 4; ++j) v[j] = source[j] == nullptr ? 0.0f : source[j][k];
      to[k] = std::max(
          0.0f, w.weight[0] * v[0] + w.weight[1] * v[1] + w.weight[2] * v[2] + w.weight[3] * v[3]);
    }
  }
  return out;
}

std::vector<FloatImage> mipPyramid(FloatImage image, uint wrap) {
  PT_CHECK(image.width > 0 && image.height > 0 && image.channels > 0, "an empty image");
  if (!isPowerOfTwo(image.width) || !isPowerOfTwo(image.height)) {
    image = resizeUp(image, roundUpPowerOfTwo(image.width), roundUpPowerOfTwo(image.height), wrap);
  }
  int levels = 1;
  for (int side = std::max(image.width, image.height); side > 1; side /= 2) ++levels;
  std::vector<FloatImage> pyramid;
  pyramid.reserve(std::size_t(levels));
  pyramid.push_back(std::move(image));
  for (int i = 1; i < levels; ++i) {
    const FloatImage& from = pyramid.back();
    FloatImage next;
    next.width = std::max(1, from.width / 2);
    next.height = std::max(1, from.height / 2);
    next.channels = from.channels;
    next.reserveValues();
    const std::size_t c = std::size_t(from.channels);
    next.values.resize(std::size_t(next.width) * std::size_t(next.height) * c);
    float* to = next.values.data();
    for (int y = 0; y < next.height; ++y) {
      // The 2 x 2 texels; a side of 1 repeats its one texel (pbrt-v4's source offsets).
      const float* row0 = from.values.data() + std::size_t(2 * y) * std::size_t(from.width) * c;
      const float* row1 = from.values.data() + std::size_t(std::min(2 * y + 1, from.height - 1)) *
                                                   std::size_t(from.width) * c;
      for (int x = 0; x < next.width; ++x) {
        const std::size_t x0 = std::size_t(2 * x) * c;
        const std::size_t x1 = std::size_t(std::min(2 * x + 1, from.width - 1)) * c;
        for (std::size_t ch = 0; ch < c; ++ch) {
          *to++ = (row0[x0 + ch] + row0[x1 + ch] + row1[x0 + ch] + row1[x1 + ch]) / 4.0f;
        }
      }
    }
    pyramid.push_back(std::move(next));
  }
  return pyramid;
}

}  // namespace pt
