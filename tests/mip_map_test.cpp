// MIP maps (host/scene/mip_pyramid.h) and the filtered lookups over a footprint
// (shaders/texture.h): the levels' 2 x 2 averages, the resampling of sides that are not powers
// of two, the level each footprint width chooses for the point, bilinear and trilinear filters,
// EWA's gaussian over the ellipse, the 8-bit levels' encoding, and the checkerboard's filtered
// edges, all against hand-computed values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "scene/mip_pyramid.h"
#include "scene/scene.h"
#include "scene/textures.h"
#include "texture.h"

namespace pt {
namespace {

FloatImage greyImage(int width, int height, std::vector<float> values) {
  FloatImage image;
  image.width = width;
  image.height = height;
  image.channels = 1;
  image.values = std::move(values);
  return image;
}

TEST(MipPyramid, LevelsAreTwoByTwoAveragesDownToOneTexel) {
  const std::vector<FloatImage> levels =
      mipPyramid(greyImage(4, 2, {1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f, 8.0f}), kWrapRepeat);
  ASSERT_EQ(levels.size(), 3u);
  EXPECT_EQ(levels[0].values, (std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8}));
  ASSERT_EQ(levels[1].width, 2);
  ASSERT_EQ(levels[1].height, 1);
  EXPECT_EQ(levels[1].values, (std::vector<float>{(1 + 2 + 5 + 6) / 4.0f, (3 + 4 + 7 + 8) / 4.0f}));
  ASSERT_EQ(levels[2].width, 1);
  ASSERT_EQ(levels[2].height, 1);
  // A side of one repeats its texel: (3.5 + 3.5 + 5.5 + 5.5) / 4.
  EXPECT_EQ(levels[2].values, (std::vector<float>{4.5f}));
}

TEST(MipPyramid, SidesThatAreNotPowersOfTwoAreResampledUp) {
  EXPECT_TRUE(isPowerOfTwo(1));
  EXPECT_TRUE(isPowerOfTwo(64));
  EXPECT_FALSE(isPowerOfTwo(3));
  EXPECT_EQ(roundUpPowerOfTwo(3), 4);
  EXPECT_EQ(roundUpPowerOfTwo(17), 32);
  // A constant stays constant (the weights are normalized) for every wrap mode but black,
  // whose zeros beyond the edges darken the edge texels.
  const FloatImage constant = greyImage(9, 5, std::vector<float>(45, 0.25f));
  for (uint wrap : {kWrapRepeat, kWrapClamp}) {
    const std::vector<FloatImage> levels = mipPyramid(constant, wrap);
    ASSERT_EQ(levels[0].width, 16);
    ASSERT_EQ(levels[0].height, 8);
    ASSERT_EQ(levels.size(), 5u);
    for (float v : levels[0].values) EXPECT_NEAR(v, 0.25f, 1e-6f);
  }
  const FloatImage black = mipPyramid(constant, kWrapBlack)[0];
  EXPECT_LT(black.at(0, 0, 0), 0.25f - 1e-3f);
  // Texel (8, 4)'s taps are old texels 3..6 and 1..4: all inside.
  EXPECT_NEAR(black.at(8, 4, 0), 0.25f, 1e-6f);
  // pbrt-v4's weights, hand-computed for 1 -> 2 texels with repeat (every tap is the one
  // texel): the new texels are the old one's value; and negative lobes are clamped to zero: a
  // single bright texel among zeros rings below zero beside it, stored as 0.
  EXPECT_NEAR(resizeUp(greyImage(1, 1, {0.5f}), 2, 1, kWrapRepeat).at(1, 0, 0), 0.5f, 1e-6f);
  const FloatImage ringing =
      resizeUp(greyImage(5, 1, {0.0f, 0.0f, 1.0f, 0.0f, 0.0f}), 8, 1, kWrapClamp);
  for (float v : ringing.values) EXPECT_GE(v, 0.0f);
}

// A 4 x 4 RGB float image, grey, 16 at texel (0, 0) and 0 elsewhere: level 1 (2 x 2) is 4 at
// (0, 0) and 0 elsewhere, level 2 (1 x 1) is 1. At the centre of texel (0, 0), (s, t) =
// (1/8, 7/8), bilinear lookups give 16 in level 0; in level 1 the point is a quarter texel
// before texel (0, 0) on both axes, so 0.75 * 0.75 * 4 = 2.25 (repeat wraps to zeros); 1 in
// level 2.
struct Spike {
  Scene scene;
  uint texture = kNoTexture;
  explicit Spike(uint filter, float maxAnisotropy = 8.0f) {
    TextureImage image;
    image.width = 4;
    image.height = 4;
    image.channels = 3;
    image.floats.assign(48, 0.0f);
    image.floats[0] = image.floats[1] = image.floats[2] = 16.0f;
    ImageTextureDesc desc;
    desc.filename = "spike";
    desc.filter = filter;
    desc.maxAnisotropy = maxAnisotropy;
    TextureBuilder builder(scene);
    texture = builder.image(image, desc, false);
  }
  // The value at the centre of texel (0, 0) for a footprint of (ds/dx, dt/dx), (ds/dy, dt/dy).
  float at(vec2 dx, vec2 dy) const {
    const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr,
                               nullptr};
    return evalTextureAt(tables, texture, UVFootprint(vec2(0.125f, 0.875f), dx, dy)).x;
  }
};

