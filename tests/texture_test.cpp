// Textures (shaders/texture.h, host/scene/textures.h): image lookups against hand-computed
// bilinear values at texel centres, edges and corners for each wrap mode, the colour
// encodings' decoding tables against their formulas, what float textures read of an image,
// the checkerboard's area fractions, composite textures, material parameters, and a textured
// plane rendered on both backends against its closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/reader_helpers.h"
#include "scene/scene.h"
#include "scene/textures.h"
#include "test_util.h"
#include "texture.h"

namespace pt {
namespace {

// A float RGB image whose texel (x, y) is (x + 1, y + 1, 10 (x + 1) + y + 1) / 100: every texel
// different, in every channel.
TextureImage rampImage(int width, int height) {
  TextureImage image;
  image.width = width;
  image.height = height;
  image.channels = 3;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.floats.push_back(float(x + 1) / 100.0f);
      image.floats.push_back(float(y + 1) / 100.0f);
      image.floats.push_back(float(10 * (x + 1) + y + 1) / 100.0f);
    }
  }
  return image;
}

glm::dvec3 rampTexel(int x, int y) {
  return glm::dvec3(double(float(x + 1) / 100.0f), double(float(y + 1) / 100.0f),
                    double(float(10 * (x + 1) + y + 1) / 100.0f));
}

struct Built {
  Scene scene;
  uint texture = kNoTexture;
  TextureTables tables() const {
    return TextureTables{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  }
  vec3 at(vec2 uv) const { return evalTexture(tables(), texture, uv); }
};

Built buildImage(const TextureImage& image, ImageTextureDesc desc, bool isFloat = false) {
  Built b;
  TextureBuilder builder(b.scene);
  desc.filename = "memory";
  b.texture = builder.image(image, desc, isFloat);
  return b;
}

void expectTexelNear(vec3 got, glm::dvec3 want, const std::string& what) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(double(got[c]), want[c], 1e-6) << what << " channel " << c;
}

TEST(Textures, WrapModesFoldTexelCoordinates) {
  EXPECT_EQ(wrapTexel(-1, 4, kWrapRepeat), 3);
  EXPECT_EQ(wrapTexel(-4, 4, kWrapRepeat), 0);
  EXPECT_EQ(wrapTexel(-5, 4, kWrapRepeat), 3);
  EXPECT_EQ(wrapTexel(4, 4, kWrapRepeat), 0);
  EXPECT_EQ(wrapTexel(9, 4, kWrapRepeat), 1);
  EXPECT_EQ(wrapTexel(-7, 4, kWrapClamp), 0);
  EXPECT_EQ(wrapTexel(7, 4, kWrapClamp), 3);
  EXPECT_EQ(wrapTexel(2, 4, kWrapClamp), 2);
  EXPECT_EQ(wrapTexel(-1, 4, kWrapBlack), -1);
  EXPECT_EQ(wrapTexel(4, 4, kWrapBlack), -1);
  EXPECT_EQ(wrapTexel(3, 4, kWrapBlack), 3);
}

