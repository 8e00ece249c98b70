// glTF's material textures rendered: the metallic-roughness, emissive and normal textures and
// the alpha modes, each against the scene it must equal (the constant material, the surface
// tilted as the normal map tilts it, the sky seen through a cut-out), and a scene of all of them
// on both backends.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

// stb_image_write for the test's PNGs (RGBA, which writeImage does not write), with internal
// linkage like ptcore's copy.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/gltf/gltf_scene.h"
#include "tests/gltf_builder.h"
#include "tests/gltf_texture_scene.h"
#include "texture.h"

namespace pt {
namespace {

using nlohmann::json;
using test::GltfBuilder;

void appendPng(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  out->insert(out->end(), static_cast<const std::uint8_t*>(data),
              static_cast<const std::uint8_t*>(data) + size);
}

}  // namespace

namespace test {

std::vector<std::uint8_t> png(int width, int height, int channels,
                              const std::vector<std::uint8_t>& texels) {
  std::vector<std::uint8_t> out;
  EXPECT_TRUE(stbi_write_png_to_func(appendPng, &out, width, height, channels, texels.data(),
                                     width * channels));
  return out;
}

}  // namespace test

namespace {

using test::addCamera;
using test::addDirectionalLight;
using test::addMaterial;
using test::addSphere;
using test::addSquare;
using test::addTexture;
using test::addUniformTexture;
using test::expectSameImage;
using test::meanOf;
using test::png;
using test::renderCpuImage;
using test::rotationTaking;

// A metallic-roughness texture of G 153 (0.6) and B 204 (0.8), times roughness factor 0.5 and
// metallic factor 1, is the constant material of roughness 0.3 and metallic 0.8.
TEST(GltfTextures, MetallicRoughnessTextureRendersAsTheConstantMaterial) {
  const auto scene = [](bool textured) {
    GltfBuilder b;
    json pbr = {{"baseColorFactor", {0.9, 0.6, 0.3, 1.0}}};
    if (textured) {
      pbr["metallicRoughnessTexture"] = {{"index", addUniformTexture(b, {17, 153, 204})}};
      pbr["roughnessFactor"] = 0.5;
      pbr["metallicFactor"] = 1.0;
    } else {
      pbr["roughnessFactor"] = 0.3;
      pbr["metallicFactor"] = 0.8;
    }
    const int m = addMaterial(b, {{"pbrMetallicRoughness", pbr}});
    b.scene({addSphere(b, m), addCamera(b, 4.0, 0.6),
             addDirectionalLight(b, glm::dvec3(-1, -1, -1), 3.0)});
    return b;
  };
  expectSameImage(renderCpuImage(scene(true), 32, 16), renderCpuImage(scene(false), 32, 16));
}

// An emissive texture of sRGB (200, 100, 50) times emissiveFactor and the emissive strength is
// the constant emission of their product: seen directly, and as the light of a floor (light
// sampling and emission found by BSDF sampling, MIS).
TEST(GltfTextures, EmissiveTextureRendersAsTheConstantEmission) {
  const auto scene = [](bool textured) {
    GltfBuilder b;
    const float r = srgbToLinear(200.0f / 255.0f), g = srgbToLinear(100.0f / 255.0f),
                bl = srgbToLinear(50.0f / 255.0f);
    json lamp = {{"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 2.0}}}}},
                 {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}}};
    if (textured) {
      lamp["emissiveFactor"] = {1.0, 0.5, 1.0};
      lamp["emissiveTexture"] = {{"index", addUniformTexture(b, {200, 100, 50})}};
    } else {
      lamp["emissiveFactor"] = {r, 0.5 * g, bl};
    }
    b.doc["extensionsUsed"] = json::array({"KHR_materials_emissive_strength"});
    const int lampMaterial = addMaterial(b, lamp);
    const int floorMaterial = addMaterial(
        b, {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.7}}}});
    // The floor (y = -1, facing up) and the lamp above it, facing down and tilted towards the
    // camera (60 degrees about x from +z) so that it is seen too.
    b.scene({addSquare(b, floorMaterial,
                       {{"translation", {0, -1, 0}},
                        {"rotation", {-std::sin(0.7854), 0, 0, std::cos(0.7854)}},
                        {"scale", {3, 3, 1}}}),
             addSquare(b, lampMaterial,
                       {{"translation", {0, 1.2, 0}},
                        {"rotation", {std::sin(0.5236), 0, 0, std::cos(0.5236)}},
                        {"scale", {0.5, 0.5, 1}}}),
             addCamera(b, 5.0, 0.7)});
    return b;
  };
  expectSameImage(renderCpuImage(scene(true), 32, 16), renderCpuImage(scene(false), 32, 16));
}

