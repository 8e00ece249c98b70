// Helpers shared by the tests: procedural meshes, temporary files, the configs/ directory and
// running the pt command line.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <hwy/targets.h>

#include "common/check.h"
#include "common/shared.h"
#include "cpu/integrator.h"
#include "scene/scene.h"

namespace pt::test {

// Runs body() once per instruction set in `targets` (a Highway-dispatched function's compiled
// and runnable targets, e.g. wideTraversalTargets()), making the dispatch choose it, and
// restores the normal choice afterwards, also when body() fails a fatal assertion.
template <typename Body>
void forEachHighwayTarget(const std::vector<int64_t>& targets, const Body& body) {
  ASSERT_FALSE(targets.empty());
  struct Restore {
    ~Restore() { hwy::SetSupportedTargetsForTest(0); }
  } restore;
  for (int64_t target : targets) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    body();
    if (::testing::Test::HasFatalFailure()) return;
  }
}

// The scene files in configs/.
inline const std::filesystem::path kConfigs = std::filesystem::path(PT_SOURCE_DIR) / "configs";
// Two sphere area lights over a diffuse floor (BDPT's and SPPM's tests of sphere lights).
inline const std::filesystem::path kSphereLightsScene =
    std::filesystem::path(PT_SOURCE_DIR) / "tests/data/sphere-lights.pbrt";

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

// The deepest tree the BVH builders make: 63 clusters whose Morton codes each have a single
// bit set, one cluster per bit, so that every highest-differing-bit split peels off one
// cluster (a chain 62 levels deep), and each cluster is 64 coincident triangles, which need 6
// more levels with leaves of 1; one more cluster at (1, 1, 1) fixes the centroid bounds to
// about [0, 1].
inline std::vector<Triangle> makeDeepMortonChain() {
  constexpr float kCell = 1.0f / float(1 << 21);
  std::vector<Triangle> tris;
  auto addCluster = [&](vec3 c) {
    // Coincident copies; small enough for the centroid to stay in its Morton cell, large
    // enough to stay a real triangle in float where the coordinates reach 0.5.
    const float s = 0.5f * kCell;
    for (int i = 0; i < 64; ++i) {
      tris.push_back(
          Triangle{c, 0, c + vec3(s, 0, 0), kNoEmitter, c + vec3(0, s, 0), uint(tris.size())});
    }
  };
  for (int bit = 0; bit < 63; ++bit) {
    vec3 c(0.25f * kCell);
    c[bit % 3] = (std::ldexp(1.0f, bit / 3) + 0.5f) * kCell;
    addCluster(c);
  }
  addCluster(vec3(1.0f));
  return tris;
}

// Adds quad (c -/+ u -/+ v) as two triangles, (p0, p1, p2) and (p0, p2, p3) with p0 = c - u - v,
// p1 = c + u - v, p2 = c + u + v, p3 = c - u + v, whose geometric normal is cross(u, v).
// Primitive ids are left 0 for the caller to number.
inline void addQuad(Scene& scene, vec3 c, vec3 u, vec3 v, uint material) {
  const vec3 p0 = c - u - v, p1 = c + u - v, p2 = c + u + v, p3 = c - u + v;
  scene.triangles.push_back(Triangle{p0, material, p1, kNoEmitter, p2, 0});
  scene.triangles.push_back(Triangle{p0, material, p2, kNoEmitter, p3, 0});
}

// The six faces of the cube [-1, 1]^3 as quads facing inward, in the order -x, +x, -y, +y, -z,
// +z; face f gets materials[f].
inline void addInwardCube(Scene& scene, const uint (&materials)[6]) {
  const vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  addQuad(scene, -x, y, z, materials[0]);
  addQuad(scene, x, z, y, materials[1]);
  addQuad(scene, -y, z, x, materials[2]);
  addQuad(scene, y, x, z, materials[3]);
  addQuad(scene, -z, x, y, materials[4]);
  addQuad(scene, z, y, x, materials[5]);
}

// A fresh empty directory under the system's temp directory, named after the process and the
// running test; removed, with everything in it, by the destructor. (Keep the name short: the
// scene loader's messages cut quoted paths at 80 characters, and scene tests match them.)
class TempDir {
 public:
  TempDir() {
    std::string name = "pt-" + std::to_string(::getpid());
    if (const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info()) {
      name += std::string("-") + info->test_suite_name() + "-" + info->name();
    }
    std::replace(name.begin(), name.end(), '/', '_');  // parameterised tests' names
    // A number that makes it new: a test may hold several, and a crashed run may have left one.
    static std::atomic<int> count = 0;
    do {
      path_ = std::filesystem::temp_directory_path() / (name + "-" + std::to_string(count++));
    } while (!std::filesystem::create_directory(path_));
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

  // Writes `text` to the file `name` (its directories created as needed); returns its path.
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path p = path_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  // The names of everything directly in the directory, sorted: tests check with it that
  // nothing was left behind.
  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::filesystem::path path_;
};

// The whole content of a file ("" when it cannot be read).
inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Writes `bytes` to `path`, replacing the file.
inline void writeBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

// Runs `f` and returns the InputError's message ("" and a test failure if none).
template <typename F>
std::string inputErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError";
  return "";
}

// What a run of the pt command line gave back.
struct PtResult {
  int status = -1;       // exit status; -1 when pt did not exit (killed by a signal)
  std::string out, err;  // everything it wrote to stdout and to stderr
};

// Runs `pt args` through the shell, with `environment` ("NAME=value ...") put before it, and
// captures both streams (through files in a directory of its own).
inline PtResult runPt(const std::string& args, const std::string& environment = "") {
  const TempDir streams;
  const std::filesystem::path out = streams / "stdout.txt", err = streams / "stderr.txt";
  const std::string command = environment + (environment.empty() ? "" : " ") + PT_BINARY + " " +
                              args + " >" + out.string() + " 2>" + err.string();
  const int raw = std::system(command.c_str());
  PtResult result;
  result.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = readFile(out);
  result.err = readFile(err);
  return result;
}

// CPU render options for `spp` samples per pixel on `threads` threads.
inline CpuRenderOptions cpuOptions(int threads, int spp) {
  CpuRenderOptions options;
  options.threads = threads;
  options.spp = spp;
  return options;
}

}  // namespace pt::test