// Bilinear lookups of a 3 x 2 image, (s, t) with t = 1 at row 0 (pbrt-v4 flips t): texel
// centres give the texel; the left edge halfway between the first column and, by the wrap
// mode, the last (repeat), the first again (clamp) or black; the top-left corner the four
// corners' mean (repeat), the corner texel (clamp) or a quarter of it (black).
TEST(Textures, BilinearAtCentresEdgesAndCorners) {
  // Sides that are powers of two: level 0 of the MIP map is the image itself.
  const int w = 4, h = 2;
  for (uint wrap : {kWrapRepeat, kWrapClamp, kWrapBlack}) {
    SCOPED_TRACE(wrap);
    ImageTextureDesc desc;
    desc.wrap = wrap;
    const Built b = buildImage(rampImage(w, h), desc);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const vec2 st((float(x) + 0.5f) / float(w), 1.0f - (float(y) + 0.5f) / float(h));
        expectTexelNear(b.at(st), rampTexel(x, y), "centre");
      }
    }
    // Left edge at row 0's centre: s = 0, halfway between texel -1 and texel 0.
    const vec2 edge(0.0f, 1.0f - 0.5f / float(h));
    const glm::dvec3 t0 = rampTexel(0, 0);
    const glm::dvec3 left = wrap == kWrapRepeat  ? rampTexel(w - 1, 0)
                            : wrap == kWrapClamp ? t0
                                                 : glm::dvec3(0.0);
    expectTexelNear(b.at(edge), 0.5 * (t0 + left), "left edge");
    // Top-left corner: s = 0, t = 1.
    glm::dvec3 corner;
    if (wrap == kWrapRepeat) {
      corner = 0.25 * (rampTexel(0, 0) + rampTexel(w - 1, 0) + rampTexel(0, h - 1) +
                       rampTexel(w - 1, h - 1));
    } else if (wrap == kWrapClamp) {
      corner = rampTexel(0, 0);
    } else {
      corner = 0.25 * rampTexel(0, 0);
    }
    expectTexelNear(b.at(vec2(0.0f, 1.0f)), corner, "corner");
    // A point inside: weights 0.75 and 0.25 along s between columns 1 and 2 of row 1.
    const vec2 inner((1.5f + 0.25f) / float(w), 1.0f - 1.5f / float(h));
    expectTexelNear(b.at(inner), 0.75 * rampTexel(1, 1) + 0.25 * rampTexel(2, 1), "inner");
  }
}

TEST(Textures, MappingScaleInvertAndPointFilter) {
  ImageTextureDesc desc;
  desc.filter = kTexturePoint;
  desc.mapping = vec4(2.0f, 1.0f, 0.25f, 0.0f);  // s = 2u + 0.25
  const Built b = buildImage(rampImage(4, 4), desc);
  // u = 0.3: s = 0.85, texel x = round(0.85 * 4 - 0.5) = 3; v = 0.9: t = 0.9, row
  // round(0.1 * 4 - 0.5) = 0 (halves away from zero: -0.1 rounds to 0).
  expectTexelNear(b.at(vec2(0.3f, 0.9f)), rampTexel(3, 0), "point");
  // Exactly halfway rounds away from zero: s * 4 - 0.5 = 1.5 gives texel 2.
  expectTexelNear(b.at(vec2((2.0f / 4.0f - 0.25f) / 2.0f, 0.9f)), rampTexel(2, 0), "half");
  desc.scale = 2.0f;
  desc.invert = true;
  const Built inverted = buildImage(rampImage(4, 4), desc);
  expectTexelNear(inverted.at(vec2(0.3f, 0.9f)),
                  glm::max(glm::dvec3(0.0), 1.0 - 2.0 * rampTexel(3, 0)), "scale then invert");
}

// 8-bit images decode each byte through a table of 256 values: sRGB's curve (IEC 61966-2-1),
// a gamma, or linear, computed in double and rounded once.
TEST(Textures, EncodingsDecodeBytesByTheirFormulas) {
  TextureImage bytes;
  bytes.width = 256;
  bytes.height = 1;
  bytes.channels = 1;
  for (int i = 0; i < 256; ++i) bytes.bytes.push_back(uint8_t(i));
  const auto srgb = [](double c) {
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  for (const std::string encoding : {"sRGB", "linear", "gamma 2.2"}) {
    SCOPED_TRACE(encoding);
    ImageTextureDesc desc;
    desc.filter = kTexturePoint;
    desc.encoding = encoding;
    const Built b = buildImage(bytes, desc);
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      const double want = encoding == "sRGB"     ? srgb(c)
                          : encoding == "linear" ? c
                                                 : std::pow(c, 2.2);
      const vec3 got = b.at(vec2((float(i) + 0.5f) / 256.0f, 0.5f));
      EXPECT_EQ(got.x, float(want)) << "byte " << i;
      EXPECT_EQ(got.y, got.x);
      EXPECT_EQ(got.z, got.x);
    }
  }
  EXPECT_EQ(srgb(1.0), 1.0);
  Scene scene;
  TextureBuilder builder(scene);
  ImageTextureDesc bad;
  bad.filename = "x.png";
  bad.encoding = "gamma -1";
  EXPECT_THROW(builder.image(bytes, bad, false), InputError);
}

