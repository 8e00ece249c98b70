// Linear RGB images in memory and on disk (EXR, PFM, PNG), and image comparison.
// Knows nothing of scenes or renderers.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/check.h"
#include "image/exact_sum.h"

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

enum class ImageFormat { kExr, kPfm, kPng };

// The format a file name's extension (any case) asks for; InputError "<path>: unknown image
// file extension ..." for anything else.
ImageFormat imageFormatOf(const std::filesystem::path& path);

// Writes by file extension: .exr (32-bit float RGB, scene-linear), .pfm (little-endian
// float RGB, rows bottom-to-top as PFM requires), .png (8-bit sRGB-encoded, clamped to
// [0, 1]). Writes to a temporary file beside the target and renames it, so an interrupted
// or failed write never leaves a half-written file. Throws InputError for an unknown
// extension or an unwritable path.
void writeImage(const Image& image, const std::filesystem::path& path);

// Reads .exr, .pfm, .png (PNG is decoded from sRGB to linear) or .hdr (Radiance RGBE, by
// stb_image's stbi_loadf; read, not written). Throws InputError naming
// the file for anything malformed.
Image readImage(const std::filesystem::path& path);

struct DiffStats {
  double rmse = 0.0;               // sqrt(mean over pixels and channels of (a - b)^2)
  double relMse = 0.0;             // mean of (a - b)^2 / (b^2 + 1e-2), b the reference
  double maxAbsError = 0.0;        // max over pixels and channels of |a - b|
  size_t pixelsOverThreshold = 0;  // pixels with any channel |a - b| > threshold * max(1, |b|)
  size_t pixelCount = 0;
  // Pixels where a channel of a or b is NaN or infinite. They are also counted in
  // pixelsOverThreshold and left out of rmse, relMse and maxAbsError (whose means are then
  // over the finite pixels only; 0 when there are none).
  size_t nonFinitePixels = 0;
};

// Compares a against the reference b (same size, else InputError "image sizes differ: WxH vs
// WxH"). A negative or NaN threshold is an InputError.
DiffStats diffImages(const Image& a, const Image& b, double threshold);

// A false-colour heatmap of the per-pixel max channel |a - b|, scaled so that `scale` maps to
// the top of the colour ramp (black, blue, magenta, yellow, white as the error grows); pixels
// where a or b is non-finite are pure green. The result holds linear values, so written as
// PNG it shows the ramp colours exactly. Sizes must match and scale must be positive, else
// InputError.
Image diffHeatmap(const Image& a, const Image& b, double scale);

// The exact piecewise sRGB transfer curve (IEC 61966-2-1) on [0, 1], evaluated in double.
float linearToSrgb(float linear);
float srgbToLinear(float encoded);
// One linear channel as an 8-bit sRGB code, as PNG output stores it: clamped to [0, 1], NaN
// as 0, rounded to nearest.
uint8_t linearToSrgb8(float linear);

// Per-pixel sums of linear radiance plus sample counts. The sums are exact (ExactSum), so a
// pixel's value does not depend on the order its samples were added in: renders split
// across threads, passes, interruptions and machines give the same bits, and long renders
// (1e6+ samples per pixel) do not drift. `sum` holds each exact sum rounded to double.
// Invalid (NaN/Inf) samples are not added; they are counted per pixel so they can be
// reported, never silently dropped.
struct Film {
  int width = 0, height = 0;
  std::vector<uint64_t> sampleCount;   // valid samples added per pixel, row-major, row 0 top
  std::vector<uint64_t> invalidCount;  // NaN/Inf samples seen per pixel
  std::vector<std::array<ExactSum, 3>> exact;  // the sums themselves, per channel

  Film() = default;
  Film(int w, int h);

  // Throws InputError "<what>a WxH film needs N GiB (...), but only M GiB of memory is
  // available" when a w x h film (and the image resolved from it) cannot fit in memory: the
  // constructor checks, and a caller that knows where the size came from checks first, so that
  // its error names the file (`what`, e.g. "scene.json: ") and nothing has been built yet.
  static void checkFitsInMemory(int w, int h, const std::string& what = "");
  // The bytes a film holds per pixel, with its resolved image.
  static size_t bytesPerPixel();

  size_t pixelCount() const { return exact.size(); }
  // Pixel i's sum (row-major index), rounded to double from the exact sums when asked: adding
  // a sample does not round, which saves that work on each of a render's samples.
  glm::dvec3 sum(size_t i) const {
    return glm::dvec3(exact[i][0].toDouble(), exact[i][1].toDouble(), exact[i][2].toDouble());
  }