// A lamp whose emissive texture is white on its left half and black on its right lights a
// floor as a lamp of its left half alone does: light sampling reads the texture at the point
// it samples (strategy "nee"), as BSDF sampling does at the point it finds ("bsdf").
TEST(GltfTextures, EmissiveTextureIsSampledWhereItEmits) {
  const auto scene = [](bool textured) {
    GltfBuilder b;
    const json black = {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}}};
    json lamp = black;
    lamp["emissiveFactor"] = {1.0, 1.0, 1.0};
    if (textured) {
      lamp["emissiveTexture"] = {{"index", addTexture(b, png(2, 1, 3, {255, 255, 255, 0, 0, 0}))}};
    }
    const int lampMaterial = addMaterial(b, lamp);
    const int blackMaterial = addMaterial(b, black);
    const int floorMaterial = addMaterial(
        b, {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}});
    // The floor faces +z; the lamp, 1 above it, faces it (half a turn about x keeps its u along
    // +x). Without the texture the lamp is two squares: the left emits, the right is black.
    const json down = {1, 0, 0, 0};
    std::vector<int> roots = {addSquare(b, floorMaterial, {{"scale", {3, 3, 1}}}),
                              addCamera(b, 8.0, 0.5)};
    if (textured) {
      roots.push_back(
          addSquare(b, lampMaterial,
                    {{"translation", {0, 0, 1}}, {"rotation", down}, {"scale", {0.5, 0.5, 1}}}));
    } else {
      roots.push_back(addSquare(
          b, lampMaterial,
          {{"translation", {-0.25, 0, 1}}, {"rotation", down}, {"scale", {0.25, 0.5, 1}}}));
      roots.push_back(addSquare(
          b, blackMaterial,
          {{"translation", {0.25, 0, 1}}, {"rotation", down}, {"scale", {0.25, 0.5, 1}}}));
    }
    b.scene(roots);
    return b;
  };
  for (uint strategy : {kStrategyNee, kStrategyBsdf}) {
    const Image textured =
        renderCpuImage(scene(true), 24, 64, RenderSettings{.strategy = strategy});
    const Image half = renderCpuImage(scene(false), 24, 64, RenderSettings{.strategy = strategy});
    const vec3 a = meanOf(textured, 0, 0, 24, 24), h = meanOf(half, 0, 0, 24, 24);
    EXPECT_GT(h.x, 0.01f);
    EXPECT_NEAR(a.x, h.x, 0.03f * h.x) << "strategy " << strategy;
  }
}