// What a float texture reads (pbrt-v4's MIPMap): a grey image's channel, an RGBA image's alpha
// unless every alpha is one, else the mean of R, G and B.
TEST(Textures, FloatTexturesReadTheChannelPbrtReads) {
  TextureImage rgba;
  rgba.width = 1;
  rgba.height = 1;
  rgba.channels = 4;
  rgba.floats = {0.2f, 0.4f, 0.9f, 0.5f};
  ImageTextureDesc desc;
  EXPECT_EQ(buildImage(rgba, desc, true).at(vec2(0.5f)).x, 0.5f);
  EXPECT_EQ(buildImage(rgba, desc, false).at(vec2(0.5f)), vec3(0.2f, 0.4f, 0.9f));
  rgba.floats[3] = 1.0f;
  EXPECT_EQ(buildImage(rgba, desc, true).at(vec2(0.5f)).x, (0.2f + 0.4f + 0.9f) / 3.0f);
  TextureImage grey;
  grey.width = 1;
  grey.height = 1;
  grey.channels = 1;
  grey.floats = {0.7f};
  EXPECT_EQ(buildImage(grey, desc, true).at(vec2(0.5f)), vec3(0.7f));
  EXPECT_EQ(buildImage(grey, desc, false).at(vec2(0.5f)), vec3(0.7f));
}

// The checkerboard covers its two textures by area: half each on an 8 x 8 board, and on a
// 3 x 1 board (squares 0 and 2 even) two thirds tex1.
TEST(Textures, CheckerboardAreaFractions) {
  for (const auto& [mapping, want] : {std::pair{vec4(8.0f, 8.0f, 0.0f, 0.0f), 0.5},
                                      std::pair{vec4(3.0f, 1.0f, 0.0f, 0.0f), 1.0 / 3.0},
                                      std::pair{vec4(2.0f, 2.0f, 0.5f, 0.0f), 0.5}}) {
    Scene scene;
    TextureBuilder builder(scene);
    const uint t =
        builder.checkerboard(mapping, builder.constant(vec3(0.0f)), builder.constant(vec3(1.0f)));
    const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr,
                               nullptr};
    constexpr int kGrid = 600;
    double tex2 = 0.0;
    for (int j = 0; j < kGrid; ++j) {
      for (int i = 0; i < kGrid; ++i) {
        tex2 += evalTexture(tables, t, vec2((i + 0.5f) / kGrid, (j + 0.5f) / kGrid)).x;
      }
    }
    EXPECT_NEAR(tex2 / (kGrid * kGrid), want, 1e-9);
  }
}

