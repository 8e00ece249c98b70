// Comparing a rendered image against a reference: error statistics and a false-colour
// heatmap of where they differ.

#include "image/image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace pt {
namespace {

void requireSameSize(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) {
    throw InputError("image sizes differ: " + std::to_string(a.width) + "x" +
                     std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                     std::to_string(b.height));
  }
}

bool isFinite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Heatmap ramp with stops evenly spaced in error: black, blue, magenta, yellow, white. The
// stops' channels are all 0 or 1, so they are the same colours linear or sRGB-encoded. Blending
// between them in linear light makes luminance rise all along the ramp (blending the encoded
// values would make it dip between magenta and yellow), so a bigger error always looks
// brighter, while the hue tells the bands apart.
constexpr std::array<glm::vec3, 5> kRamp = {glm::vec3(0, 0, 0), glm::vec3(0, 0, 1),
                                            glm::vec3(1, 0, 1), glm::vec3(1, 1, 0),
                                            glm::vec3(1, 1, 1)};
// Pixels where either image is NaN or infinite: a colour the ramp never produces.
constexpr glm::vec3 kNonFiniteColour(0, 1, 0);

glm::vec3 rampColour(double t) {  // t in [0, 1]
  const double position = t * double(kRamp.size() - 1);
  const size_t i = std::min(size_t(position), kRamp.size() - 2);
  const float f = float(position - double(i));
  return glm::mix(kRamp[i], kRamp[i + 1], f);
}

}  // namespace

DiffStats diffImages(const Image& a, const Image& b, double threshold) {
  requireSameSize(a, b);
  if (!(threshold >= 0.0)) {
    throw InputError("diff threshold must be a non-negative number, got " +
                     std::to_string(threshold));
  }
  DiffStats stats;
  stats.pixelCount = a.pixels.size();
  double sumSquared = 0.0, sumRelative = 0.0;
  size_t finitePixels = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3& pa = a.pixels[i];
    const glm::vec3& pb = b.pixels[i];
    // A NaN would poison the sums and compare false against the threshold, so such pixels are
    // counted on their own and always fail.
    if (!isFinite(pa) || !isFinite(pb)) {
      ++stats.nonFinitePixels;
      ++stats.pixelsOverThreshold;
      continue;
    }
    bool over = false;
    for (int c = 0; c < 3; ++c) {
      const double reference = pb[c];
      const double d = double(pa[c]) - reference;
      const double absError = std::fabs(d);
      sumSquared += d * d;
      sumRelative += d * d / (reference * reference + 1e-2);
      stats.maxAbsError = std::max(stats.maxAbsError, absError);
      if (absError > threshold * std::max(1.0, std::fabs(reference))) over = true;
    }
    ++finitePixels;
    if (over) ++stats.pixelsOverThreshold;
  }
  if (finitePixels > 0) {
    const double samples = 3.0 * double(finitePixels);
    stats.rmse = std::sqrt(sumSquared / samples);
    stats.relMse = sumRelative / samples;
  }
  return stats;
}

Image diffHeatmap(const Image& a, const Image& b, double scale) {
  requireSameSize(a, b);
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw InputError("heatmap scale must be a positive number, got " + std::to_string(scale));
  }
  Image heatmap(a.width, a.height);
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3& pa = a.pixels[i];
    const glm::vec3& pb = b.pixels[i];
    glm::vec3 colour = kNonFiniteColour;
    if (isFinite(pa) && isFinite(pb)) {
      double error = 0.0;
      for (int c = 0; c < 3; ++c) error = std::max(error, std::fabs(double(pa[c]) - double(pb[c])));
      colour = rampColour(std::min(1.0, error / scale));
    }
    heatmap.pixels[i] = colour;
  }
  return heatmap;
}

}  // namespace pt
