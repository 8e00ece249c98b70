// bsdf.h's materials in whole renders: the Cornell box with its two blocks made of each type,
// on both backends (they must agree as for diffuse scenes), with nothing invalid, and the
// effect set naming exactly the types used. The BSDFs themselves are tested in bsdf_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "bsdf.h"
#include "cpu/integrator.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_materials.h"
#include "test_util.h"

namespace pt {
namespace {

using test::diffuseTransmission;
using test::thinDielectric;

// The types' parameters, as the scene reader would fill them (alphas already remapped).
Material conductor(float alpha) {
  return test::conductor(alpha, alpha);
}
Material dielectric(float eta, float alpha) {
  return test::dielectric(alpha, alpha, eta);
}
Material diffuseTransmission() {
  return diffuseTransmission(vec3(0.5f, 0.4f, 0.3f), vec3(0.3f, 0.4f, 0.5f));
}
Material coatedDiffuseMaterial(float alpha, vec3 albedo) {
  Material m{};
  m.type = kMaterialCoatedDiffuse;
  m.reflectance = vec3(0.6f, 0.3f, 0.2f);
  m.eta = vec3(1.5f);
  m.alphaX = m.alphaY = alpha;
  m.thickness = 0.01f;
  m.transmittance = albedo;
  m.g = 0.3f;
  m.maxDepth = 10;
  m.nSamples = 1;
  return m;
}

// The Cornell box (configs/cornell-box.json) with the short block made of `a` and the tall
// one of `b`: triangles 10-19 and 20-29 in its load order.
SceneData cornellWith(const Material& a, const Material& b, int size) {
  Scene scene = loadScene(test::kConfigs / "cornell-box.json");
  const uint ia = uint(scene.materials.size());
  scene.materials.push_back(a);
  scene.materialNames.push_back("a");
  scene.materials.push_back(b);
  scene.materialNames.push_back("b");
  for (size_t t = 10; t < 30; ++t) scene.triangles[t].material = t < 20 ? ia : ia + 1;
  return prepareScene(std::move(scene), RenderSettings{.width = size, .height = size});
}

struct MaterialCase {
  const char* name;
  Material a, b;
  const char* effects;  // the material types the effect string must list
};

class MaterialsAgree : public ::testing::TestWithParam<MaterialCase> {};

TEST_P(MaterialsAgree, OnBothBackends) {
  const MaterialCase& c = GetParam();
  const SceneData data = cornellWith(c.a, c.b, 32);
  EXPECT_NE(data.effects.toString().find(c.effects), std::string::npos) << data.effects.toString();
  EXPECT_TRUE(data.effects.hasBsdfMaterials());
  const Comparison cmp = renderBoth(data, 8);
  expectAgreement(cmp);
  EXPECT_EQ(cmp.cpu.invalidSamples, 0u);
}

INSTANTIATE_TEST_SUITE_P(
    Types, MaterialsAgree,
    ::testing::Values(
        MaterialCase{"conductors", conductor(0.0f), conductor(0.3f), "conductor"},
        MaterialCase{"anisotropicConductor", conductor(0.05f),
                     [] {
                       Material m = conductor(0.05f);
                       m.alphaY = 0.5f;
                       return m;
                     }(),
                     "conductor"},
        MaterialCase{"glass", dielectric(1.5f, 0.0f), dielectric(1.5f, 0.3f), "dielectric"},
        MaterialCase{"glassBelowOne", dielectric(1.0f / 1.33f, 0.2f), dielectric(1.0f, 0.0f),
                     "dielectric"},
        MaterialCase{"thinAndTranslucent", thinDielectric(1.5f), diffuseTransmission(),
                     "thindielectric+diffusetransmission"},
        MaterialCase{"coated", coatedDiffuseMaterial(0.0f, vec3(0.0f)),
                     coatedDiffuseMaterial(0.3f, vec3(0.5f)), "coateddiffuse"},
        // The hard cases: nearly smooth and fully rough, indices next to 1 and far from it
        // (glass blocks: total internal reflection inside), extreme anisotropy.
        MaterialCase{"conductorRoughnessExtremes", conductor(1e-4f), conductor(1.0f), "conductor"},
        MaterialCase{"glassIndexExtremes", dielectric(1.0001f, 0.0f), dielectric(4.0f, 0.0f),
                     "dielectric"},
        MaterialCase{"roughGlassExtremes", dielectric(1.0001f, 0.05f), dielectric(4.0f, 1.0f),
                     "dielectric"},
        MaterialCase{"anisotropyExtremes",
                     [] {
                       Material m = conductor(0.001f);
                       m.alphaY = 1.0f;
                       return m;
                     }(),
                     [] {
                       Material m = dielectric(1.5f, 1.0f);
                       m.alphaY = 0.001f;
                       return m;
                     }(),
                     "conductor+dielectric"},
        MaterialCase{"coatedExtremes", coatedDiffuseMaterial(1.0f, vec3(1.0f)),
                     coatedDiffuseMaterial(1e-4f, vec3(0.0f)), "coateddiffuse"},
        MaterialCase{"gltfSmooth", test::gltfMaterial(vec3(0.9f, 0.6f, 0.3f), 1.0f, 0.0f),
                     test::gltfMaterial(vec3(0.2f, 0.5f, 0.8f), 0.0f, 0.0f), "gltf"},
        MaterialCase{"gltfRough", test::gltfMaterial(vec3(0.9f, 0.6f, 0.3f), 0.5f, 0.4f),
                     test::gltfMaterial(vec3(0.2f, 0.5f, 0.8f), 0.0f, 1.0f, 1.1f), "gltf"}),
    [](const ::testing::TestParamInfo<MaterialCase>& info) {
      return std::string(info.param.name);
    });

// A sphere of 2 * 24 * 48 triangles at the origin, radius 1, with vertex normals: the
// sphere's own (smooth shading), or twisted by `twist` radians about the vertical axis's
// cross product with the normal (so that many shading normals point below their triangles).
void addTwistedSphere(Scene& scene, uint material, float twist) {
  const std::vector<Triangle> sphere = test::makeSphere(vec3(0.0f), 1.0f, 24, 48);
  if (scene.normals.empty()) {
    for (const Triangle& t : scene.triangles) {
      const vec3 ng = normalize(cross(t.v1 - t.v0, t.v2 - t.v0));
      scene.normals.push_back(TriangleNormals{ng, 0u, ng, 0u, ng, 0u});
    }
  }
  auto normalAt = [&](vec3 v) {
    const vec3 n = normalize(v);
    const vec3 axis = cross(vec3(0.0f, 1.0f, 0.0f), n);
    if (dot(axis, axis) < 1e-12f) return n;
    const vec3 a = normalize(axis);
    // Rodrigues' rotation of n about a by `twist`.
    return n * std::cos(twist) + cross(a, n) * std::sin(twist) +
           a * dot(a, n) * (1.0f - std::cos(twist));
  };
  for (Triangle t : sphere) {
    t.material = material;
    t.primitive = uint(scene.triangles.size());
    scene.triangles.push_back(t);
    scene.normals.push_back(
        TriangleNormals{normalAt(t.v0), 0u, normalAt(t.v1), 0u, normalAt(t.v2), 0u});
  }
}

// A closed cube around the sphere whose faces emit Le = 1 and reflect nothing, looked into
// from inside: a white furnace.
Scene furnaceWith(const Material& m, float twist) {
  Scene scene;
  scene.materials = {Material{vec3(0.0f), kMaterialDiffuse, vec3(1.0f), 0}, m};
  for (Triangle& t : scene.triangles) t.material = 0;
  const uint faces[6] = {0, 0, 0, 0, 0, 0};
  test::addInwardCube(scene, faces);
  for (Triangle& t : scene.triangles) {
    t.v0 *= 3.0f;
    t.v1 *= 3.0f;
    t.v2 *= 3.0f;
  }
  for (uint i = 0; i < scene.triangles.size(); ++i) scene.triangles[i].primitive = i;
  addTwistedSphere(scene, 1, twist);
  scene.camera = CameraDesc{vec3(0.0f, 0.0f, -2.9f), vec3(0.0f), vec3(0, 1, 0), 40.0f, 16, 16};
  scene.integrator.maxDepth = 1000;
  return scene;
}

// Mean and standard error of an image's pixels.
struct ImageMean {
  glm::dvec3 mean{0.0}, se{0.0};
};
ImageMean imageMean(const Image& image) {
  ImageMean r;
  const double n = double(image.pixels.size());
  for (const vec3& p : image.pixels) r.mean += glm::dvec3(p) / n;
  glm::dvec3 sq(0.0);
  for (const vec3& p : image.pixels) sq += (glm::dvec3(p) - r.mean) * (glm::dvec3(p) - r.mean);
  r.se = sqrt(sq / (n - 1.0) / n);
  return r;
}

// In the furnace every material that loses no energy shows radiance 1, whatever it is; one
// that absorbs shows less, never more. The camera sees the smooth-shaded sphere, which fills
// the view; both backends, nothing invalid.
TEST(MaterialsFurnace, NeverAboveOneAndOneWhenLosslessOnBothBackends) {
  Material transmissive = diffuseTransmission();
  transmissive.reflectance = vec3(0.5f);
  transmissive.transmittance = vec3(0.5f);
  Material coated = coatedDiffuseMaterial(0.2f, vec3(0.0f));
  coated.reflectance = vec3(1.0f);
  Material metal = conductor(0.3f);
  metal.eta = vec3(1.0f);
  metal.k = vec3(200.0f);  // reflectance 0.9999
  struct FurnaceCase {
    const char* name;
    Material m;
    bool lossless;
  };
  for (const FurnaceCase& c :
       {FurnaceCase{"smooth glass", dielectric(1.5f, 0.0f), true},
        FurnaceCase{"thin glass", thinDielectric(1.5f), true},
        FurnaceCase{"diffuse transmission", transmissive, true},
        FurnaceCase{"rough glass", dielectric(1.5f, 0.3f), false},
        FurnaceCase{"rough metal", metal, false}, FurnaceCase{"coated", coated, false}}) {
    SCOPED_TRACE(c.name);
    const SceneData data = prepareScene(furnaceWith(c.m, 0.0f), RenderSettings{});
    EXPECT_TRUE(data.effects.shadingNormals);
    const Comparison cmp = renderBoth(data, 32);
    EXPECT_EQ(cmp.cpu.invalidSamples + cmp.gpu.invalidSamples, 0u);
    EXPECT_EQ(cmp.gpu.validationErrors, 0u);
    for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
      const ImageMean m = imageMean(*image);
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_LE(m.mean[ch], 1.0 + 3.0 * m.se[ch] + 1e-6) << "channel " << ch;
        if (c.lossless) EXPECT_NEAR(m.mean[ch], 1.0, 3.0 * m.se[ch] + 1e-5) << "channel " << ch;
      }
      std::printf("furnace, %s, %s: mean %.5f (standard error %.5f)\n", c.name,
                  image == &cmp.cpuImage ? "cpu" : "vulkan", m.mean.x, m.se.x);
    }
  }
}

