// Linear RGB images in memory and on disk (EXR, PFM, PNG), and image comparison.
// Knows nothing of scenes or renderers.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace pt {

// Linear radiance, row 0 at the top, pixels row-major.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> pixels;

  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(size_t(w) * size_t(h), glm::vec3(0.0f)) {}
  glm::vec3& at(int x, int y) { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  const glm::vec3& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

// Writes by file extension: .exr (32-bit float RGB, scene-linear), .pfm (little-endian
// float RGB, rows bottom-to-top as PFM requires), .png (8-bit sRGB-encoded, clamped to
// [0, 1]). Writes to a temporary file beside the target and renames it, so an interrupted
// or failed write never leaves a half-written file. Throws InputError for an unknown
// extension or an unwritable path.
void writeImage(const Image& image, const std::filesystem::path& path);

// Reads .exr, .pfm or .png (PNG is decoded from sRGB to linear). Throws InputError naming
// the file for anything malformed.
Image readImage(const std::filesystem::path& path);

struct DiffStats {
  double rmse = 0.0;          // sqrt(mean over pixels and channels of (a - b)^2)
  double relMse = 0.0;        // mean of (a - b)^2 / (b^2 + 1e-2), b the reference
  double maxAbsError = 0.0;   // max over pixels and channels of |a - b|
  size_t pixelsOverThreshold = 0;  // pixels with any channel |a - b| > threshold * max(1, |b|)
  size_t pixelCount = 0;
};

// Compares a against the reference b (same size, else InputError).
DiffStats diffImages(const Image& a, const Image& b, double threshold);

// A false-colour heatmap of the per-pixel max channel |a - b|, scaled so that `scale` maps to
// the top of the colour ramp.
Image diffHeatmap(const Image& a, const Image& b, double scale);

}  // namespace pt