  // Inline because it runs once per sample. Threads may call it concurrently for disjoint
  // pixels: it touches only pixel (x, y) and takes no lock.
  void add(int x, int y, glm::vec3 radiance) {
    PT_DCHECK(x >= 0 && x < width && y >= 0 && y < height, "film pixel out of range");
    const size_t i = size_t(y) * size_t(width) + size_t(x);
    if (std::isfinite(radiance.x) && std::isfinite(radiance.y) && std::isfinite(radiance.z)) {
      addExact(i, radiance);
      ++sampleCount[i];
    } else {
      ++invalidCount[i];
    }
  }

  // Asks the processor to bring pixel (x, y)'s entries into its caches ahead of an add():
  // a render adds to each pixel once per pass, so they are rarely still there, and add()
  // waits for them (a tenth of the CPU's time on the Cornell box, measured). Only a hint.
  // Always inlined: GCC 12 deletes calls to a function that only prefetches.
  [[gnu::always_inline]] void prefetch(int x, int y) const {
    const size_t i = size_t(y) * size_t(width) + size_t(x);
    const char* sums = reinterpret_cast<const char*>(&exact[i]);  // 120 bytes: 2 or 3 lines
    __builtin_prefetch(sums, /*write=*/1);
    __builtin_prefetch(sums + 64, 1);
    __builtin_prefetch(sums + sizeof(exact[i]) - 1, 1);
    __builtin_prefetch(&sampleCount[i], 1);
  }

  // Undoes add(x, y, radiance) exactly, as if it had never been called (the sums are exact
  // integers underneath, so subtracting restores their bits): how a stopped render drops the
  // samples of a pass it did not finish.
  void takeBack(int x, int y, glm::vec3 radiance) {
    PT_CHECK(x >= 0 && x < width && y >= 0 && y < height, "film pixel out of range");
    const size_t i = size_t(y) * size_t(width) + size_t(x);
    if (std::isfinite(radiance.x) && std::isfinite(radiance.y) && std::isfinite(radiance.z)) {
      PT_CHECK(sampleCount[i] > 0, "taking back a sample that was not added");
      addExact(i, -radiance);
      --sampleCount[i];
    } else {
      PT_CHECK(invalidCount[i] > 0, "taking back a sample that was not added");
      --invalidCount[i];
    }
  }

  // Adds light that reaches pixel (x, y) other than through the pixel's own samples (the light
  // tracing of bidirectional methods: pbrt-v4's splats) to its sum alone, so that the pixel's
  // mean divides it by the samples added, as pbrt-v4 scales its splats by 1 / spp. A
  // non-finite value is not added; it counts as an invalid sample of the pixel.
  void addSplat(int x, int y, glm::vec3 radiance) {
    PT_CHECK(x >= 0 && x < width && y >= 0 && y < height, "film pixel out of range");
    const size_t i = size_t(y) * size_t(width) + size_t(x);
    if (std::isfinite(radiance.x) && std::isfinite(radiance.y) && std::isfinite(radiance.z)) {
      addExact(i, radiance);
    } else {
      ++invalidCount[i];
    }
  }

  // Adds a batch of pixel i's samples (row-major index), summed elsewhere in float: the sum
  // of its `valid` finite samples and the number of `invalid` ones (the Vulkan backend's
  // fold). A non-finite sum (float overflow of finite samples) counts them all as invalid.
  void addSums(size_t i, glm::vec3 radianceSum, uint64_t valid, uint64_t invalid) {
    if (std::isfinite(radianceSum.x) && std::isfinite(radianceSum.y) &&
        std::isfinite(radianceSum.z)) {
      addExact(i, radianceSum);
      sampleCount[i] += valid;
    } else {
      invalid += valid;
    }
    invalidCount[i] += invalid;
  }

  // Adds pixel i's sums summed exactly elsewhere (the Vulkan backend's BDPT film: its samples
  // and splats), with `valid` samples and `invalid` NaN or infinite samples or splats.
  void addExactSums(size_t i, const std::array<ExactSum, 3>& sums, uint64_t valid,
                    uint64_t invalid) {
    for (int c = 0; c < 3; ++c) exact[i][c].add(sums[c]);
    sampleCount[i] += valid;
    invalidCount[i] += invalid;
  }

  // Adds other's samples (sizes must match, PT_CHECK). Exact: merging in any order gives the
  // same film.
  void merge(const Film& other);
  uint64_t totalInvalid() const;
  Image resolve() const;  // sum / count per pixel (0 where count == 0)

 private:
  void addExact(size_t i, glm::vec3 v) {
    for (int c = 0; c < 3; ++c) exact[i][c].add(v[c]);
  }
};

}  // namespace pt