// Light sampling weighs a BSDF's f (and, with MIS, its pdf), BSDF sampling only its sample
// weights: in the furnace, whose light comes from every direction, light sampling alone, BSDF
// sampling alone and MIS estimate the same image only if f, pdf and the sampler describe one
// BSDF. CPU, every non-delta type, smooth-shaded sphere.
TEST(MaterialsFurnace, LightSamplingAgreesWithBsdfSampling) {
  Material transmissive = diffuseTransmission();
  Material roughCoat = coatedDiffuseMaterial(0.5f, vec3(0.0f));
  roughCoat.reflectance = vec3(0.8f);
  Material mediumCoat = coatedDiffuseMaterial(0.3f, vec3(0.8f));
  mediumCoat.thickness = 0.3f;
  for (const Material& m :
       {conductor(0.3f), dielectric(1.5f, 0.3f), transmissive, roughCoat, mediumCoat}) {
    SCOPED_TRACE("type " + std::to_string(m.type) + " alpha " + std::to_string(m.alphaX));
    Scene scene = furnaceWith(m, 0.0f);
    scene.camera.width = scene.camera.height = 32;
    Image images[3];
    int i = 0;
    for (uint strategy : {kStrategyBsdf, kStrategyNee, kStrategyMis}) {
      RenderSettings settings;
      settings.strategy = strategy;
      const SceneData data = prepareScene(scene, settings);
      Film film(32, 32);
#ifdef PT_BSDF_TEST_SLOW
      constexpr int kSpp = 64;
#else
      constexpr int kSpp = 512;
#endif
      const RenderStats stats = renderCpu(data, test::cpuOptions(2, kSpp), film);
      EXPECT_EQ(stats.invalidSamples, 0u);
      images[i++] = film.resolve();
    }
    // The mean of the per-pixel differences and its standard error: the image's own variation
    // across pixels cancels.
    for (int k = 1; k < 3; ++k) {
      Image diff = images[k];
      for (size_t p = 0; p < diff.pixels.size(); ++p) diff.pixels[p] -= images[0].pixels[p];
      const ImageMean d = imageMean(diff);
      const double reference = imageMean(images[0]).mean.x;
      std::printf("furnace, type %u: %s - BSDF sampling = %+.5f (se %.5f) of %.5f\n", m.type,
                  k == 1 ? "light sampling" : "MIS", d.mean.x, d.se.x, reference);
      EXPECT_NEAR(d.mean.x, 0.0, 4.0 * d.se.x) << (k == 1 ? "light sampling" : "MIS");
    }
  }
}

