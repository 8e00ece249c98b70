// Environment images' sampling tables; see environment_map.h.
#include "render/environment_map.h"

#include <algorithm>
#include <cmath>

#include "common/check.h"
#include "common/numbers.h"

namespace pt {
namespace {

// sin theta at the centre of row y of a lat-long map of `height` rows: the solid angle its
// texels cover, relative to the equator's.
double latLongRowWeight(int y, int height) {
  return std::sin(kPiD * (double(y) + 0.5) / double(height));
}

// The ends of the CDF of `weights` (n of them, non-negative), as floats, the last exactly 1;
// uniform where they sum to 0. Returns the sum.
double cdfEnds(const double* weights, size_t n, float* ends) {
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum += weights[i];
  double running = 0.0;
  for (size_t i = 0; i < n; ++i) {
    running += weights[i];
    const double end = sum > 0.0 ? running / sum : double(i + 1) / double(n);
    ends[i] = i + 1 == n ? 1.0f : std::min(float(end), 1.0f);
  }
  return sum;
}

// The guide table of the CDF with these `ends` (environment.h's environmentGuideSize + 1
// entries), written from float `at` of `out` on.
void writeGuide(const float* ends, uint n, std::vector<vec4>& out, size_t at) {
  const uint g = environmentGuideSize(n);
  uint bin = 0;
  for (uint k = 0; k <= g; ++k) {
    // k / G is exact in float: the comparison is the shader's.
    const float threshold = float(k) / float(g);
    while (bin + 1 < n && !(ends[bin] > threshold)) ++bin;
    const size_t i = at + k;
    out[i / 4][int(i % 4)] = float(bin);
  }
}

}  // namespace

std::vector<vec4> buildEnvironmentTexels(const Image& radiance, uint mapping, bool compensated) {
  const int w = radiance.width, h = radiance.height;
  PT_CHECK(w > 0 && h > 0 && radiance.pixels.size() == size_t(w) * size_t(h));
  std::vector<double> weights(radiance.pixels.size());
  for (int y = 0; y < h; ++y) {
    const double row = mapping == kEnvironmentLatLong ? latLongRowWeight(y, h) : 1.0;
    for (int x = 0; x < w; ++x) {
      const vec3 c = max(radiance.at(x, y), vec3(0.0f));
      weights[size_t(y) * size_t(w) + size_t(x)] =
          (double(c.x) + double(c.y) + double(c.z)) / 3.0 * row;
    }
  }
  if (compensated) {
    double mean = 0.0;
    for (double v : weights) mean += v;
    mean /= double(weights.size());
    bool any = false;
    for (double& v : weights) {
      v = std::max(v - mean, 0.0);
      any |= v > 0.0;
    }
    if (!any) std::fill(weights.begin(), weights.end(), 1.0);
  }
  std::vector<vec4> texels(environmentTexelCount(w, h), vec4(0.0f));
  const size_t marginalBase = size_t(w) * size_t(h);
  std::vector<double> rowSums(size_t(h), 0.0);
  std::vector<float> ends(static_cast<size_t>(w));
  for (int y = 0; y < h; ++y) {
    const size_t base = size_t(y) * size_t(w);
    rowSums[size_t(y)] = cdfEnds(&weights[base], size_t(w), ends.data());
    for (int x = 0; x < w; ++x) {
      texels[base + size_t(x)] = vec4(max(radiance.at(x, y), vec3(0.0f)), ends[size_t(x)]);
    }
    writeGuide(ends.data(), uint(w), texels, environmentGuideStart(uint(w), uint(h), y));
  }
  std::vector<float> marginal(static_cast<size_t>(h));
  cdfEnds(rowSums.data(), size_t(h), marginal.data());
  for (int y = 0; y < h; ++y) texels[marginalBase + size_t(y) / 4][y % 4] = marginal[size_t(y)];
  writeGuide(marginal.data(), uint(h), texels, environmentGuideStart(uint(w), uint(h), -1));
  return texels;
}

vec3 environmentMeanRadiance(const Image& radiance, uint mapping) {
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int y = 0; y < radiance.height; ++y) {
    const double row = mapping == kEnvironmentLatLong ? latLongRowWeight(y, radiance.height) : 1.0;
    for (int x = 0; x < radiance.width; ++x) {
      sum += glm::dvec3(max(radiance.at(x, y), vec3(0.0f))) * row;
      weight += row;
    }
  }
  return weight > 0.0 ? vec3(sum / weight) : vec3(0.0f);
}

}  // namespace pt
