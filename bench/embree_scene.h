// Embree 3 as the benchmarks use it: a device that reports its errors, and a scene of one
// triangle geometry over our triangles, for which Embree builds its own BVH with its
// defaults (RTC_BUILD_QUALITY_MEDIUM, RTC_SCENE_FLAG_NONE, binned SAH, its task system on
// every hardware thread unless the device's config says otherwise). Two ways in: the
// unshared triangles as we store them (ray_bench's traversal, where the layout of the input
// does not matter: Embree copies the vertices into its leaves), and an indexed mesh with
// shared vertices, filled before any clock starts (bvh_build_bench: Embree's build time as
// its own buildbench measures it). Only for the benchmarks that link Embree
// (bench/CMakeLists.txt).
#pragma once

#include <embree3/rtcore.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "common/check.h"
#include "common/shared.h"

namespace pt::bench {

class EmbreeDevice {
 public:
  // `config`: rtcNewDevice's string, e.g. "threads=2"; nullptr for Embree's defaults.
  explicit EmbreeDevice(const char* config = nullptr) : device_(rtcNewDevice(config)) {
    PT_CHECK(device_ != nullptr, "rtcNewDevice failed");
    rtcSetDeviceErrorFunction(
        device_,
        [](void*, RTCError code, const char* message) {
          std::fprintf(stderr, "embree error %d: %s\n", int(code), message);
        },
        nullptr);
  }
  ~EmbreeDevice() { rtcReleaseDevice(device_); }
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;

  RTCDevice get() const { return device_; }

 private:
  RTCDevice device_;
};

// A committed scene of the triangles, in the given order: Embree's primID is the index in
// `triangles`. Vertices are not shared (three per triangle, float3), as our Triangle stores
// them. `flags`: e.g. RTC_SCENE_FLAG_ROBUST, Embree's slower watertight mode. The caller
// releases the scene (rtcReleaseScene).
inline RTCScene newEmbreeScene(RTCDevice device, const std::vector<Triangle>& triangles,
                               RTCSceneFlags flags = RTC_SCENE_FLAG_NONE) {
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, flags);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const size_t n = triangles.size();
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), n));
  PT_CHECK(vertices != nullptr && indices != nullptr, "Embree could not allocate the buffers");
  for (size_t i = 0; i < n; ++i) {
    const Triangle& t = triangles[i];
    for (int k = 0; k < 3; ++k) {
      vertices[9 * i + 0 + size_t(k)] = t.v0[k];
      vertices[9 * i + 3 + size_t(k)] = t.v1[k];
      vertices[9 * i + 6 + size_t(k)] = t.v2[k];
      indices[3 * i + size_t(k)] = uint32_t(3 * i + size_t(k));
    }
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  return scene;
}

// A triangle mesh as Embree's own tools hand it to Embree (tutorials/common/scenegraph,
// buildbench's convertTriangleMesh): positions 16 bytes apart (Vec3fa: x, y, z and a pad,
// which also gives Embree the readable bytes past the last vertex that it asks for), three
// 32-bit indices per triangle.
struct IndexedMesh {
  struct alignas(16) Position {
    float x, y, z, pad;
  };
  std::vector<Position> positions;
  std::vector<std::array<uint32_t, 3>> indices;  // indices[i]: triangles[i] of the input
};

// The shared-vertex mesh of `triangles`, in their order: positions that are equal bit for
// bit become one vertex, numbered in order of first use. The scene loaders hand every
// triangle its own three vertices; where a file's vertices are distinct (the bunny's OBJ:
// 34,835) this gives back its indexing, up to the numbering. The dragon's PLY has 437,645
// vertices at 435,545 distinct positions, which the weld makes its vertices; bench::uvSphere's
// grid gives 526,354 (its south-pole row stays apart: sin(pi) is not 0 in floats).
inline IndexedMesh weldVertices(const std::vector<Triangle>& triangles) {
  using Key = std::array<uint32_t, 3>;
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint64_t h = 0x9e3779b97f4a7c15ull;
      for (uint32_t v : k) h = (h ^ v) * 0xff51afd7ed558ccdull;
      return size_t(h ^ (h >> 32));
    }
  };
  IndexedMesh mesh;
  std::unordered_map<Key, uint32_t, KeyHash> index;
  index.reserve(triangles.size());
  mesh.indices.reserve(triangles.size());
  auto vertex = [&](vec3 p) {
    Key key;
    for (int k = 0; k < 3; ++k) std::memcpy(&key[size_t(k)], &p[k], sizeof(float));
    const auto [it, added] = index.try_emplace(key, uint32_t(mesh.positions.size()));
    if (added) mesh.positions.push_back({p[0], p[1], p[2], 0.0f});
    return it->second;
  };
  for (const Triangle& t : triangles)
    mesh.indices.push_back({vertex(t.v0), vertex(t.v1), vertex(t.v2)});
  return mesh;
}

// A scene of one triangle geometry over `mesh`'s buffers, shared (rtcSetSharedGeometryBuffer:
// not copied; `mesh` must outlive the scene), with the build quality and scene flags set to
// Embree's defaults (RTC_BUILD_QUALITY_MEDIUM, RTC_SCENE_FLAG_NONE) as buildbench's
// create_static_static sets them. Not committed: the caller times rtcCommitScene alone, as
// buildbench does, and releases the scene.
inline RTCScene newUncommittedEmbreeScene(RTCDevice device, const IndexedMesh& mesh) {
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_MEDIUM);
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                             mesh.positions.data(), 0, sizeof(IndexedMesh::Position),
                             mesh.positions.size());
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                             mesh.indices.data(), 0, sizeof(mesh.indices[0]), mesh.indices.size());
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  return scene;
}

}  // namespace pt::bench