// Shading normals twisted by 100 degrees, so that many point below their triangles: every
// material still gives finite samples, and the backends still agree.
TEST(MaterialsShadingNormals, TwistedNormalsStayFiniteOnBothBackends) {
  for (const Material& m :
       {dielectric(1.5f, 0.0f), conductor(0.2f), coatedDiffuseMaterial(0.1f, vec3(0.0f)),
        Material{vec3(0.7f), kMaterialDiffuse, vec3(0.0f), 0}}) {
    SCOPED_TRACE("type " + std::to_string(m.type));
    Scene scene = furnaceWith(m, 100.0f * kPi / 180.0f);
    scene.materials[0].reflectance = vec3(0.3f);  // the walls scatter too
    const SceneData data = prepareScene(std::move(scene), RenderSettings{});
    const Comparison cmp = renderBoth(data, 8);
    EXPECT_EQ(cmp.cpu.invalidSamples + cmp.gpu.invalidSamples, 0u);
    expectAgreement(cmp);
  }
}

// Smooth shading changes the image (the sphere's facets disappear) and the backends agree on
// it, for the seed's materials too.
TEST(MaterialsShadingNormals, SmoothSphereAgreesAndDiffersFromFlatOnBothBackends) {
  Scene scene = loadScene(test::kConfigs / "cornell-box.json");
  Material glass = dielectric(1.5f, 0.0f);
  scene.materials.push_back(glass);
  scene.materialNames.push_back("glass");
  scene.triangles.resize(10);  // walls only; the blocks go
  scene.triangles.push_back(loadScene(test::kConfigs / "cornell-box.json").triangles[30]);
  scene.triangles.push_back(loadScene(test::kConfigs / "cornell-box.json").triangles[31]);
  for (uint i = 0; i < scene.triangles.size(); ++i) scene.triangles[i].primitive = i;
  const size_t before = scene.triangles.size();
  addTwistedSphere(scene, uint(scene.materials.size() - 1), 0.0f);
  for (size_t i = before; i < scene.triangles.size(); ++i) {
    Triangle& t = scene.triangles[i];
    for (vec3* v : {&t.v0, &t.v1, &t.v2}) *v = *v * 120.0f + vec3(278.0f, 150.0f, 280.0f);
  }
  Scene flat = scene;
  flat.normals.clear();
  const RenderSettings settings{.width = 32, .height = 32};
  const SceneData smooth = prepareScene(std::move(scene), settings);
  const SceneData faceted = prepareScene(std::move(flat), settings);
  EXPECT_TRUE(smooth.effects.shadingNormals);
  EXPECT_FALSE(faceted.effects.shadingNormals);
  const Comparison a = renderBoth(smooth, 8);
  expectAgreement(a);
  const Comparison b = renderBoth(faceted, 8);
  expectAgreement(b);
  EXPECT_GT(diffImages(a.cpuImage, b.cpuImage, 1e-3).pixelsOverThreshold, 10u);
}