// The frame of the normal map: (0.5, 0.5, 1) is the normal itself; a tilt along x goes along
// dp/du, along y along dp/dv (up the image), scaled by `scale`, and the bitangent follows dp/dv
// where the texture coordinates are mirrored.
TEST(GltfTextures, NormalMapFrame) {
  TriangleDerivatives d;
  d.dpdu = vec3(2.0f, 0.0f, 0.3f);  // not perpendicular to the normal: made so
  d.dpdv = vec3(0.0f, 1.0f, 0.0f);
  d.determinant = 1.0f;
  TextureNode node{};
  node.type = kTextureConstant;
  node.count = 1;
  const vec3 ns(0.0f, 0.0f, 1.0f);
  vec4 vertexTangent(0.0f);  // none: the frame of dp/du and dp/dv
  const auto mapped = [&](vec3 c, float scale, TriangleDerivatives der) {
    node.value = c;
    TextureTables tables;
    tables.nodes = &node;
    return normalMappedNormal(tables, 0u, scale, der, vertexTangent, pointFootprint(vec2(0.0f)),
                              ns);
  };
  const vec3 same = mapped(vec3(0.5f, 0.5f, 1.0f), 1.0f, d);
  EXPECT_NEAR(glm::length(same - ns), 0.0f, 1e-7f);
  const float s = std::sin(0.5f), c = std::cos(0.5f);
  const vec3 tiltX = mapped(vec3(0.5f + 0.5f * s, 0.5f, 0.5f + 0.5f * c), 1.0f, d);
  EXPECT_NEAR(glm::length(tiltX - vec3(s, 0.0f, c)), 0.0f, 1e-6f);
  const vec3 tiltY = mapped(vec3(0.5f, 0.5f + 0.5f * s, 0.5f + 0.5f * c), 1.0f, d);
  EXPECT_NEAR(glm::length(tiltY - vec3(0.0f, s, c)), 0.0f, 1e-6f);
  // scale 2: x and y doubled before the normalization.
  const vec3 scaled = mapped(vec3(0.5f, 0.5f + 0.5f * s, 0.5f + 0.5f * c), 2.0f, d);
  EXPECT_NEAR(glm::length(scaled - glm::normalize(vec3(0.0f, 2.0f * s, c))), 0.0f, 1e-6f);
  TriangleDerivatives mirrored = d;
  mirrored.dpdv = vec3(0.0f, -1.0f, 0.0f);
  const vec3 flipped = mapped(vec3(0.5f, 0.5f + 0.5f * s, 0.5f + 0.5f * c), 1.0f, mirrored);
  EXPECT_NEAR(glm::length(flipped - vec3(0.0f, -s, c)), 0.0f, 1e-6f);
  // A vertex tangent along +y (not perpendicular to the normal: made so) replaces dp/du; the
  // bitangent is N x T = -x times w.
  vertexTangent = vec4(0.0f, 2.0f, -0.5f, 1.0f);
  const vec3 alongT = mapped(vec3(0.5f + 0.5f * s, 0.5f, 0.5f + 0.5f * c), 1.0f, d);
  EXPECT_NEAR(glm::length(alongT - vec3(0.0f, s, c)), 0.0f, 1e-6f);
  const vec3 alongB = mapped(vec3(0.5f, 0.5f + 0.5f * s, 0.5f + 0.5f * c), 1.0f, d);
  EXPECT_NEAR(glm::length(alongB - vec3(-s, 0.0f, c)), 0.0f, 1e-6f);
  vertexTangent.w = -1.0f;
  const vec3 alongMinusB = mapped(vec3(0.5f, 0.5f + 0.5f * s, 0.5f + 0.5f * c), 1.0f, d);
  EXPECT_NEAR(glm::length(alongMinusB - vec3(s, 0.0f, c)), 0.0f, 1e-6f);
}

// Tangents packed in a word (TriangleNormals::tangent*) come back within 2e-4 radians, with
// their bitangent's sign; zero is no tangent.
TEST(GltfTextures, PackedTangentsRoundTrip) {
  for (int i = 0; i < 200; ++i) {
    const float a = 0.37f * float(i), z = -1.0f + 2.0f * (float(i) + 0.5f) / 200.0f;
    const float r = std::sqrt(1.0f - z * z);
    const vec3 t(r * std::cos(a), r * std::sin(a), z);
    const float w = i % 2 == 0 ? 1.0f : -1.0f;
    const uint packed = packTangent(3.0f * t, w);
    ASSERT_NE(packed, 0u);
    EXPECT_LT(glm::length(unpackTangent(packed) - t), 2e-4f) << i;  // the chord: the angle
    TriangleNormals n{};
    n.tangent0 = n.tangent1 = n.tangent2 = packed;
    EXPECT_EQ(interpolatedTangent(n, vec3(0.2f, 0.3f, 0.5f)).w, w);
  }
  for (const vec3 axis : {vec3(1, 0, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1)}) {
    EXPECT_EQ(unpackTangent(packTangent(axis, 1.0f)), axis);
  }
  EXPECT_EQ(packTangent(vec3(0.0f), 1.0f), 0u);
  EXPECT_EQ(interpolatedTangent(TriangleNormals{}, vec3(1, 0, 0)), vec4(0.0f));
}

