// Textured glTF scenes for the tests: PNG textures as data URIs, materials, a square and a
// sphere with texture coordinates, a camera and a directional light added to a GltfBuilder,
// their CPU render, and the comparison of two renders of the same scene told two ways.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/gltf/gltf_scene.h"
#include "tests/gltf_builder.h"

namespace pt::test {

// An 8-bit PNG of width x height texels of `channels` bytes each, row 0 at the top (defined in
// gltf_texture_render_test.cpp, beside stb_image_write's implementation).
std::vector<std::uint8_t> png(int width, int height, int channels,
                              const std::vector<std::uint8_t>& texels);

// A texture of the PNG (a data URI) with a nearest, clamped sampler; returns its index.
inline int addTexture(GltfBuilder& b, const std::vector<std::uint8_t>& bytes) {
  b.doc["images"].push_back({{"uri", "data:image/png;base64," + base64(bytes)}});
  if (!b.doc.contains("samplers")) {
    b.doc["samplers"] = nlohmann::json::array(
        {{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33071}}});
  }
  b.doc["textures"].push_back({{"source", int(b.doc["images"].size()) - 1}, {"sampler", 0}});
  return int(b.doc["textures"].size()) - 1;
}

// A uniform texture of one RGB(A) texel value, 2 x 2.
inline int addUniformTexture(GltfBuilder& b, std::vector<std::uint8_t> texel) {
  std::vector<std::uint8_t> texels;
  for (int i = 0; i < 4; ++i) texels.insert(texels.end(), texel.begin(), texel.end());
  return addTexture(b, png(2, 2, int(texel.size()), texels));
}

inline int addMaterial(GltfBuilder& b, const nlohmann::json& material) {
  b.doc["materials"].push_back(material);
  return int(b.doc["materials"].size()) - 1;
}

// A square of side 2 in the z = 0 plane facing +z, its texture coordinates glTF's (v down the
// square: the image upright as the camera on +z sees it), placed by `node` (its mesh set here).
// With `tangent` (w not 0), every vertex has that TANGENT.
inline int addSquare(GltfBuilder& b, int material, nlohmann::json node = nlohmann::json::object(),
                     glm::vec4 tangent = glm::vec4(0.0f)) {
  const int p = b.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3", 3);
  const int n = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
  const int uv = b.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  const std::vector<std::uint16_t> idx = {0, 1, 2, 0, 2, 3};
  const int i = b.accessor(b.view(idx), GltfBuilder::kUShort, idx.size(), "SCALAR");
  nlohmann::json attributes = {{"POSITION", p}, {"NORMAL", n}, {"TEXCOORD_0", uv}};
  if (tangent.w != 0.0f) {
    std::vector<float> t;
    for (int k = 0; k < 4; ++k) t.insert(t.end(), {tangent.x, tangent.y, tangent.z, tangent.w});
    attributes["TANGENT"] = b.floats(t, "VEC4", 4);
  }
  node["mesh"] = b.mesh(nlohmann::json::array(
      {{{"attributes", attributes}, {"indices", i}, {"material", material}}}));
  return b.node(node);
}

// A UV sphere of radius 1 with normals and texture coordinates.
inline int addSphere(GltfBuilder& b, int material, nlohmann::json node = nlohmann::json::object()) {
  const GltfBuilder::SphereAccessors s = b.sphere(16, 32, true);
  node["mesh"] = b.mesh(nlohmann::json::array(
      {{{"attributes", {{"POSITION", s.positions}, {"NORMAL", s.normals}, {"TEXCOORD_0", s.uvs}}},
        {"indices", s.indices},
        {"material", material}}}));
  return b.node(node);
}

// A camera on +z at `distance` looking along -z, film of the given aspect ratio (width over
// height), field of view yfov (radians).
inline int addCamera(GltfBuilder& b, double distance, double yfov, double aspectRatio = 1.0) {
  b.doc["cameras"] = nlohmann::json::array(
      {{{"type", "perspective"},
        {"perspective", {{"yfov", yfov}, {"aspectRatio", aspectRatio}, {"znear", 0.01}}}}});
  return b.node({{"camera", 0}, {"translation", {0, 0, distance}}});
}

// The rotation (a quaternion, glTF's x, y, z, w) that takes unit `from` onto the direction `to`:
// about from x to by the angle between them.
inline nlohmann::json rotationTaking(glm::dvec3 from, glm::dvec3 to) {
  to = glm::normalize(to);
  glm::dvec3 axis = glm::cross(from, to);
  const double s = glm::length(axis);
  axis = s > 0 ? axis / s : glm::dvec3(1, 0, 0);
  const double half = std::atan2(s, glm::dot(from, to)) / 2;
  return {axis.x * std::sin(half), axis.y * std::sin(half), axis.z * std::sin(half),
          std::cos(half)};
}

// A directional light shining along `direction` (its node's -z turned onto it).
inline int addDirectionalLight(GltfBuilder& b, glm::dvec3 direction, double intensity) {
  b.doc["extensionsUsed"] = nlohmann::json::array({"KHR_lights_punctual"});
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
      nlohmann::json::array({{{"type", "directional"}, {"intensity", intensity}}});
  return b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}},
                 {"rotation", rotationTaking(glm::dvec3(0, 0, -1), direction)}});
}

inline Image renderCpuImage(const GltfBuilder& b, int size, int spp, RenderSettings settings = {}) {
  Scene scene = loadGltfSceneBytes(b.gltf(), "test.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  settings.width = size;
  settings.height = size;
  const SceneData data = prepareScene(std::move(scene), settings);
  Film film(size, size);
  renderCpu(data, cpuOptions(2, spp), film);
  return film.resolve();
}

inline vec3 meanOf(const Image& image, int x0, int y0, int x1, int y1) {
  vec3 sum(0.0f);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) sum += image.at(x, y);
  }
  return sum / float((x1 - x0) * (y1 - y0));
}

// Two renders of the same scene told two ways, over the pixels [x0, x1) x [y0, y1) (the whole
// image by default): 99.5 % of them within 1e-3 (relative, or absolute below 1e-3) and the
// means within 1e-3.
inline void expectSameImage(const Image& a, const Image& b, int x0 = 0, int y0 = 0, int x1 = -1,
                            int y1 = -1) {
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  ASSERT_EQ(a.width, b.width);
  if (x1 < 0) x1 = a.width;
  if (y1 < 0) y1 = a.height;
  size_t over = 0;
  vec3 meanA(0.0f), meanB(0.0f);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const vec3 p = a.at(x, y), q = b.at(x, y);
      for (int c = 0; c < 3; ++c) {
        if (std::abs(p[c] - q[c]) >
            1e-3f * std::max(1.0f, std::max(std::abs(p[c]), std::abs(q[c])))) {
          ++over;
          break;
        }
      }
      meanA += p;
      meanB += q;
    }
  }
  EXPECT_LE(double(over), 0.005 * double((x1 - x0) * (y1 - y0)));
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(meanA[c], 0.0f);
    EXPECT_NEAR(meanA[c], meanB[c], 1e-3f * meanB[c]) << "channel " << c;
  }
}

}  // namespace pt::test
