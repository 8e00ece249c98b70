// What the benchmarks share: wall-clock timing, medians, and the generated UV sphere of
// about 1.05M triangles that both bvh_build_bench and ray_bench use as their large scene.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "common/shared.h"

namespace pt::bench {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The middle value (the upper one of the two middle values for an even count); requires a
// non-empty list.
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// A unit UV sphere about the origin: `rings` bands of latitude, `segments` of longitude, two
// triangles per quad and one per quad at the poles: 2 * segments * (rings - 1) triangles,
// 1,051,250 for uvSphere(726, 725). Triangles carry material `material`, no emitter, and
// their index as primitive.
inline std::vector<Triangle> uvSphere(int rings, int segments, uint material = 0) {
  auto vertex = [&](int ring, int segment) {
    const double theta = kPi * double(ring) / double(rings);
    const double phi = 2.0 * kPi * double(segment % segments) / double(segments);
    return vec3(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                float(std::sin(theta) * std::sin(phi)));
  };
  std::vector<Triangle> triangles;
  triangles.reserve(size_t(2) * size_t(segments) * size_t(rings - 1));
  auto add = [&](vec3 a, vec3 b, vec3 c) {
    triangles.push_back(Triangle{a, material, b, kNoEmitter, c, uint(triangles.size())});
  };
  for (int ring = 0; ring < rings; ++ring) {
    for (int segment = 0; segment < segments; ++segment) {
      const vec3 a = vertex(ring, segment), b = vertex(ring, segment + 1);
      const vec3 c = vertex(ring + 1, segment), d = vertex(ring + 1, segment + 1);
      if (ring > 0) add(a, c, b);
      if (ring < rings - 1) add(b, c, d);
    }
  }
  return triangles;
}

}  // namespace pt::bench