TEST(Textures, CompositeTexturesEvaluateTheirPrograms) {
  Scene scene;
  TextureBuilder builder(scene);
  ImageTextureDesc desc;
  desc.filename = "ramp";
  const uint image = builder.image(rampImage(2, 2), desc, false);
  const uint mixed =
      builder.mix(builder.constant(vec3(0.1f, 0.2f, 0.3f)), image, builder.constant(vec3(0.25f)));
  const uint scaled = builder.scale(mixed, builder.constant(vec3(4.0f)));
  const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  const vec2 uv(0.25f, 0.75f);  // texel (0, 0)'s centre
  const glm::dvec3 want = 4.0 * (0.75 * glm::dvec3(0.1, 0.2, 0.3) + 0.25 * rampTexel(0, 0));
  expectTexelNear(evalTexture(tables, scaled, uv), want, "scale(mix(constant, image, 0.25), 4)");
  // A checkerboard of a scaled image and a constant: both operands on its stack.
  const uint board =
      builder.checkerboard(vec4(1.0f, 1.0f, 0.0f, 0.0f), scaled, builder.constant(vec3(7.0f)));
  const TextureTables grown{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  expectTexelNear(evalTexture(grown, board, uv), want, "checkerboard's tex1");
  expectTexelNear(evalTexture(grown, board, vec2(1.25f, 0.5f)), glm::dvec3(7.0),
                  "checkerboard's tex2");
  // Nesting that needs a deeper stack than the shader has is refused when the texture is made.
  uint deep = builder.constant(vec3(1.0f));
  EXPECT_THROW(
      {
        for (int i = 0; i < 8; ++i) {
          deep = builder.mix(
              builder.constant(vec3(0.0f)), builder.constant(vec3(1.0f)),
              builder.mix(builder.constant(vec3(0.0f)), deep, builder.constant(vec3(0.5f))));
        }
      },
      InputError);
}

TEST(Textures, MaterialParametersTakeTheirTextures) {
  Scene scene;
  TextureBuilder builder(scene);
  const uint bright = builder.constant(vec3(1.5f, 0.25f, -1.0f));
  const uint rough = builder.constant(vec3(0.09f));
  const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  MaterialTextures t = noMaterialTextures();
  t.reflectance = bright;
  // Reflectances are clamped to [0, 1] as pbrt-v4's albedo spectra are.
  Material diffuse = resolveMaterial(tables, defaultMaterial(kMaterialDiffuse), t, vec2(0.0f));
  EXPECT_EQ(diffuse.reflectance, vec3(1.0f, 0.25f, 0.0f));
  // A conductor by its reflectance: eta 1 and pbrt-v4's k, as the host computes for a value.
  Material expected = defaultMaterial(kMaterialConductor);
  setConductorReflectance(expected, vec3(1.0f, 0.25f, 0.0f));
  Material conductor = resolveMaterial(tables, defaultMaterial(kMaterialConductor), t, vec2(0.0f));
  EXPECT_EQ(conductor.eta, expected.eta);
  // (The host clamps white to 0.9999 in double, the shared code to 0.9999f: 1 - r differs by
  // 8e-5 relative there.)
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(conductor.k[c], expected.k[c], 2e-4f * expected.k[c]);
  // Roughness remapped to alpha (sqrt) unless remaproughness is false.
  MaterialTextures r = noMaterialTextures();
  r.uRoughness = r.vRoughness = rough;
  r.flags = kRemapRoughness;
  Material remapped = resolveMaterial(tables, defaultMaterial(kMaterialConductor), r, vec2(0.0f));
  EXPECT_FLOAT_EQ(remapped.alphaX, 0.3f);
  EXPECT_FLOAT_EQ(remapped.alphaY, 0.3f);
  r.flags = 0;
  Material direct = resolveMaterial(tables, defaultMaterial(kMaterialConductor), r, vec2(0.0f));
  EXPECT_EQ(direct.alphaX, 0.09f);
  // diffusetransmission's scale multiplies the textured colours, clamped again.
  MaterialTextures d = noMaterialTextures();
  d.reflectance = builder.constant(vec3(0.4f));
  d.scale = 2.0f;
  const TextureTables tables2{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  Material dt =
      resolveMaterial(tables2, defaultMaterial(kMaterialDiffuseTransmission), d, vec2(0.0f));
  EXPECT_EQ(dt.reflectance, vec3(0.8f));
  // coateddiffuse's medium: thickness and g (kept inside (-1, 1)).
  MaterialTextures c = noMaterialTextures();
  c.thickness = builder.constant(vec3(0.25f));
  c.g = builder.constant(vec3(-3.0f));
  const TextureTables tables3{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  Material coated =
      resolveMaterial(tables3, defaultMaterial(kMaterialCoatedDiffuse), c, vec2(0.0f));
  EXPECT_EQ(coated.thickness, 0.25f);
  EXPECT_EQ(coated.g, -0.999f);
}

// ---- Rendered ------------------------------------------------------------------------------

// A JSON scene seen from 10 above the origin looking down (image right = +x, image up = +z),
// under a distant light straight above of irradiance pi (a diffuse surface's radiance is then
// its albedo), one bounce: `textures`, `materials` and `shapes` are the arrays' contents.
std::string topDownScene(const std::string& textures, const std::string& materials,
                         const std::string& shapes, int spp) {
  return R"({"camera": {"position": [0, 10, 0], "target": [0, 0, 0], "up": [0, 0, 1],
    "vfov": 60, "width": 40, "height": 40},
    "integrator": {"spp": )" +
         std::to_string(spp) + R"(, "maxDepth": 1},
    "textures": [)" +
         textures + R"(],
    "materials": [)" +
         materials + R"(],
    "shapes": [)" +
         shapes + R"(],
    "lights": [{"type": "distant", "direction": [0, 1, 0],
      "radiance": [3.14159265, 3.14159265, 3.14159265]}]})";
}