// The example scenes with these materials, on both backends.
TEST(MaterialsExamples, AgreeOnBothBackends) {
  for (const char* config : {"cornell-materials.json", "veach-mis.json"}) {
    SCOPED_TRACE(config);
    const SceneData data =
        prepareScene(loadScene(test::kConfigs / config), RenderSettings{.width = 48, .height = 32});
    EXPECT_TRUE(data.effects.conductor);
    expectAgreement(renderBoth(data, 8));
  }
}

TEST(Materials, DiffuseOnlySceneUsesNone) {
  const SceneData data = prepareScene(loadScene(test::kConfigs / "cornell-box.json"),
                                      RenderSettings{.width = 16, .height = 16});
  EXPECT_FALSE(data.effects.hasBsdfMaterials());
  EXPECT_EQ(data.effects.toString().find("conductor"), std::string::npos);
}

TEST(Materials, SmoothOnlySceneNeedsNoLightSampling) {
  // Only delta lobes besides the black light: nothing for next-event estimation to do.
  Scene scene = loadScene(test::kConfigs / "cornell-box.json");
  scene.materials[0] = conductor(0.0f);
  scene.materials[1] = dielectric(1.5f, 0.0f);
  scene.materials[2] = thinDielectric(1.5f);
  const SceneData data = prepareScene(std::move(scene), RenderSettings{.width = 16, .height = 16});
  EXPECT_FALSE(data.effects.lightSampling);
  EXPECT_TRUE(data.effects.conductor && data.effects.dielectric && data.effects.thinDielectric);
}

}  // namespace
}  // namespace pt
