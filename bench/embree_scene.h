// Embree 3 as the benchmarks use it: a device that reports its errors, and a scene of one
// triangle geometry over our triangles, for which Embree builds its own BVH with its
// defaults (RTC_BUILD_QUALITY_MEDIUM, binned SAH, its task system on every hardware thread).
// Only for the benchmarks that link Embree (bench/CMakeLists.txt).
#pragma once

#include <embree3/rtcore.h>

#include <cstdio>
#include <vector>

#include "common/check.h"
#include "common/shared.h"

namespace pt::bench {

class EmbreeDevice {
 public:
  EmbreeDevice() : device_(rtcNewDevice(nullptr)) {
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

}  // namespace pt::bench