// The square [-10, 10]^2 of the plane y = 0 in material `material` (named "plane"), its
// (u, v) = ((10 - x) / 20, (z + 10) / 20).
std::string planeScene(const std::string& textures, const std::string& material, int spp) {
  return topDownScene(textures, material, R"({"type": "quad", "material": "plane",
      "vertices": [[10, 0, -10], [-10, 0, -10], [-10, 0, 10], [10, 0, 10]]})",
                      spp);
}

// The plane's radiance over each pixel (16 x 16 points of the box filter's square), from
// albedo(u, v), to compare with renders.
template <typename Albedo>
Image expectedPlane(const SceneData& data, const Albedo& albedo) {
  return pixelAverages(data.params.camera, [&](const Ray& ray) {
    const glm::dvec3 o(ray.origin), d(ray.direction);
    const glm::dvec3 hit = o + d * (-o.y / d.y);
    // The quad's first corner is (10, 0, -10): u grows towards -x.
    return albedo((10.0 - hit.x) / 20.0, (hit.z + 10.0) / 20.0);
  });
}

template <typename Albedo>
void expectPlane(const SceneData& data, const Albedo& albedo, double tolerance) {
  const Image expected = expectedPlane(data, albedo);
  const Comparison cmp = renderBoth(data, data.spp);
  expectAgreement(cmp);
  expectNearClosedForm(cmp, expected, tolerance, 0.0);
}

// An image texture (4 x 4 texels over the plane twice along u, repeated, offset) on both
// backends against bilinear interpolation written out here.
TEST(Textures, ImageTexturedPlaneMatchesItsClosedFormOnBothBackends) {
  const test::TempDir dir;
  Image texels(4, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      texels.at(x, y) =
          vec3(0.1f + 0.2f * float(x), 0.1f + 0.25f * float(y), 0.05f + 0.2f * float((x + y) % 4));
    }
  }
  writeImage(texels, dir / "ramp.exr");
  const Scene scene = loadScene(
      dir.write("plane.json",
                planeScene(R"({"name": "ramp", "type": "imagemap", "filename": "ramp.exr",
                     "uscale": 2, "udelta": 0.125})",
                           R"({"name": "plane", "type": "diffuse", "reflectance": "ramp"})", 64)));
  const SceneData data = prepareScene(scene, RenderSettings{});
  EXPECT_TRUE(data.effects.textures);
  const auto albedo = [&](double u, double v) {
    const double s = 2.0 * u + 0.125, t = v;
    const double x = s * 4.0 - 0.5, y = (1.0 - t) * 4.0 - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const auto texel = [&](int i, int j) {
      i = ((i % 4) + 4) % 4;
      j = ((j % 4) + 4) % 4;
      return glm::dvec3(texels.at(i, j));
    };
    const int xi = int(fx), yi = int(fy);
    const double dx = x - fx, dy = y - fy;
    return (1 - dx) * (1 - dy) * texel(xi, yi) + dx * (1 - dy) * texel(xi + 1, yi) +
           (1 - dx) * dy * texel(xi, yi + 1) + dx * dy * texel(xi + 1, yi + 1);
  };
  expectPlane(data, albedo, 0.01);
}

