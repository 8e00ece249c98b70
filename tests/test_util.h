// Helpers shared by the tests: procedural meshes and temporary files.
#pragma once

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "common/shared.h"

namespace pt::test {

// A UV sphere of 2 * rings * segments triangles (minus the pole slivers' neighbours), with
// outward winding; vertices shared exactly between neighbouring triangles.
inline std::vector<Triangle> makeSphere(vec3 center, float radius, int rings, int segments) {
  auto point = [&](int i, int j) {
    if (i == 0) return center + vec3(0, radius, 0);
    if (i == rings) return center - vec3(0, radius, 0);
    const float theta = kPi * float(i) / float(rings);
    const float phi = 2.0f * kPi * float(j % segments) / float(segments);
    return center + radius * vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                  std::sin(theta) * std::sin(phi));
  };
  std::vector<Triangle> tris;
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const vec3 a = point(i, j), b = point(i, j + 1), c = point(i + 1, j), d = point(i + 1, j + 1);
      if (i != 0) tris.push_back(Triangle{a, 0, c, kNoEmitter, b, 0});
      if (i != rings - 1) tris.push_back(Triangle{b, 0, c, kNoEmitter, d, 0});
    }
  }
  for (uint i = 0; i < tris.size(); ++i) tris[i].primitive = i;
  return tris;
}

// A fresh empty directory under the system's temp directory, removed by the destructor.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("pt-test-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace pt::test