// The level of a footprint of width w = 2 max|d| is 2 + log2(w): d = 2^(level - 3).
float footprintFor(float level) {
  return std::exp2(level - 3.0f);
}

TEST(MipMap, LevelChoiceForPointBilinearAndTrilinear) {
  const Spike bilinear(kTextureBilinear);
  const Spike trilinear(kTextureTrilinear);
  const Spike point(kTexturePoint);
  const vec2 none(0.0f);
  // No footprint: level 0.
  EXPECT_FLOAT_EQ(bilinear.at(none, none), 16.0f);
  EXPECT_FLOAT_EQ(trilinear.at(none, none), 16.0f);
  // Level 0 and 1 exactly; the widest extent counts, in x or in y, in s or in t.
  EXPECT_FLOAT_EQ(bilinear.at(vec2(footprintFor(0.0f), 0.0f), none), 16.0f);
  EXPECT_FLOAT_EQ(bilinear.at(vec2(footprintFor(1.0f), 0.0f), none), 2.25f);
  EXPECT_FLOAT_EQ(bilinear.at(vec2(0.01f, 0.0f), vec2(0.0f, -footprintFor(1.0f))), 2.25f);
  // Between levels 1 and 2: bilinear reads level 1; trilinear interpolates, halfway here.
  EXPECT_FLOAT_EQ(bilinear.at(vec2(footprintFor(1.5f), 0.0f), none), 2.25f);
  EXPECT_NEAR(trilinear.at(vec2(footprintFor(1.5f), 0.0f), none), 0.5f * (2.25f + 1.0f), 1e-5f);
  // pbrt-v4's trilinear below level 1 reads level 0 alone.
  EXPECT_FLOAT_EQ(trilinear.at(vec2(footprintFor(0.5f), 0.0f), none), 16.0f);
  // The point filter: level 1's nearest texel to (-0.25, -0.25) is (0, 0), 4.
  EXPECT_FLOAT_EQ(point.at(vec2(footprintFor(1.0f), 0.0f), none), 4.0f);
  // At the last level or beyond: its one texel.
  EXPECT_FLOAT_EQ(bilinear.at(vec2(footprintFor(2.0f), 0.0f), none), 1.0f);
  EXPECT_FLOAT_EQ(trilinear.at(vec2(footprintFor(7.0f), 0.0f), none), 1.0f);
}

