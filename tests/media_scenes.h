// Building blocks of the media tests' scenes (media_test.cpp, nanovdb_cloud_test.cpp): media,
// shapes with medium interfaces, a camera, a constant environment.
#pragma once

#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "render/prepare.h"
#include "render_compare.h"
#include "test_util.h"

namespace pt::media_scenes {

constexpr uint kVacuum = kNoMedium;

inline Medium homogeneous(vec3 sigmaA, vec3 sigmaS, float g = 0.0f) {
  Medium m{};
  m.type = kMediumHomogeneous;
  m.sigmaA = sigmaA;
  m.sigmaS = sigmaS;
  m.g = g;
  m.density = m.majorants = m.emission = kNoGrid;
  return m;
}

// A uniformgrid medium over [lo, hi] (identity transform) with the given densities (x fastest),
// appended to scene.mediumGrids.
inline Medium uniformGrid(Scene& scene, vec3 lo, vec3 hi, uvec3 size,
                          const std::vector<float>& density, vec3 sigmaA, vec3 sigmaS) {
  Medium m = homogeneous(sigmaA, sigmaS);
  m.type = kMediumUniformGrid;
  m.boundsMin = lo;
  m.boundsMax = hi;
  m.size = size;
  m.density = uint(scene.mediumGrids.size());
  scene.mediumGrids.insert(scene.mediumGrids.end(), density.begin(), density.end());
  m.toMedium0 = vec4(1, 0, 0, 0);
  m.toMedium1 = vec4(0, 1, 0, 0);
  m.toMedium2 = vec4(0, 0, 1, 0);
  return m;
}

// Appends triangles with one medium interface for all of them, numbering their primitives.
inline void addShape(Scene& scene, std::vector<Triangle> tris, uint material,
                     MediumInterface media) {
  for (Triangle& t : tris) {
    t.material = material;
    t.primitive = uint(scene.triangles.size());
    scene.triangles.push_back(t);
    scene.mediumInterfaces.push_back(media);
  }
}

// Quad c -/+ u -/+ v (normal cross(u, v)), as test_util's addQuad.
inline std::vector<Triangle> quad(vec3 c, vec3 u, vec3 v) {
  Scene s;
  test::addQuad(s, c, u, v, 0);
  return s.triangles;
}

// The box [lo, hi] with outward normals.
inline std::vector<Triangle> box(vec3 lo, vec3 hi) {
  const vec3 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
  const vec3 x(h.x, 0, 0), y(0, h.y, 0), z(0, 0, h.z);
  std::vector<Triangle> tris;
  for (const auto& q : {quad(c + x, y, z), quad(c - x, z, y), quad(c + y, z, x), quad(c - y, x, z),
                        quad(c + z, x, y), quad(c - z, y, x)}) {
    tris.insert(tris.end(), q.begin(), q.end());
  }
  return tris;
}

// A sphere with outward normals (test_util's faces inward).
inline std::vector<Triangle> sphere(vec3 centre, float radius) {
  std::vector<Triangle> tris = test::makeSphere(centre, radius, 24, 48);
  for (Triangle& t : tris) std::swap(t.v1, t.v2);
  return tris;
}

inline CameraDesc camera(vec3 position, vec3 target, float vfov, int size) {
  CameraDesc c;
  c.position = position;
  c.target = target;
  c.up = vec3(0, 1, 0);
  c.vfovDegrees = vfov;
  c.width = c.height = size;
  return c;
}

inline Light environment(float radiance) {
  Light sky{};
  sky.type = kLightInfinite;
  sky.radiance = vec3(radiance);
  return sky;
}

inline SceneData prepare(Scene scene, int maxDepth = 64) {
  scene.integrator.maxDepth = maxDepth;
  return prepareScene(std::move(scene), RenderSettings{});
}

// A sphere of scattering medium bounded by an interface (index 1: no surface) under a
// constant environment of radiance 1. At albedo 1 no energy is lost or gained: every pixel is
// an estimate of 1, the sphere's as the environment's. At albedo 0.5 the sphere is darker and
// no pixel brighter than the environment beyond noise.
struct FurnaceResult {
  Comparison cmp;
  std::vector<size_t> sphere;  // pixels whose camera rays all cross the sphere
};
inline FurnaceResult furnace(const Medium& medium, const std::vector<float>& grids, int spp) {
  constexpr int kSize = 12;
  Scene scene;
  scene.camera = camera(vec3(0, 0, -4), vec3(0, 0, 0), 30.0f, kSize);
  scene.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0}};
  scene.lights = {environment(1.0f)};
  scene.media = {medium};
  scene.mediumGrids = grids;
  addShape(scene, sphere(vec3(0.0f), 1.0f), 0, MediumInterface{0, kVacuum});
  FurnaceResult r;
  const SceneData data = prepare(scene, 256);
  r.cmp = renderBoth(data, spp);
  // The pixels whose four corners' rays pass well inside the unit sphere.
  const Camera& cam = data.params.camera;
  const auto inside = [&](float x, float y) {
    const Ray ray = cameraRay(cam, vec2(x, y));
    const vec3 d = normalize(ray.direction);
    const vec3 o = ray.origin + data.shift;
    const float b = dot(o, d);
    return b * b - (dot(o, o) - 0.95f) > 0.0f;
  };
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const float fx = float(x), fy = float(y);
      if (inside(fx, fy) && inside(fx + 1, fy) && inside(fx, fy + 1) && inside(fx + 1, fy + 1)) {
        r.sphere.push_back(size_t(y) * kSize + size_t(x));
      }
    }
  }
  return r;
}

inline FurnaceResult furnace(vec3 sigmaA, vec3 sigmaS, float g, int spp) {
  return furnace(homogeneous(sigmaA, sigmaS, g), {}, spp);
}

// A furnace whose medium has albedo 1 renders the environment: within 4 standard errors (of at
// most 0.015) inside the sphere, exactly outside it; the backends agree.
inline void expectTheEnvironment(const FurnaceResult& r) {
  ASSERT_GE(r.sphere.size(), 50u);
  expectAgreement(r.cmp);
  for (const Image* image : {&r.cmp.cpuImage, &r.cmp.gpuImage}) {
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0, sumSquares = 0.0;
      for (size_t i : r.sphere) {
        const double v = image->pixels[i][c];
        sum += v;
        sumSquares += v * v;
      }
      const double n = double(r.sphere.size());
      const double mean = sum / n;
      const double se = std::sqrt(std::max(0.0, sumSquares / n - mean * mean) / n);
      EXPECT_LT(se, 0.015) << "channel " << c;
      EXPECT_NEAR(mean, 1.0, 4.0 * se + 1e-3) << "channel " << c;
    }
    // Outside the sphere: the environment, exactly.
    EXPECT_EQ(image->at(0, 0), vec3(1.0f));
  }
}

}  // namespace pt::media_scenes
