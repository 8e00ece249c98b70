// The textures of glTF's material extensions (host/scene/gltf/gltf_extension_textures.h):
// transmissionTexture (R), clearcoatTexture (R), clearcoatRoughnessTexture (G),
// clearcoatNormalTexture (RGB, linear, its scale), specularTexture (A), specularColorTexture (RGB,
// sRGB), sheenColorTexture (RGB, sRGB) and sheenRoughnessTexture (A), each times its factor, bound
// with its texture
// coordinate set and KHR_texture_transform as the core textures are; rendered as the factors
// they stand for where constant, and over the regions they cover where not, on both backends.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

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

// Two RGBA texels side by side (u 0 to 0.5, 0.5 to 1), every channel of each a different value.
const std::vector<std::uint8_t> kTwoTexels = {40, 80, 120, 160, 200, 220, 240, 250};

vec3 extensionTextureAt(const Scene& scene, uint texture, float s) {
  TextureTables tables;
  tables.nodes = scene.textureNodes.data();
  tables.words = scene.imageWords.data();
  return evalTexture(tables, texture, vec2(s, 0.5f));
}

float byteValue(std::uint8_t c) {
  return float(c) / 255.0f;
}

// Every extension texture of one material, each bound to its parameter with its channel times
// its factor (the coat's normal map as read, its scale apart); nothing warned (the volume's
// thicknessTexture is ignored by design).
TEST(GltfExtensionTextures, EachIsBoundWithItsChannelTimesItsFactor) {
  GltfBuilder b;
  const int t = test::addTexture(b, test::png(2, 1, 4, kTwoTexels));
  const json info = {{"index", t}};
  const int m = test::addMaterial(
      b, {{"extensions",
           {{"KHR_materials_transmission",
             {{"transmissionFactor", 0.5}, {"transmissionTexture", info}}},
            {"KHR_materials_volume", {{"thicknessFactor", 1.0}, {"thicknessTexture", info}}},
            {"KHR_materials_clearcoat",
             {{"clearcoatFactor", 0.8},
              {"clearcoatTexture", info},
              {"clearcoatRoughnessFactor", 0.6},
              {"clearcoatRoughnessTexture", info},
              {"clearcoatNormalTexture", {{"index", t}, {"scale", 0.7}}}}},
            {"KHR_materials_specular",
             {{"specularFactor", 0.9},
              {"specularTexture", info},
              {"specularColorFactor", {2.0, 1.0, 0.5}},
              {"specularColorTexture", info}}},
            {"KHR_materials_sheen",
             {{"sheenColorFactor", {0.9, 0.6, 0.3}},
              {"sheenColorTexture", info},
              {"sheenRoughnessFactor", 0.4},
              {"sheenRoughnessTexture", info}}}}}});
  b.scene({test::addSquare(b, m)});
  const Scene scene = loadGltfSceneBytes(b.gltf(), "test.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  ASSERT_EQ(scene.materialTextures.size(), 1u);
  const MaterialTextures& mt = scene.materialTextures[0];
  for (uint texture : {mt.transmission, mt.clearcoat, mt.clearcoatRoughness, mt.specular,
                       mt.specularColour, mt.sheenColour, mt.sheenRoughness, mt.clearcoatNormal}) {
    ASSERT_NE(texture, kNoTexture);
  }
  EXPECT_EQ(mt.scale, 0.7f);  // the coat normal map's scale
  EXPECT_EQ(mt.normalMap, kNoTexture);
  for (int texel : {0, 1}) {
    const float s = texel == 0 ? 0.25f : 0.75f;
    const std::uint8_t* c = &kTwoTexels[std::size_t(4 * texel)];
    EXPECT_NEAR(extensionTextureAt(scene, mt.transmission, s).x, 0.5f * byteValue(c[0]), 1e-6f);
    EXPECT_NEAR(extensionTextureAt(scene, mt.clearcoat, s).x, 0.8f * byteValue(c[0]), 1e-6f);
    EXPECT_NEAR(extensionTextureAt(scene, mt.clearcoatRoughness, s).x, 0.6f * byteValue(c[1]),
                1e-6f);
    EXPECT_NEAR(extensionTextureAt(scene, mt.specular, s).x, 0.9f * byteValue(c[3]), 1e-6f);
    const vec3 colour = extensionTextureAt(scene, mt.specularColour, s);
    EXPECT_NEAR(colour.x, 2.0f * srgbToLinear(byteValue(c[0])), 1e-6f);
    EXPECT_NEAR(colour.y, 1.0f * srgbToLinear(byteValue(c[1])), 1e-6f);
    EXPECT_NEAR(colour.z, 0.5f * srgbToLinear(byteValue(c[2])), 1e-6f);
    const vec3 sheen = extensionTextureAt(scene, mt.sheenColour, s);
    EXPECT_NEAR(sheen.x, 0.9f * srgbToLinear(byteValue(c[0])), 1e-6f);
    EXPECT_NEAR(sheen.y, 0.6f * srgbToLinear(byteValue(c[1])), 1e-6f);
    EXPECT_NEAR(sheen.z, 0.3f * srgbToLinear(byteValue(c[2])), 1e-6f);
    EXPECT_NEAR(extensionTextureAt(scene, mt.sheenRoughness, s).x, 0.4f * byteValue(c[3]), 1e-6f);
    const vec3 normal = extensionTextureAt(scene, mt.clearcoatNormal, s);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(normal[k], byteValue(c[k]), 1e-6f) << k;
  }
  // The factors stay in the material: a texture multiplies them, it does not replace them.
  const Material& material = scene.materials[0];
  EXPECT_EQ(material.transmittance.x, 0.5f);
  EXPECT_EQ(material.eta.y, 0.9f);
  EXPECT_NE(material.nSamples & kGltfSheen, 0u);
  EXPECT_EQ(gltfSheenColour(material), vec3(0.9f, 0.6f, 0.3f));
  EXPECT_NEAR(gltfSheenRoughness(material), 0.4f, 1e-5f);
  // The sheen textures and the coat's normal are what the shader compiles in for the scene.
  const uint features =
      prepareScene(Scene(scene), RenderSettings{.width = 8, .height = 8}).effects.textureFeatures;
  EXPECT_NE(features & kTextureUsesGltfSheen, 0u);
  EXPECT_NE(features & kTextureUsesCoatNormal, 0u);
}

// A specular texture without an alpha channel is the factor alone (the specification's alpha of
// 1), and a texture whose factor is 0 is not read.
TEST(GltfExtensionTextures, NoAlphaOrAZeroFactorLeavesTheFactor) {
  GltfBuilder b;
  const int rgb = test::addTexture(b, test::png(1, 1, 3, {10, 20, 30}));
  const int m = test::addMaterial(
      b, {{"extensions",
           {{"KHR_materials_specular", {{"specularTexture", {{"index", rgb}}}}},
            {"KHR_materials_clearcoat",
             {{"clearcoatFactor", 0.0}, {"clearcoatTexture", {{"index", rgb}}}}}}}});
  b.scene({test::addSquare(b, m)});
  const Scene scene = loadGltfSceneBytes(b.gltf(), "test.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  EXPECT_TRUE(scene.materialTextures.empty());
}

// texCoord 1 (or KHR_texture_transform's texCoord 1) makes the material's triangles keep
// TEXCOORD_1; KHR_texture_transform's offset and scale move the texel read; a texture of the
// other set than the material's first is left out, warned.
TEST(GltfExtensionTextures, TexCoordAndTransformAsTheCoreTextures) {
  const auto read = [](const json& colourInfo, const json& pbr) {
    GltfBuilder b;
    const int t = test::addTexture(b, test::png(2, 1, 4, kTwoTexels));
    json info = colourInfo;
    info["index"] = t;
    json material = {
        {"extensions",
         {{"KHR_materials_specular",
           {{"specularColorFactor", {1.0, 1.0, 1.0}}, {"specularColorTexture", info}}}}}};
    if (!pbr.empty()) {
      json p = pbr;
      p["baseColorTexture"]["index"] = t;
      material["pbrMetallicRoughness"] = p;
    }
    const int m = test::addMaterial(b, material);
    const int p = b.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3", 3);
    const int corners = b.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
    const int zeros = b.floats({0, 0, 0, 0, 0, 0, 0, 0}, "VEC2", 2);
    const std::vector<std::uint16_t> idx = {0, 1, 2, 0, 2, 3};
    const int i = b.accessor(b.view(idx), GltfBuilder::kUShort, idx.size(), "SCALAR");
    const json attributes = {{"POSITION", p}, {"TEXCOORD_0", zeros}, {"TEXCOORD_1", corners}};
    b.scene({b.node(
        {{"mesh",
          b.mesh(json::array({{{"attributes", attributes}, {"indices", i}, {"material", m}}}))}})});
    b.doc["extensionsUsed"] = json::array({"KHR_texture_transform"});
    return loadGltfSceneBytes(b.gltf(), "test.gltf");
  };
  const vec3 left(srgbToLinear(byteValue(40)), srgbToLinear(byteValue(80)),
                  srgbToLinear(byteValue(120)));
  const vec3 right(srgbToLinear(byteValue(200)), srgbToLinear(byteValue(220)),
                   srgbToLinear(byteValue(240)));
  for (const json& info : {json{{"texCoord", 1}},
                           json{{"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}}}) {
    const Scene s = read(info, json::object());
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    ASSERT_EQ(s.uvs.size(), 2u);
    EXPECT_NE(s.uvs[0].uv0, s.uvs[0].uv1) << info.dump();  // TEXCOORD_1's corners, not zeros
    ASSERT_NE(s.materialTextures[0].specularColour, kNoTexture);
    EXPECT_LT(
        glm::length(extensionTextureAt(s, s.materialTextures[0].specularColour, 0.25f) - left),
        1e-6f);
  }
  // u' = 0.5 u + 0.5: the left half of the square reads the right texel.
  const Scene moved = read(
      {{"texCoord", 0},
       {"extensions", {{"KHR_texture_transform", {{"offset", {0.5, 0}}, {"scale", {0.5, 1}}}}}}},
      json::object());
  EXPECT_TRUE(moved.warnings.empty()) << moved.warnings.front();
  EXPECT_LT(glm::length(extensionTextureAt(moved, moved.materialTextures[0].specularColour, 0.25f) -
                        right),
            1e-6f);
  const Scene mixed = read({{"texCoord", 1}}, {{"baseColorTexture", {{"texCoord", 0}}}});
  ASSERT_EQ(mixed.warnings.size(), 1u);
  EXPECT_EQ(mixed.warnings[0],
            "test.gltf: materials[0].extensions.KHR_materials_specular.specularColorTexture."
            "texCoord: the material's textures read different texture coordinate sets, and the "
            "renderer keeps one per triangle (TEXCOORD_0): the texture is left out");
  EXPECT_EQ(mixed.materialTextures[0].specularColour, kNoTexture);
  EXPECT_NE(mixed.materialTextures[0].reflectance, kNoTexture);
}

// Three spheres: thin-walled transmission, a clear coat, KHR_materials_specular; lit by a
// directional light and the sky behind, over a floor. `textured`: each extension's parameters
// by a uniform texture of one texel (153, 51, 204, 102) times a factor, else by the product as
// the factor.
SceneData layeredSpheres(bool textured) {
  GltfBuilder b;
  const float r = 153.0f / 255.0f, g = 51.0f / 255.0f, a = 102.0f / 255.0f;
  const vec3 srgb(srgbToLinear(r), srgbToLinear(g), srgbToLinear(204.0f / 255.0f));
  const int t = textured ? test::addUniformTexture(b, {153, 51, 204, 102}) : -1;
  const auto material = [&](vec3 base, double roughness, json extensions) {
    return test::addMaterial(b, {{"pbrMetallicRoughness",
                                  {{"baseColorFactor", {base.x, base.y, base.z, 1.0}},
                                   {"metallicFactor", 0.0},
                                   {"roughnessFactor", roughness}}},
                                 {"extensions", extensions}});
  };
  const json info = {{"index", t}};
  json transmission = {{"transmissionFactor", textured ? 0.9 : 0.9 * r}};
  json clearcoat = {{"clearcoatFactor", textured ? 1.0 : r},
                    {"clearcoatRoughnessFactor", textured ? 1.0 : g}};
  json specular = {
      {"specularFactor", textured ? 0.9 : 0.9 * a},
      {"specularColorFactor", textured ? json{1.0, 0.5, 1.0} : json{srgb.x, 0.5 * srgb.y, srgb.z}}};
  if (textured) {
    transmission["transmissionTexture"] = info;
    clearcoat["clearcoatTexture"] = info;
    clearcoat["clearcoatRoughnessTexture"] = info;
    specular["specularTexture"] = info;
    specular["specularColorTexture"] = info;
  }
  const int glass =
      material(vec3(0.9f, 0.8f, 0.7f), 0.3, {{"KHR_materials_transmission", transmission}});
  const int coated =
      material(vec3(0.8f, 0.1f, 0.1f), 0.7, {{"KHR_materials_clearcoat", clearcoat}});
  const int shiny = material(vec3(0.1f, 0.2f, 0.8f), 0.3, {{"KHR_materials_specular", specular}});
  const int floor = test::addMaterial(
      b, {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}});
  b.scene({test::addSphere(b, glass, {{"translation", {-2.2, 0, 0}}}),
           test::addSphere(b, coated, {{"translation", {0, 0, 0}}}),
           test::addSphere(b, shiny, {{"translation", {2.2, 0, 0}}}),
           test::addSquare(b, floor,
                           {{"translation", {0, -1, 0}},
                            {"rotation", {-0.7071068, 0, 0, 0.7071068}},
                            {"scale", {6, 6, 1}}}),
           test::addCamera(b, 9.0, 0.5, 2.0),
           test::addDirectionalLight(b, glm::dvec3(-1, -2, -1), 2.0)});
  Scene scene = loadGltfSceneBytes(b.gltf(), "layered.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  return prepareScene(std::move(scene), RenderSettings{.width = 48, .height = 24});
}

// Uniform extension textures render as the factors of their values, on the CPU and on
// lavapipe; the textured scene agrees on both backends.
TEST(GltfExtensionTextures, UniformTexturesRenderAsTheirFactorsOnBothBackends) {
  const SceneData textured = layeredSpheres(true);
  const std::string effects = textured.effects.toString();
  EXPECT_NE(effects.find("textures"), std::string::npos) << effects;
  EXPECT_NE(textured.effects.textureFeatures & kTextureUsesGltfLayers, 0u) << effects;
  const SceneData factors = layeredSpheres(false);
  EXPECT_EQ(factors.effects.textureFeatures & kTextureUsesGltfLayers, 0u);
  const Comparison withTextures = renderBoth(textured, 16);
  const Comparison withFactors = renderBoth(factors, 16);
  expectAgreement(withTextures);
  test::expectSameImage(withTextures.cpuImage, withFactors.cpuImage);
  test::expectSameImage(withTextures.gpuImage, withFactors.gpuImage);
}

// A clear coat whose texture is 1 on the square's left half and 0 on its right, under the white
// sky of a file without lights: the left half renders as the coat of factor 1, the right as the
// coat of factor 0 (each scene with
// KHR_materials_specular at its defaults, so that all three take the same layered BSDF), on
// both backends; the two halves of the references differ.
TEST(GltfExtensionTextures, ClearcoatTextureCoatsTheHalfItCoversOnBothBackends) {
  const auto scene = [](double factor, bool textured) {
    GltfBuilder b;
    json clearcoat = {{"clearcoatFactor", factor}, {"clearcoatRoughnessFactor", 0.2}};
    if (textured) {
      clearcoat["clearcoatTexture"] = {
          {"index", test::addTexture(b, test::png(2, 1, 3, {255, 0, 0, 0, 0, 0}))}};
    }
    const int m = test::addMaterial(
        b,
        {{"pbrMetallicRoughness",
          {{"baseColorFactor", {0.8, 0.1, 0.1, 1.0}},
           {"metallicFactor", 0.0},
           {"roughnessFactor", 0.8}}},
         {"extensions",
          {{"KHR_materials_clearcoat", clearcoat}, {"KHR_materials_specular", json::object()}}}});
    b.scene({test::addSquare(b, m), test::addCamera(b, 3.0, 0.7)});
    Scene s = loadGltfSceneBytes(b.gltf(), "coat.gltf");
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    return prepareScene(std::move(s), RenderSettings{.width = 32, .height = 32});
  };
  const Comparison textured = renderBoth(scene(1.0, true), 16);
  const Comparison coated = renderBoth(scene(1.0, false), 16);
  const Comparison bare = renderBoth(scene(0.0, false), 16);
  expectAgreement(textured);
  // The square spans about pixels 2 to 29; the texel edge is at x = 16.
  for (bool gpu : {false, true}) {
    SCOPED_TRACE(gpu ? "lavapipe" : "cpu");
    const Image& t = gpu ? textured.gpuImage : textured.cpuImage;
    const Image& c = gpu ? coated.gpuImage : coated.cpuImage;
    const Image& n = gpu ? bare.gpuImage : bare.cpuImage;
    test::expectSameImage(t, c, 4, 6, 14, 26);
    test::expectSameImage(t, n, 18, 6, 28, 26);
    // The coat shows: the coated and bare references differ on each half.
    EXPECT_GT(test::meanOf(c, 4, 6, 14, 26).y, 1.1f * test::meanOf(n, 4, 6, 14, 26).y);
    EXPECT_GT(test::meanOf(c, 18, 6, 28, 26).y, 1.1f * test::meanOf(n, 18, 6, 28, 26).y);
  }
}

// Every extension texture at once, varying over the surface (8 x 8 texels), on the CPU and on
// lavapipe.
TEST(GltfExtensionTextures, VaryingTexturesAgreeOnBothBackends) {
  GltfBuilder b;
  std::vector<std::uint8_t> texels;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      texels.insert(texels.end(),
                    {std::uint8_t(32 * x + 8), std::uint8_t(255 - 30 * y),
                     std::uint8_t(16 * (x + y)), std::uint8_t(40 + 25 * ((x + y) % 9))});
    }
  }
  const json info = {{"index", test::addTexture(b, test::png(8, 8, 4, texels))}};
  const int m =
      test::addMaterial(b, {{"pbrMetallicRoughness",
                             {{"baseColorFactor", {0.9, 0.6, 0.4, 1.0}},
                              {"metallicFactor", 0.0},
                              {"roughnessFactor", 0.4}}},
                            {"extensions",
                             {{"KHR_materials_transmission",
                               {{"transmissionFactor", 0.8}, {"transmissionTexture", info}}},
                              {"KHR_materials_clearcoat",
                               {{"clearcoatFactor", 1.0},
                                {"clearcoatTexture", info},
                                {"clearcoatRoughnessFactor", 0.7},
                                {"clearcoatRoughnessTexture", info}}},
                              {"KHR_materials_specular",
                               {{"specularFactor", 1.0},
                                {"specularTexture", info},
                                {"specularColorFactor", {1.5, 1.0, 0.8}},
                                {"specularColorTexture", info}}}}}});
  const int floor = test::addMaterial(b, {{"pbrMetallicRoughness",
                                           {{"baseColorFactor", {0.3, 0.6, 0.3, 1.0}},
                                            {"metallicFactor", 0.0},
                                            {"roughnessFactor", 1.0}}}});
  b.scene({test::addSphere(b, m),
           test::addSquare(b, m, {{"translation", {-1.5, 0.2, 1.0}}, {"scale", {0.6, 0.6, 1}}}),
           test::addSquare(b, floor,
                           {{"translation", {0, -1, 0}},
                            {"rotation", {-0.7071068, 0, 0, 0.7071068}},
                            {"scale", {5, 5, 1}}}),
           test::addCamera(b, 6.0, 0.7),
           test::addDirectionalLight(b, glm::dvec3(-1, -1, -1), 3.0)});
  Scene scene = loadGltfSceneBytes(b.gltf(), "varying.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  const SceneData data = prepareScene(std::move(scene), RenderSettings{.width = 40, .height = 40});
  EXPECT_NE(data.effects.textureFeatures & kTextureUsesGltfLayers, 0u);
  expectAgreement(renderBoth(data, 8));
}

}  // namespace
}  // namespace pt