// EWA over a round footprint small enough for level 0 (lod = 2 + log2(1/8) < 0): in texels
// the axes are 1/2 long, so the ellipse is r2 = 0.8 (ds^2 + dt^2) (the filter widened by a
// texel and normalized as pbrt-v4's): texel (0, 0) at r2 = 0 and its four neighbours at
// r2 = 0.8 fall inside, with pbrt-v4's table weights exp(-2 i / 127) - exp(-2) at
// i = floor(128 r2): 16 w0 / (w0 + 4 w102).
TEST(MipMap, EwaWeighsTheTexelsInsideTheEllipse) {
  const Spike ewa(kTextureEwa);
  const double w0 = 1.0 - std::exp(-2.0);
  const double w102 = std::exp(-2.0 * 102.0 / 127.0) - std::exp(-2.0);
  EXPECT_NEAR(ewa.at(vec2(0.125f, 0.0f), vec2(0.0f, 0.125f)), 16.0 * w0 / (w0 + 4.0 * w102), 2e-5);
  // No footprint: level 0 bilinear.
  EXPECT_FLOAT_EQ(ewa.at(vec2(0.0f), vec2(0.0f)), 16.0f);
  // A footprint as wide as the image: lod 2 + log2(1) = 2, the last level, whose one texel is 1.
  EXPECT_NEAR(ewa.at(vec2(1.0f, 0.0f), vec2(0.0f, 1.0f)), 1.0f, 1e-6f);
}

// The longer axis is clamped to maxAnisotropy times the shorter by widening the shorter: a
// needle footprint of 1/64 by 1 (t) at maxAnisotropy 2 becomes 1/2 by 1, so its level is the
// one of its widened shorter axis, 2 + log2(1/2) = 1: in level 1's texels (st = (-1/4, -1/4),
// axes (1, 0) and (0, 2)) the ellipse is r2 = 0.5 ss^2 + 0.2 tt^2, which holds ten texels,
// two of them copies of level 1's 4 (at tt = 1/4 and -7/4); their table weights give 1.2587
// (hand-computed). With maxAnisotropy 64 it stays a needle at level 0, r2 = (256/257) ss^2 +
// tt^2 / 17 over columns -1..1 and rows -4..4, the spike 16 at rows 0 and +-4: 3.7550.
TEST(MipMap, EwaClampsTheAnisotropy) {
  const Spike clamped(kTextureEwa, 2.0f);
  const Spike needle(kTextureEwa, 64.0f);
  const vec2 along(0.0f, 1.0f);
  const vec2 across(1.0f / 64.0f, 0.0f);
  EXPECT_NEAR(clamped.at(across, along), 1.2587, 1e-4);
  EXPECT_NEAR(needle.at(across, along), 3.7550, 1e-4);
}

// 8-bit images keep 8-bit levels, encoded as the image is (pbrt-v4's): an sRGB image of two
// texels 0 and 255 has a level 1 of their linear mean 0.5, stored as the byte whose sRGB
// value is nearest, round(255 * srgb(0.5)) = 188, read back as its decoded value.
TEST(MipMap, EightBitLevelsAreEncodedAsTheImage) {
  TextureImage image;
  image.width = 2;
  image.height = 1;
  image.channels = 1;
  image.bytes = {0, 255};
  Scene scene;
  TextureBuilder builder(scene);
  ImageTextureDesc desc;
  desc.filename = "bytes";
  const uint texture = builder.image(image, desc, false);
  const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  const float v =
      evalTextureAt(tables, texture,
                    UVFootprint(vec2(0.25f, 0.5f), vec2(footprintFor(2.0f), 0.0f), vec2(0.0f)))
          .x;
  const double c = 188.0 / 255.0;
  EXPECT_NEAR(v, std::pow((c + 0.055) / 1.055, 2.4), 1e-6);
}