// A square with a normal map lit by a directional light and seen from afar renders as the
// square turned so that its normal is the map's (computed by hand from the texel's bytes), and
// unlike the flat square; a map of the up normal (128, 128, 255: 0.4 % off) as no map.
TEST(GltfTextures, NormalMapTiltsTheShadingAsTheTurnedSurface) {
  const std::vector<std::uint8_t> tilt = {128, 191, 238};
  const auto scene = [](const std::vector<std::uint8_t>* map, glm::dvec3 turnTo) {
    GltfBuilder b;
    json material = {{"pbrMetallicRoughness",
                      {{"baseColorFactor", {0.8, 0.8, 0.8, 1}},
                       {"metallicFactor", 0.0},
                       {"roughnessFactor", 0.5}}}};
    if (map != nullptr) material["normalTexture"] = {{"index", addUniformTexture(b, *map)}};
    const int m = addMaterial(b, material);
    b.scene({addSquare(b, m, {{"rotation", rotationTaking(glm::dvec3(0, 0, 1), turnTo)}}),
             addCamera(b, 200.0, 0.002), addDirectionalLight(b, glm::dvec3(0.3, -1, -0.6), 2.0)});
    return b;
  };
  // The map's normal: 2 c - 1 of the bytes decoded linearly, in the frame (+x, +y, +z).
  const glm::dvec3 n(2.0 * tilt[0] / 255.0 - 1.0, 2.0 * tilt[1] / 255.0 - 1.0,
                     2.0 * tilt[2] / 255.0 - 1.0);
  const Image mapped = renderCpuImage(scene(&tilt, glm::dvec3(0, 0, 1)), 8, 16);
  const Image turned = renderCpuImage(scene(nullptr, n), 8, 16);
  const Image flat = renderCpuImage(scene(nullptr, glm::dvec3(0, 0, 1)), 8, 16);
  const vec3 a = meanOf(mapped, 2, 2, 6, 6), t = meanOf(turned, 2, 2, 6, 6),
             f = meanOf(flat, 2, 2, 6, 6);
  EXPECT_NEAR(a.x, t.x, 0.01f * t.x);
  EXPECT_GT(std::abs(a.x - f.x), 0.1f * f.x);
  const std::vector<std::uint8_t> up = {128, 128, 255};
  const vec3 u = meanOf(renderCpuImage(scene(&up, glm::dvec3(0, 0, 1)), 8, 16), 2, 2, 6, 6);
  EXPECT_NEAR(u.x, f.x, 0.01f * f.x);
}

// With a TANGENT along +y (w 1: the bitangent N x T = -x), the map's x tilts the normal towards
// +y and its y towards -x: the square renders as the one turned to (-y, x, z) of the map's
// (x, y, z); with w -1, to (y, x, z). The reader packs the tangents, and a mirroring node turns
// their sign.
TEST(GltfTextures, NormalMapUsesTheTangentAttribute) {
  const std::vector<std::uint8_t> tilt = {191, 150, 238};
  const auto scene = [&](bool mapped, glm::dvec3 turnTo, float w) {
    GltfBuilder b;
    json material = {{"pbrMetallicRoughness",
                      {{"baseColorFactor", {0.8, 0.8, 0.8, 1}},
                       {"metallicFactor", 0.0},
                       {"roughnessFactor", 0.5}}}};
    if (mapped) material["normalTexture"] = {{"index", addUniformTexture(b, tilt)}};
    const int m = addMaterial(b, material);
    b.scene({addSquare(b, m, {{"rotation", rotationTaking(glm::dvec3(0, 0, 1), turnTo)}},
                       mapped ? glm::vec4(0, 1, 0, w) : glm::vec4(0.0f)),
             addCamera(b, 200.0, 0.002), addDirectionalLight(b, glm::dvec3(0.3, -1, -0.6), 2.0)});
    return b;
  };
  const glm::dvec3 t(2.0 * tilt[0] / 255.0 - 1.0, 2.0 * tilt[1] / 255.0 - 1.0,
                     2.0 * tilt[2] / 255.0 - 1.0);
  for (float w : {1.0f, -1.0f}) {
    const glm::dvec3 expected = w > 0 ? glm::dvec3(-t.y, t.x, t.z) : glm::dvec3(t.y, t.x, t.z);
    const vec3 a = meanOf(renderCpuImage(scene(true, glm::dvec3(0, 0, 1), w), 8, 16), 2, 2, 6, 6);
    const vec3 e = meanOf(renderCpuImage(scene(false, expected, w), 8, 16), 2, 2, 6, 6);
    EXPECT_NEAR(a.x, e.x, 0.01f * e.x) << "w " << w;
  }
  // The packed tangents, and a mirroring node's.
  GltfBuilder b = scene(true, glm::dvec3(0, 0, 1), 1.0f);
  b.doc["nodes"][0]["scale"] = {-1, 1, 1};
  const Scene mirrored = loadGltfSceneBytes(b.gltf(), "test.gltf");
  ASSERT_FALSE(mirrored.normals.empty());
  const vec4 tm = interpolatedTangent(mirrored.normals[0], vec3(1, 0, 0));
  EXPECT_NEAR(glm::length(vec3(tm) - vec3(0, 1, 0)), 0.0f, 1e-4f);
  EXPECT_EQ(tm.w, -1.0f);
}