TEST(Textures, CheckerboardPlaneMatchesItsClosedFormOnBothBackends) {
  const test::TempDir dir;
  const Scene scene = loadScene(dir.write(
      "plane.json",
      planeScene(R"({"name": "grey", "type": "constant", "value": 0.2},
                    {"name": "board", "type": "checkerboard", "uscale": 4, "vscale": 4,
                     "tex1": [0.9, 0.5, 0.1], "tex2": "grey"})",
                 R"({"name": "plane", "type": "diffuse", "reflectance": "board"})", 256)));
  const SceneData data = prepareScene(scene, RenderSettings{});
  const auto albedo = [](double u, double v) {
    const bool even = (int(std::floor(4.0 * u)) + int(std::floor(4.0 * v))) % 2 == 0;
    return even ? glm::dvec3(0.9, 0.5, 0.1) : glm::dvec3(0.2);
  };
  // The pixels across a square's edge average the two colours by where the samples land.
  expectPlane(data, albedo, 0.06);
}

TEST(Textures, ScenesWithoutTexturesCompileNone) {
  const SceneData data = prepareScene(loadScene(test::kConfigs / "cornell-box.json"), {});
  EXPECT_FALSE(data.effects.textures || data.effects.alphaCutouts || data.effects.bumpMaps);
  EXPECT_EQ(data.params.texturesPresent, 0u);
  EXPECT_TRUE(data.uvs.empty() && data.textureNodes.empty() && data.materialTextures.empty());
}

TEST(Textures, JsonTextureErrorsNameTheField) {
  const test::TempDir dir;
  const auto error = [&](const std::string& textures, const std::string& material) {
    try {
      loadScene(dir.write("bad.json", planeScene(textures, material, 1)));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string plane = R"({"name": "plane", "type": "diffuse", "reflectance": "t"})";
  EXPECT_NE(error("", plane).find("materials[0].reflectance: unknown texture 't'"),
            std::string::npos)
      << error("", plane);
  EXPECT_NE(error(R"({"name": "t", "type": "marble"})", plane)
                .find("textures[0].type: unknown texture type 'marble'"),
            std::string::npos);
  const std::string missing =
      error(R"({"name": "t", "type": "imagemap", "filename": "none.exr"})", plane);
  EXPECT_NE(missing.find("textures[0].filename: "), std::string::npos) << missing;
  EXPECT_NE(missing.find("none.exr"), std::string::npos) << missing;
  EXPECT_EQ(missing.find('\n'), std::string::npos) << missing;
  EXPECT_NE(
      error(R"({"name": "t", "type": "imagemap", "filename": "a.png", "encoding": "cmyk"})", plane)
          .find("textures[0].encoding: unknown encoding 'cmyk'"),
      std::string::npos);
  EXPECT_NE(error(R"({"name": "t", "type": "constant"}, {"name": "t", "type": "constant"})", plane)
                .find("textures[1].name: duplicate texture name 't'"),
            std::string::npos);
  EXPECT_NE(
      error(R"({"name": "t", "type": "imagemap", "filename": "a.png", "wrap": "mirror"})", plane)
          .find("textures[0].wrap: unknown wrap mode 'mirror'"),
      std::string::npos);
}

}  // namespace
}  // namespace pt

namespace pt {
namespace {

// A plane of albedo 0.8 at y = 0 under a distant light straight above (irradiance pi), seen
// from 10 above through a black quad at y = 5 whose alpha is `alpha` (a texture's name or a
// number): camera rays see the plane through the cut-outs, and the plane is lit where the
// light comes through them.
std::string cutoutScene(const std::string& textures, const std::string& alpha, int spp) {
  return topDownScene(textures,
                      R"({"name": "plane", "type": "diffuse", "reflectance": [0.8, 0.8, 0.8]},
      {"name": "screen", "type": "diffuse", "reflectance": [0, 0, 0], "alpha": )" +
                          alpha + "}",
                      R"({"type": "quad", "material": "plane",
      "vertices": [[20, 0, -20], [-20, 0, -20], [-20, 0, 20], [20, 0, 20]]},
      {"type": "quad", "material": "screen",
      "vertices": [[10, 5, -10], [-10, 5, -10], [-10, 5, 10], [10, 5, 10]]})",
                      spp);
}