// Every byte an 8-bit level can take, for sRGB and two gammas: a 512-texel grey image of byte
// pairs (a, b) has a level 1 of their linear means, each stored as the byte whose encoded
// value is nearest: the number of the 255 thresholds (the linear values of the encoded
// (k - 1/2) / 255) at or below the mean. Read back with the point filter in level 1, each
// texel is that byte's decoded value. Means within 1e-5 of a threshold are skipped (float
// rounding may put them on either side).
TEST(MipMap, EightBitLevelsTakeTheNearestEncodedByte) {
  for (const std::string encoding : {"sRGB", "gamma 2.2", "gamma 0.45"}) {
    const double gamma = encoding == "sRGB" ? 0.0 : std::stod(encoding.substr(6));
    const auto decode = [&](double c) {
      if (gamma != 0.0) return std::pow(c, gamma);
      return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    };
    std::vector<double> thresholds;
    for (int k = 1; k <= 255; ++k) thresholds.push_back(double(float(decode((k - 0.5) / 255.0))));
    TextureImage image;
    image.width = 512;
    image.height = 1;
    image.channels = 1;
    // The pairs' second bytes: spread over 0..255, and near white for the last 16 pairs.
    const auto second = [](int i) { return i < 240 ? (i * 37 + 11) % 256 : 255 - (i - 240) / 2; };
    for (int i = 0; i < 256; ++i) {
      image.bytes.push_back(uint8_t(i));
      image.bytes.push_back(uint8_t(second(i)));
    }
    Scene scene;
    TextureBuilder builder(scene);
    ImageTextureDesc desc;
    desc.filename = "bytes";
    desc.encoding = encoding;
    desc.filter = kTexturePoint;
    const uint texture = builder.image(image, desc, false);
    const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr,
                               nullptr};
    // Level 1.5 of 10 (512 texels): the point filter reads level 1.
    const float d = 0.5f * std::exp2(1.5f - 9.0f);
    int checked = 0;
    for (int i = 0; i < 256; ++i) {
      const float a = float(decode(i / 255.0)), b = float(decode(second(i) / 255.0));
      const double mean = double((a + b + a + b) / 4.0f);
      const auto near = [&](double t) { return std::fabs(t - mean) <= 1e-5 * std::max(t, 1e-3); };
      if (std::any_of(thresholds.begin(), thresholds.end(), near)) continue;
      const int byte =
          int(std::upper_bound(thresholds.begin(), thresholds.end(), mean) - thresholds.begin());
      const float v = evalTextureAt(tables, texture,
                                    UVFootprint(vec2((float(i) + 0.5f) / 256.0f, 0.5f),
                                                vec2(d, 0.0f), vec2(0.0f)))
                          .x;
      EXPECT_NEAR(v, decode(byte / 255.0), 1e-6 + 1e-6 * decode(byte / 255.0))
          << encoding << ": texel " << i << " of level 1, mean " << mean << ", byte " << byte;
      ++checked;
    }
    EXPECT_GT(checked, 240) << encoding;
  }
}

// The checkerboard's filtered weight of tex2 (pbrt-v4's closed form against a triangle filter
// of radius 1.5 times the footprint): 0 and 1 inside squares at a point, 1/2 on an edge the
// footprint straddles evenly, 0.875 at s = 1.25 with radius 1/2 (hand-computed: the s factor
// is (d(1.75) - 2 d(1.25) + d(0.75)) / 0.25 = -0.75), and 1/2 for a footprint of many squares.
TEST(MipMap, CheckerboardIsFilteredOverTheFootprint) {
  const vec2 none(0.0f);
  EXPECT_EQ(checkerboardWeight(vec2(0.5f, 0.5f), none, none), 0.0f);
  EXPECT_EQ(checkerboardWeight(vec2(1.5f, 0.5f), none, none), 1.0f);
  const vec2 third(1.0f / 3.0f, 0.0f);
  EXPECT_NEAR(checkerboardWeight(vec2(1.0f, 0.5f), third, none), 0.5f, 1e-6f);
  EXPECT_NEAR(checkerboardWeight(vec2(1.25f, 0.5f), third, none), 0.875f, 1e-6f);
  EXPECT_NEAR(checkerboardWeight(vec2(0.3f, 0.6f), vec2(40.0f, 0.0f), vec2(0.0f, 40.0f)), 0.5f,
              1e-3f);
}

}  // namespace
}  // namespace pt