// A black square whose base colour texture's alpha is 0.2 on the left half and 0.8 on the right,
// before the white sky: MASK (cut-off 0.5) shows the sky (radiance 1) through the left half;
// OPAQUE ignores alpha.
TEST(GltfTextures, MaskCutsOutWhereAlphaIsBelowTheCutoff) {
  const auto scene = [](const char* mode) {
    GltfBuilder b;
    const int t = addTexture(b, png(2, 1, 4, {0, 0, 0, 51, 0, 0, 0, 204}));
    const int m = addMaterial(b, {{"alphaMode", mode},
                                  {"pbrMetallicRoughness",
                                   {{"baseColorTexture", {{"index", t}}},
                                    {"metallicFactor", 0.0},
                                    {"roughnessFactor", 1.0}}}});
    b.scene({addSquare(b, m), addCamera(b, 3.0, 0.5)});
    return b;
  };
  const Image mask = renderCpuImage(scene("MASK"), 16, 4);
  const Image opaque = renderCpuImage(scene("OPAQUE"), 16, 4);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      if (x < 8) {
        EXPECT_NEAR(mask.at(x, y).x, 1.0f, 1e-5f) << x << ", " << y;
      } else {
        EXPECT_LT(mask.at(x, y).x, 0.3f) << x << ", " << y;
      }
      EXPECT_LT(opaque.at(x, y).x, 0.3f) << x << ", " << y;
    }
  }
}

// BLEND at alpha 0.25 (the factor's, no texture) passes three quarters of the rays: the square
// before the white sky shows 0.75 of the sky plus a quarter of the opaque square's reflection.
TEST(GltfTextures, BlendPassesOneMinusAlpha) {
  const auto scene = [](const char* mode) {
    GltfBuilder b;
    const int m = addMaterial(b, {{"alphaMode", mode},
                                  {"pbrMetallicRoughness",
                                   {{"baseColorFactor", {0, 0, 0, 0.25}},
                                    {"metallicFactor", 0.0},
                                    {"roughnessFactor", 1.0}}}});
    b.scene({addSquare(b, m), addCamera(b, 3.0, 0.5)});
    return b;
  };
  const float blend = meanOf(renderCpuImage(scene("BLEND"), 16, 64), 0, 0, 16, 16).x;
  const float opaque = meanOf(renderCpuImage(scene("OPAQUE"), 16, 64), 0, 0, 16, 16).x;
  EXPECT_LT(opaque, 0.3f);
  EXPECT_NEAR(blend, 0.75f + 0.25f * opaque, 0.01f);
}