// A checkerboard alpha (4 x 4 squares over the screen, holes on the odd ones): the camera
// sees the plane through a hole, lit where the hole straight above it lets the light through,
// on both backends, against the same geometry worked out here.
TEST(Textures, AlphaCutoutsPassRaysAndCastTheirShadowOnBothBackends) {
  const test::TempDir dir;
  const Scene scene = loadScene(
      dir.write("cutout.json",
                cutoutScene(R"({"name": "holes", "type": "checkerboard", "uscale": 4, "vscale": 4,
                      "tex1": 1, "tex2": 0})",
                            R"("holes")", 64)));
  const SceneData data = prepareScene(scene, RenderSettings{});
  EXPECT_TRUE(data.effects.alphaCutouts);
  // Whether the screen has a hole above (x, z): u = (10 - x) / 20, v = (z + 10) / 20.
  const auto hole = [](double x, double z) {
    const double u = (10.0 - x) / 20.0, v = (z + 10.0) / 20.0;
    if (u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0) return true;  // beyond the screen
    return (int(std::floor(4.0 * u)) + int(std::floor(4.0 * v))) % 2 != 0;
  };
  const Image expected = pixelAverages(data.params.camera, [&](const Ray& ray) {
    const glm::dvec3 o(ray.origin), d(ray.direction);
    const glm::dvec3 onScreen = o + d * ((5.0 - o.y) / d.y);
    if (!hole(onScreen.x, onScreen.z)) return glm::dvec3(0.0);  // the black screen
    const glm::dvec3 onPlane = o + d * (-o.y / d.y);
    return hole(onPlane.x, onPlane.z) ? glm::dvec3(0.8) : glm::dvec3(0.0);
  });
  const Comparison cmp = renderBoth(data, data.spp);
  EXPECT_EQ(cmp.gpu.validationErrors, 0u);
  EXPECT_LE(double(cmp.diff.pixelsOverThreshold), 0.005 * double(cmp.diff.pixelCount));
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    size_t off = 0, lit = 0, dark = 0;
    for (size_t i = 0; i < expected.pixels.size(); ++i) {
      const double e = expected.pixels[i].x;
      if (std::fabs(double(image->pixels[i].x) - e) > 0.06) ++off;
      lit += e > 0.79 ? 1 : 0;
      dark += e < 0.01 ? 1 : 0;
    }
    // Whole pixels of each kind: lit plane through a hole, shadow, the screen.
    EXPECT_GT(lit, 100u);
    EXPECT_GT(dark, 400u);
    EXPECT_EQ(off, 0u) << (image == &cmp.cpuImage ? "cpu" : "vulkan");
  }
}

// pbrt-v4's stochastic alpha: a screen of alpha 0.5 passes half the camera rays and half the
// light, so the plane behind it averages 0.8 / 4.
TEST(Textures, PartialAlphaPassesThatFractionOfRaysOnBothBackends) {
  const test::TempDir dir;
  const Scene scene = loadScene(dir.write("half.json", cutoutScene("", "0.5", 256)));
  const SceneData data = prepareScene(scene, RenderSettings{});
  const Comparison cmp = renderBoth(data, data.spp);
  EXPECT_LE(double(cmp.diff.pixelsOverThreshold), 0.005 * double(cmp.diff.pixelCount));
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    double sum = 0.0;
    for (const vec3& p : image->pixels) sum += p.x;
    EXPECT_NEAR(sum / double(image->pixels.size()), 0.2, 0.004);
  }
}

}  // namespace
}  // namespace pt