// What the reader makes of each texture and alpha mode: the slots of MaterialTextures, the
// constant alpha of a factor without a texture, and the errors of the transform's fields.
TEST(GltfTextures, MaterialTextureSlotsAndAlphaModes) {
  GltfBuilder b;
  const int rgb = addUniformTexture(b, {10, 20, 30});
  const int rgba = addUniformTexture(b, {10, 20, 30, 100});
  const std::vector<json> materials = {
      {{"pbrMetallicRoughness", {{"metallicRoughnessTexture", {{"index", rgb}}}}},
       {"normalTexture", {{"index", rgb}, {"scale", 0.5}}},
       {"emissiveFactor", {1, 1, 1}},
       {"emissiveTexture", {{"index", rgb}}}},
      {{"alphaMode", "MASK"},
       {"alphaCutoff", 0.3},
       {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", rgba}}}}}},
      {{"alphaMode", "MASK"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.4}}}}},
      {{"alphaMode", "MASK"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.6}}}}},
      {{"alphaMode", "BLEND"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.6}}}}},
      {{"alphaMode", "BLEND"},
       {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", rgb}}}}}},  // no alpha channel
      {{"alphaMode", "OPAQUE"},
       {"pbrMetallicRoughness",
        {{"baseColorFactor", {1, 1, 1, 0.1}}, {"baseColorTexture", {{"index", rgba}}}}}},
      {{"emissiveTexture", {{"index", rgb}}}},  // emissiveFactor 0: nothing to texture
  };
  std::vector<int> roots;
  for (const json& m : materials) roots.push_back(addSquare(b, addMaterial(b, m)));
  b.scene(roots);
  const Scene scene = loadGltfSceneBytes(b.gltf(), "test.gltf");
  EXPECT_TRUE(scene.warnings.empty());
  ASSERT_EQ(scene.materialTextures.size(), materials.size());
  const auto& t = scene.materialTextures;
  EXPECT_NE(t[0].uRoughness, kNoTexture);
  EXPECT_EQ(t[0].vRoughness, t[0].uRoughness);
  EXPECT_EQ(t[0].flags, kSquareRoughness);
  EXPECT_NE(t[0].thickness, kNoTexture);
  EXPECT_NE(t[0].emission, kNoTexture);
  EXPECT_NE(t[0].normalMap, kNoTexture);
  EXPECT_EQ(t[0].normalScale, 0.5f);
  EXPECT_EQ(t[0].alpha, kNoTexture);
  EXPECT_NE(t[1].alpha, kNoTexture);
  EXPECT_EQ(t[1].flags, kAlphaCutoff);
  EXPECT_EQ(t[1].alphaCutoff, 0.3f);
  ASSERT_NE(t[2].alpha, kNoTexture);  // 0.4 below the default cut-off 0.5: cut away
  EXPECT_EQ(scene.textureNodes[t[2].alpha].value, vec3(0.0f));
  EXPECT_EQ(t[3].alpha, kNoTexture);  // 0.6 above it: whole
  ASSERT_NE(t[4].alpha, kNoTexture);
  EXPECT_EQ(scene.textureNodes[t[4].alpha].value, vec3(0.6f));
  EXPECT_EQ(t[4].flags, 0u);
  EXPECT_EQ(t[5].alpha, kNoTexture);
  EXPECT_EQ(t[6].alpha, kNoTexture);
  EXPECT_EQ(t[7].emission, kNoTexture);
  // The transform's fields.
  const auto errorOf = [&](const json& transform) {
    GltfBuilder e = b;
    e.doc["materials"][0]["normalTexture"]["extensions"]["KHR_texture_transform"] = transform;
    try {
      loadGltfSceneBytes(e.gltf(), "test.gltf");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  EXPECT_EQ(errorOf({{"rotation", "a"}}),
            "test.gltf: materials[0].normalTexture.extensions.KHR_texture_transform.rotation: "
            "expected a number");
  EXPECT_EQ(errorOf({{"texCoord", -1}}),
            "test.gltf: materials[0].normalTexture.extensions.KHR_texture_transform.texCoord: "
            "expected a non-negative integer");
  EXPECT_EQ(errorOf({{"scale", {1}}}),
            "test.gltf: materials[0].normalTexture.extensions.KHR_texture_transform.scale: "
            "expected 2 numbers");
}

// A texture of texCoord 1 (or KHR_texture_transform's texCoord 1) reads TEXCOORD_1: a square
// whose TEXCOORD_0 is all zeros and TEXCOORD_1 its corners renders as the square of
// TEXCOORD_0 and texCoord 0. A material whose textures read both sets keeps the first one's
// (the other texture left out, warned).
TEST(GltfTextures, SecondTextureCoordinateSet) {
  const auto scene = [](int set, bool byTransform, bool mixed) {
    GltfBuilder b;
    const int t = addTexture(b, png(2, 1, 3, {250, 200, 100, 10, 20, 30}));
    json info = {{"index", t}};
    if (set == 1 && byTransform) {
      info["extensions"]["KHR_texture_transform"] = {{"texCoord", 1}};
      b.doc["extensionsUsed"] = json::array({"KHR_texture_transform"});
    } else {
      info["texCoord"] = set;
    }
    json pbr = {{"baseColorTexture", info}, {"metallicFactor", 0.0}};
    if (mixed) pbr["metallicRoughnessTexture"] = {{"index", t}, {"texCoord", 1 - set}};
    const int m = addMaterial(b, {{"pbrMetallicRoughness", pbr}});
    const int p = b.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3", 3);
    const int corners = b.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
    const int zeros = b.floats({0, 0, 0, 0, 0, 0, 0, 0}, "VEC2", 2);
    const std::vector<std::uint16_t> idx = {0, 1, 2, 0, 2, 3};
    const int i = b.accessor(b.view(idx), GltfBuilder::kUShort, idx.size(), "SCALAR");
    json attributes = {{"POSITION", p},
                       {"TEXCOORD_0", set == 0 ? corners : zeros},
                       {"TEXCOORD_1", set == 0 ? zeros : corners}};
    const int mesh =
        b.mesh(json::array({{{"attributes", attributes}, {"indices", i}, {"material", m}}}));
    b.scene({b.node({{"mesh", mesh}}), addCamera(b, 3.0, 0.5)});
    return b;
  };
  const Image reference = renderCpuImage(scene(0, false, false), 16, 4);
  EXPECT_GT(reference.at(2, 8).x, 2.0f * reference.at(13, 8).x);  // the texture is read
  for (bool byTransform : {false, true}) {
    const Image second = renderCpuImage(scene(1, byTransform, false), 16, 4);
    for (size_t k = 0; k < second.pixels.size(); ++k) {
      EXPECT_EQ(second.pixels[k], reference.pixels[k]) << k;
    }
  }
  const Scene mixed = loadGltfSceneBytes(scene(1, false, true).gltf(), "test.gltf");
  ASSERT_EQ(mixed.warnings.size(), 1u);
  EXPECT_EQ(mixed.warnings[0],
            "test.gltf: materials[0].pbrMetallicRoughness.metallicRoughnessTexture.texCoord: the "
            "material's textures read different texture coordinate sets, and the renderer keeps "
            "one per triangle (TEXCOORD_1): the texture is left out");
  EXPECT_EQ(mixed.materialTextures[0].uRoughness, kNoTexture);
  EXPECT_NE(mixed.materialTextures[0].reflectance, kNoTexture);
}

// KHR_texture_transform's offset, rotation and scale: the texel the renderer reads at a point
// is the one the extension's matrix T R S (columns cos r, sin r and -sin r, cos r) picks from
// glTF's coordinates there (v down the image), on a 4 x 4 image of distinct texels.
TEST(GltfTextures, TextureTransformRotatesAsTheExtensionsMatrix) {
  GltfBuilder b;
  std::vector<std::uint8_t> texels;
  for (int i = 0; i < 16; ++i) texels.insert(texels.end(), {std::uint8_t(16 * i), 7, 9});
  const int t = addTexture(b, png(4, 4, 3, texels));
  const double r = 0.3, su = 1.2, sv = 0.8, ou = 0.1, ov = 0.05;
  const int m =
      addMaterial(b, {{"pbrMetallicRoughness",
                       {{"baseColorTexture",
                         {{"index", t},
                          {"extensions",
                           {{"KHR_texture_transform",
                             {{"offset", {ou, ov}}, {"rotation", r}, {"scale", {su, sv}}}}}}}}}}});
  b.doc["extensionsUsed"] = json::array({"KHR_texture_transform"});
  b.scene({addSquare(b, m)});
  const Scene scene = loadGltfSceneBytes(b.gltf(), "test.gltf");
  ASSERT_EQ(scene.materialTextures.size(), 1u);
  TextureTables tables;
  tables.nodes = scene.textureNodes.data();
  tables.words = scene.imageWords.data();
  const uint texture = scene.materialTextures[0].reflectance;
  ASSERT_NE(texture, kNoTexture);
  int checked = 0;
  for (int i = 0; i < 40; ++i) {
    const double u = 0.05 + 0.023 * i, v = 0.9 - 0.021 * i;
    const double u2 = su * std::cos(r) * u - sv * std::sin(r) * v + ou;
    const double v2 = su * std::sin(r) * u + sv * std::cos(r) * v + ov;
    if (!(u2 > 0.0 && u2 < 1.0 && v2 > 0.0 && v2 < 1.0)) continue;
    // Away from texel edges, where float rounding could pick the neighbour.
    if (std::abs(u2 * 4 - std::round(u2 * 4)) < 0.01 ||
        std::abs(v2 * 4 - std::round(v2 * 4)) < 0.01) {
      continue;
    }
    const int index = int(v2 * 4) * 4 + int(u2 * 4);
    const vec3 value = evalTexture(tables, texture, vec2(float(u), float(1.0 - v)));
    EXPECT_NEAR(value.x, srgbToLinear(float(16 * index) / 255.0f), 1e-6f) << u << ", " << v;
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

// Every texture of the material at once (metallic-roughness, normal and emissive textures, a
// normal map in the frame of a TANGENT attribute, a MASK cut-out and a BLEND square), on both
// backends.
TEST(GltfTextures, TexturedSceneAgreesOnBothBackends) {
  GltfBuilder b;
  std::vector<std::uint8_t> mr, normals, emissive, rgba;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      mr.insert(mr.end(), {0, std::uint8_t(30 + 28 * x), std::uint8_t(255 - 30 * y)});
      normals.insert(normals.end(),
                     {std::uint8_t(128 + 12 * (x - 4)), std::uint8_t(128 + 12 * (y - 4)), 230});
      emissive.insert(emissive.end(),
                      {std::uint8_t(255 * ((x + y) % 2)), 128, std::uint8_t(32 * x)});
      rgba.insert(rgba.end(),
                  {std::uint8_t(200), std::uint8_t(40 * (x % 4)), 90, std::uint8_t(32 * y + 16)});
    }
  }
  b.doc["extensionsUsed"] = json::array({"KHR_materials_emissive_strength"});
  const int mrTexture = addTexture(b, png(8, 8, 3, mr));
  const int normalTexture = addTexture(b, png(8, 8, 3, normals));
  const int emissiveTexture = addTexture(b, png(8, 8, 3, emissive));
  const int rgbaTexture = addTexture(b, png(8, 8, 4, rgba));
  const int sphereMaterial =
      addMaterial(b, {{"pbrMetallicRoughness",
                       {{"baseColorFactor", {0.9, 0.5, 0.3, 1}},
                        {"metallicRoughnessTexture", {{"index", mrTexture}}}}},
                      {"normalTexture", {{"index", normalTexture}, {"scale", 0.8}}}});
  const int lampMaterial = addMaterial(
      b, {{"emissiveFactor", {1, 1, 1}},
          {"emissiveTexture", {{"index", emissiveTexture}}},
          {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}}}});
  const int maskMaterial =
      addMaterial(b, {{"alphaMode", "MASK"},
                      {"alphaCutoff", 0.4},
                      {"pbrMetallicRoughness",
                       {{"baseColorTexture", {{"index", rgbaTexture}}}, {"metallicFactor", 0.0}}}});
  const int blendMaterial = addMaterial(b, {{"alphaMode", "BLEND"},
                                            {"pbrMetallicRoughness",
                                             {{"baseColorFactor", {0.3, 0.6, 0.9, 0.5}},
                                              {"baseColorTexture", {{"index", rgbaTexture}}},
                                              {"roughnessFactor", 0.4},
                                              {"metallicFactor", 0.0}}}});
  const int floorMaterial = addMaterial(
      b, {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}}});
  b.scene({addSphere(b, sphereMaterial, {{"translation", {0, 0, 0}}}),
           addSquare(b, lampMaterial,
                     {{"translation", {0, 3, 0}}, {"rotation", {0.7071068, 0, 0, 0.7071068}}}),
           addSquare(b, maskMaterial, {{"translation", {-1.6, 0, 1.5}}, {"scale", {0.6, 0.6, 1}}}),
           addSquare(b, blendMaterial, {{"translation", {1.6, 0, 1.5}}, {"scale", {0.6, 0.6, 1}}}),
           addSquare(b, floorMaterial,
                     {{"translation", {0, -1, 0}},
                      {"rotation", {-0.7071068, 0, 0, 0.7071068}},
                      {"scale", {5, 5, 1}}}),
           addSquare(b, sphereMaterial, {{"translation", {0, -0.4, 2}}, {"scale", {0.5, 0.3, 1}}},
                     glm::vec4(0.6f, 0.8f, 0.0f, -1.0f)),  // the normal map in its TANGENT frame
           addCamera(b, 7.0, 0.7)});
  Scene scene = loadGltfSceneBytes(b.gltf(), "textured.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  const SceneData data = prepareScene(std::move(scene), RenderSettings{.width = 40, .height = 40});
  const std::string effects = data.effects.toString();
  EXPECT_NE(effects.find("textures"), std::string::npos) << effects;
  EXPECT_NE(effects.find("alpha"), std::string::npos) << effects;
  const Comparison cmp = renderBoth(data, 8);
  expectAgreement(cmp);
}

}  // namespace
}  // namespace pt