namespace pt {
namespace {

// A bump map of a constant leaves the surface as it is: the same image, bit for bit, on both
// backends, as without one.
TEST(Textures, ConstantBumpMapLeavesTheImageUnchangedOnBothBackends) {
  const test::TempDir dir;
  const auto render = [&](const std::string& displacement) {
    const Scene scene = loadScene(dir.write(
        "bump.json",
        planeScene(R"({"name": "d", "type": "constant", "value": 0.25})",
                   R"({"name": "plane", "type": "diffuse", "reflectance": [0.5, 0.6, 0.7])" +
                       displacement + "}",
                   4)));
    return renderBoth(prepareScene(scene, RenderSettings{}), 4);
  };
  const Comparison plain = render("");
  const Comparison bumped = render(R"(, "displacement": "d")");
  EXPECT_EQ(plain.cpuImage.pixels, bumped.cpuImage.pixels);
  EXPECT_EQ(plain.gpuImage.pixels, bumped.gpuImage.pixels);
}

// A displacement rising linearly along u (a 2 x 1 image of 0 and 1, bilinear between the texel
// centres, scaled by 5: dD/du = 10) tilts the plane's shading normal by atan(10 / |dp/du|) =
// atan(0.5) about v: under light from straight above the diffuse plane shows 0.8 cos(tilt).
TEST(Textures, LinearBumpTiltsTheNormalAsPbrtsBumpMapOnBothBackends) {
  const test::TempDir dir;
  TextureImage ramp;
  Image twoTexels(2, 1);
  twoTexels.pixels = {vec3(0.0f), vec3(1.0f)};
  writeImage(twoTexels, dir / "ramp.pfm");
  const Scene scene = loadScene(dir.write(
      "bump.json",
      planeScene(R"({"name": "ramp", "type": "imagemap", "filename": "ramp.pfm", "wrap": "clamp",
                     "encoding": "linear"},
                    {"name": "d", "type": "scale", "tex": "ramp", "scale": 5})",
                 R"({"name": "plane", "type": "diffuse", "reflectance": [0.8, 0.8, 0.8],
                     "displacement": "d"})",
                 16)));
  const SceneData data = prepareScene(scene, RenderSettings{});
  EXPECT_TRUE(data.effects.bumpMaps);
  const Comparison cmp = renderBoth(data, data.spp);
  expectAgreement(cmp);
  const double expected = 0.8 / std::sqrt(1.0 + 0.25);
  // The pixels whose every camera ray lands in 0.3 < u < 0.7 (the ramp's linear part).
  const Image u = pixelAverages(data.params.camera, [](const Ray& ray) {
    const glm::dvec3 o(ray.origin), d(ray.direction);
    const double x = (o + d * (-o.y / d.y)).x;
    const double uu = (10.0 - x) / 20.0;
    return glm::dvec3(uu > 0.3 && uu < 0.7 ? 1.0 : 0.0);
  });
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    size_t checked = 0, off = 0;
    for (size_t i = 0; i < u.pixels.size(); ++i) {
      if (u.pixels[i].x != 1.0f) continue;
      ++checked;
      if (std::fabs(double(image->pixels[i].y) - expected) > 2e-3) ++off;
    }
    EXPECT_GT(checked, 500u);
    EXPECT_EQ(off, 0u) << (image == &cmp.cpuImage ? "cpu" : "vulkan");
  }
}

}  // namespace
}  // namespace pt

namespace pt {
namespace {

// The example (configs/textured-sky.json: image textures, a bump map, a roughness texture, an
// alpha cut-out, a lat-long sky) renders alike on both backends. Its files come from
// tools/make-example-textures.py (tools/fetch-assets.sh).
TEST(Textures, TexturedSkyExampleAgreesOnBothBackends) {
  const std::filesystem::path config = test::kConfigs / "textured-sky.json";
  const std::filesystem::path sphere =
      std::filesystem::path(PT_SOURCE_DIR) / "assets" / "textures" / "sphere.obj";
  ASSERT_TRUE(std::filesystem::exists(sphere)) << sphere << " missing: run tools/fetch-assets.sh";
  RenderSettings settings;
  settings.width = 96;
  settings.height = 64;
  const SceneData data = prepareScene(loadScene(config), settings);
  EXPECT_TRUE(data.effects.textures && data.effects.alphaCutouts && data.effects.bumpMaps);
  expectAgreement(renderBoth(data, 8));
}

}  // namespace
}  // namespace pt
