// pbrt-v4's point, spot, distant and infinite lights (shaders/lights.h): read from pbrt-v4
// files with its parameters, weighed in the alias table by their power, and rendered on both
// backends against closed forms: a point light's irradiance I cos(theta) / r^2 on a diffuse
// plane, a spot light's smoothstep falloff, a distant light's L cos(theta), and the furnace of
// a convex diffuse object under a constant environment (radiance a everywhere on it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "common/numbers.h"
#include "cpu/integrator.h"
#include "furnace_scene.h"
#include "lights.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/pbrt/pbrt_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

// A camera 10 above the plane z = 0 looking down, whose image is the world unmirrored
// (Scale -1 1 1 before LookAt, as Bitterli's files start), a box filter, and `spp` samples.
std::string header(int size, int spp, int maxDepth) {
  return "Scale -1 1 1\nLookAt 0 0 10  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [40]\n"
         "Film \"rgb\" \"integer xresolution\" [" +
         std::to_string(size) + "] \"integer yresolution\" [" + std::to_string(size) +
         "]\nPixelFilter \"box\"\nSampler \"zsobol\" \"integer pixelsamples\" [" +
         std::to_string(spp) + "]\nIntegrator \"path\" \"integer maxdepth\" [" +
         std::to_string(maxDepth) + "]\nWorldBegin\n";
}

// A diffuse square of albedo 0.5, side 20, in the plane z = 0.
constexpr char kPlane[] =
    "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
    "Shape \"trianglemesh\" \"point3 P\" [-10 -10 0  10 -10 0  10 10 0  -10 10 0]\n"
    "  \"integer indices\" [0 1 2 0 2 3]\n";

SceneData prepareText(const std::string& text) {
  return prepareScene(loadPbrtSceneText(text, "lights.pbrt"), RenderSettings{});
}

// The plane's radiance at x (on z = 0) as a closed form gives it, averaged over each pixel's
// footprint (16 x 16 points of the box filter's square), for comparison with a render.
template <typename Radiance>
Image expectedImage(const SceneData& data, const Radiance& radiance) {
  return pixelAverages(data.params.camera, [&](const Ray& ray) {
    const glm::dvec3 o(ray.origin), d(ray.direction);
    return radiance(o + d * (-o.z / d.z));
  });
}

// Both backends' renders against the closed form, pixel by pixel: within `tolerance` times the
// expected value plus `absolute` (the only noise is where in the pixel each sample lands).
template <typename Radiance>
void expectClosedForm(const std::string& text, const Radiance& radiance, double tolerance,
                      double absolute) {
  const SceneData data = prepareText(text);
  const Image expected = expectedImage(data, radiance);
  const Comparison cmp = renderBoth(data, data.spp);
  expectAgreement(cmp);
  expectNearClosedForm(cmp, expected, absolute, tolerance);
}

TEST(AnalyticLights, PointLightIrradianceOnAPlaneOnBothBackends) {
  // I = (2, 3, 4) * scale 1.5 at (0.5, 0.3, 2): the plane shows (albedo / pi) I cos / r^2.
  const glm::dvec3 light(0.5, 0.3, 2.0);
  const glm::dvec3 intensity = glm::dvec3(2.0, 3.0, 4.0) * 1.5;
  const std::string text = header(24, 16, 1) +
                           "LightSource \"point\" \"rgb I\" [2 3 4] \"float scale\" [1.5] "
                           "\"point3 from\" [0.5 0.3 2]\n" +
                           kPlane;
  expectClosedForm(
      text,
      [&](glm::dvec3 x) {
        const glm::dvec3 d = light - x;
        const double r2 = glm::dot(d, d);
        const double cosTheta = d.z / std::sqrt(r2);
        return 0.5 / kPiD * intensity * cosTheta / r2;
      },
      0.01, 1e-5);
}

TEST(AnalyticLights, SpotLightFalloffOnBothBackends) {
  // A spot at (0, 0, 3) aimed straight down, cone 30 degrees with 10 of falloff, given by its
  // power: I = power / (2 pi (1 - (cosStart + cosEnd) / 2)) (pbrt-v4's SpotLight::Create).
  const double cosEnd = std::cos(30.0 * kPiD / 180.0);
  const double cosStart = std::cos(20.0 * kPiD / 180.0);
  const double intensity = 50.0 / (2.0 * kPiD * (1.0 - 0.5 * (cosStart + cosEnd)));
  const std::string text = header(32, 64, 1) +
                           "AttributeBegin\nTranslate 0 0 3\n"
                           "LightSource \"spot\" \"point3 from\" [0 0 0] \"point3 to\" [0 0 -1] "
                           "\"float coneangle\" [30] \"float conedeltaangle\" [10] "
                           "\"float power\" [50]\nAttributeEnd\n" +
                           kPlane;
  expectClosedForm(
      text,
      [&](glm::dvec3 x) {
        const glm::dvec3 d = glm::dvec3(0, 0, 3) - x;
        const double r = glm::length(d);
        const double cosTheta = d.z / r;  // also the angle to the spot's axis
        const double t = std::clamp((cosTheta - cosEnd) / (cosStart - cosEnd), 0.0, 1.0);
        return glm::dvec3(0.5 / kPiD * intensity * t * t * (3.0 - 2.0 * t) * cosTheta / (r * r));
      },
      // A pixel spans a third of the falloff's width, and its samples meet the smoothstep's
      // kinks at the cone's edges: 1e-3 absolute there (the peak is 1.45).
      0.01, 1e-3);
}

TEST(AnalyticLights, DistantLightCosineOnBothBackends) {
  // Light arriving from direction (1, 0, 2) ("from" - "to"), "illuminance" 3 at normal
  // incidence: the plane shows (albedo / pi) * 3 * cos(theta), the same everywhere.
  const double cosTheta = 2.0 / std::sqrt(5.0);
  const std::string text = header(16, 4, 1) +
                           "LightSource \"distant\" \"point3 from\" [1 0 2] \"point3 to\" [0 0 0] "
                           "\"float illuminance\" [3]\n" +
                           kPlane;
  expectClosedForm(
      text, [&](glm::dvec3) { return glm::dvec3(0.5 / kPiD * 3.0 * cosTheta); }, 1e-5, 0.0);
}

// A cube of albedo 0.5 under a constant environment of radiance 1 (furnace_scene.h), 24 x 24.
std::string furnaceText(int spp, const char* light) {
  return test::furnaceScene(24, spp, light);
}
using test::objectPixels;

TEST(AnalyticLights, FurnaceUnderAConstantEnvironmentOnBothBackends) {
  for (uint strategy : {kStrategyMis, kStrategyNee, kStrategyBsdf}) {
    SCOPED_TRACE(strategy);
    Scene scene = loadPbrtSceneText(furnaceText(64, "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"),
                                    "f.pbrt");
    RenderSettings settings;
    settings.strategy = strategy;
    const SceneData data = prepareScene(std::move(scene), settings);
    EXPECT_TRUE(data.effects.environment);
    const Comparison cmp = renderBoth(data, data.spp);
    expectAgreement(cmp);
    for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
      for (size_t i : objectPixels(*image)) {
        EXPECT_EQ(image->pixels[i].x, image->pixels[i].z);  // grey in, grey out
      }
      // Light sampling alone wastes the half of its directions below the horizon: the noisiest,
      // a standard error of about 0.01.
      test::expectFurnaceMean(*image, 0.012);
    }
  }
}

TEST(AnalyticLights, MaxDepthCountsScatteringEventsAsPbrtDoesOnBothBackends) {
  // pbrt-v4's maxdepth counts scattering events: at 0 a camera ray adds the emission it finds
  // (the environment) and stops, so the cube is black; at 1 it is lit directly (0.5: the cube
  // is convex, so nothing comes from further bounces).
  for (int depth : {0, 1}) {
    RenderSettings settings;
    settings.maxDepth = depth;
    const SceneData data =
        prepareScene(loadPbrtSceneText(
                         furnaceText(16, "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"), "f.pbrt"),
                     settings);
    const Comparison cmp = renderBoth(data, data.spp);
    for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
      const std::vector<size_t> inside = objectPixels(*image);
      ASSERT_GT(inside.size(), 60u);
      double sum = 0.0;
      for (size_t i : inside) sum += image->pixels[i].y;
      if (depth == 0) {
        EXPECT_EQ(sum, 0.0);
      } else {
        EXPECT_NEAR(sum / double(inside.size()), 0.5, 0.01);
      }
    }
  }
}

TEST(AnalyticLights, TwoSidedAreaLightsEmitFromTheirBackOnBothBackends) {
  // A square light 2 above the plane, out of the camera's view: two-sided and facing up, it
  // lights the plane as the same square one-sided and facing down does (pbrt-v4's
  // "twosided"); one-sided and facing up, not at all.
  const auto scene = [&](const char* light, const char* indices) {
    return prepareText(header(16, 64, 1) + "AttributeBegin\nAreaLightSource \"diffuse\" " + light +
                       "\nShape \"trianglemesh\" \"point3 P\" [3.5 -0.5 2  4.5 -0.5 2  4.5 0.5 2"
                       "  3.5 0.5 2] \"integer indices\" [" +
                       indices + "]\nAttributeEnd\n" + kPlane);
  };
  const SceneData twoSided = scene("\"rgb L\" [5 5 5] \"bool twosided\" true", "0 1 2 0 2 3");
  const SceneData down = scene("\"rgb L\" [5 5 5]", "0 2 1 0 3 2");
  const SceneData up = scene("\"rgb L\" [5 5 5]", "0 1 2 0 2 3");
  EXPECT_NE(twoSided.effects.toString().find("two-sided-emitters"), std::string::npos);
  EXPECT_EQ(down.effects.toString().find("two-sided-emitters"), std::string::npos);
  const Comparison both = renderBoth(twoSided, twoSided.spp);
  expectAgreement(both);
  const auto mean = [](const SceneData& data) {
    Film film(int(data.params.camera.width), int(data.params.camera.height));
    renderCpu(data, test::cpuOptions(2, data.spp), film);
    double sum = 0.0;
    for (const vec3& p : film.resolve().pixels) sum += p.y;
    return sum;
  };
  const double sumDown = mean(down);
  EXPECT_GT(sumDown, 1.0);
  EXPECT_NEAR(mean(twoSided), sumDown, 0.01 * sumDown);
  EXPECT_EQ(mean(up), 0.0);
}

TEST(AnalyticLights, EveryKindTogetherAgreesOnBothBackends) {
  // A conductor and a diffuse plane lit by all four kinds and an area light: the light
  // sampling and MIS paths of both vertex kinds, on both backends.
  const std::string text =
      header(24, 8, 4) +
      "LightSource \"point\" \"rgb I\" [1 2 3] \"point3 from\" [1 1 1]\n"
      "LightSource \"spot\" \"point3 from\" [-1 0 2] \"point3 to\" [0 0 0] \"rgb I\" [4 4 4]\n"
      "LightSource \"distant\" \"point3 from\" [0 1 1] \"rgb L\" [0.5 0.4 0.3]\n"
      "LightSource \"infinite\" \"rgb L\" [0.2 0.3 0.4]\n"
      "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [3 3 3]\n"
      "Shape \"trianglemesh\" \"point3 P\" [2 2 3  3 2 3  3 3 3] \"integer indices\" [0 2 1]\n"
      "AttributeEnd\n"
      "AttributeBegin\nMaterial \"conductor\" \"float roughness\" [0.2]\n"
      "Shape \"trianglemesh\" \"point3 P\" [-2 -2 0.5  0 -2 0.5  0 0 1.5  -2 0 1.5]\n"
      "  \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n" +
      std::string(kPlane);
  const SceneData data = prepareText(text);
  EXPECT_EQ(data.lights.size(), 4u);
  EXPECT_EQ(data.emitters.size(), 5u);
  EXPECT_NE(data.effects.toString().find("delta-lights+environment"), std::string::npos)
      << data.effects.toString();
  expectAgreement(renderBoth(data, data.spp));
}

TEST(AnalyticLights, AliasTableSplitsAsPbrtsDefaultSampler) {
  // Distant and infinite lights 1 / (U + 1) each; the lights with a position share the rest by
  // pbrt-v4's Phi over pi: point 4 I, spot 2 I (1 - (cosStart + cosEnd) / 2), next to a
  // triangle's area x radiance.
  std::vector<Triangle> triangles = {
      Triangle{vec3(0, 0, 0), 0, vec3(2, 0, 0), 0, vec3(0, 1, 0), 0}};
  std::vector<Material> materials(1);
  materials[0].emission = vec3(3.0f);  // area 1: weight 3
  std::vector<Light> lights(4);
  lights[0].type = kLightPoint;
  lights[0].radiance = vec3(1.0f);  // 4
  lights[1].type = kLightSpot;
  lights[1].radiance = vec3(2.0f);
  lights[1].cosFalloffStart = 0.5f;
  lights[1].cosFalloffEnd = 0.0f;  // 2 * 2 * 0.75 = 3
  lights[2].type = kLightDistant;
  lights[2].radiance = vec3(0.5f);
  lights[3].type = kLightInfinite;
  lights[3].radiance = vec3(1.0f);
  const std::vector<Emitter> emitters = buildEmitters(triangles, materials, lights, 2.0f);
  ASSERT_EQ(emitters.size(), 5u);
  const double pmfs[] = {3.0 / 30, 4.0 / 30, 3.0 / 30, 1.0 / 3, 1.0 / 3};
  double aliasMass[5] = {};  // what the alias table gives each: its slots and what they lend
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_NEAR(emitters[i].pmf, pmfs[i], 1e-6) << i;
    EXPECT_EQ(emitters[i].triangle, i == 0 ? 0u : (kEmitterLight | uint(i - 1)));
    aliasMass[i] += emitters[i].aliasThreshold / 5.0;
    aliasMass[emitters[i].alias] += (1.0 - emitters[i].aliasThreshold) / 5.0;
  }
  for (size_t i = 0; i < 5; ++i) EXPECT_NEAR(aliasMass[i], pmfs[i], 1e-6) << i;

  // Only lights without a position: 1 / U each. Without those: by power, as for triangles.
  std::vector<Triangle> none;
  const std::vector<Emitter> sky = buildEmitters(none, materials, {lights[2], lights[3]}, 2.0f);
  ASSERT_EQ(sky.size(), 2u);
  EXPECT_FLOAT_EQ(sky[0].pmf, 0.5f);
  const std::vector<Emitter> local =
      buildEmitters(triangles, materials, {lights[0], lights[1]}, 2.0f);
  ASSERT_EQ(local.size(), 3u);
  EXPECT_NEAR(local[1].pmf, 0.4, 1e-6);
}

TEST(AnalyticLights, SampledDirectionsAndRadiances) {
  Light point{};
  point.type = kLightPoint;
  point.position = vec3(0, 0, 2);
  point.radiance = vec3(8.0f);
  const AnalyticLightSample s = sampleAnalyticLight(point, vec3(0.0f), vec2(0.3f), 5.0f);
  EXPECT_TRUE(s.delta);
  EXPECT_EQ(s.wi, vec3(0, 0, 1));
  EXPECT_EQ(s.Li, vec3(2.0f));  // 8 / 2^2
  EXPECT_EQ(s.target, point.position);

  // The spot's smoothstep: full inside cosStart, none outside cosEnd, 0.5 half-way.
  Light spot = point;
  spot.type = kLightSpot;
  spot.direction = vec3(0, 0, -1);
  spot.cosFalloffStart = 0.9f;
  spot.cosFalloffEnd = 0.7f;
  const auto spotAt = [&](float cosAngle) {
    const float sinAngle = std::sqrt(1.0f - cosAngle * cosAngle);
    const vec3 p = spot.position + 2.0f * vec3(sinAngle, 0.0f, -cosAngle);
    return sampleAnalyticLight(spot, p, vec2(0.0f), 5.0f).Li.x;
  };
  EXPECT_NEAR(spotAt(0.95f), 2.0f, 1e-5f);
  EXPECT_NEAR(spotAt(0.8f), 1.0f, 1e-4f);
  EXPECT_EQ(spotAt(0.6f), 0.0f);

  // Distant: the one direction; the shadow ray ends 2 r away.
  Light distant{};
  distant.type = kLightDistant;
  distant.direction = vec3(0, 1, 0);
  distant.radiance = vec3(1.5f);
  const AnalyticLightSample d = sampleAnalyticLight(distant, vec3(1, 0, 0), vec2(0.5f), 5.0f);
  EXPECT_TRUE(d.delta);
  EXPECT_EQ(d.target, vec3(1, 10, 0));
  EXPECT_EQ(d.Li, vec3(1.5f));

  // Infinite: uniform directions, density 1 / (4 pi); z spread evenly over [-1, 1].
  Light sky{};
  sky.type = kLightInfinite;
  sky.radiance = vec3(1.0f);
  int upper = 0;
  constexpr int kN = 4096;
  for (int i = 0; i < kN; ++i) {
    const vec2 u((float(i) + 0.5f) / kN, float((i * 2654435761u) % kN) / kN);
    const AnalyticLightSample e = sampleAnalyticLight(sky, vec3(0.0f), u, 1.0f);
    EXPECT_FALSE(e.delta);
    EXPECT_NEAR(length(e.wi), 1.0f, 1e-5f);
    EXPECT_FLOAT_EQ(e.pdf, 1.0f / (4.0f * float(kPiD)));
    if (e.wi.z > 0.5f) ++upper;  // a quarter of the sphere's area
  }
  EXPECT_NEAR(double(upper) / kN, 0.25, 0.01);
}

TEST(AnalyticLights, PbrtParametersAndTransforms) {
  // Point: "from" through the CTM; power P gives I = P / (4 pi) per unit of I.
  {
    const Scene scene = loadPbrtSceneText(
        header(8, 1, 1) +
            "Translate 1 2 3\nLightSource \"point\" \"rgb I\" [1 0.5 0.25] \"float power\" [10] "
            "\"point3 from\" [1 1 1]\n" +
            kPlane,
        "p.pbrt");
    ASSERT_EQ(scene.lights.size(), 1u);
    EXPECT_EQ(scene.lights[0].type, kLightPoint);
    EXPECT_EQ(scene.lights[0].position, vec3(2, 3, 4));
    EXPECT_NEAR(scene.lights[0].radiance.x, 10.0 / (4.0 * kPiD), 1e-6);
    EXPECT_NEAR(scene.lights[0].radiance.z, 0.25 * 10.0 / (4.0 * kPiD), 1e-6);
  }
  // A camera placed by LookAt alone mirrors the world in x (see docs/pbrt-format.md): the
  // light follows the geometry.
  {
    const Scene scene = loadPbrtSceneText(
        "LookAt 0 0 10  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
        "LightSource \"spot\" \"point3 from\" [1 2 3] \"point3 to\" [1 2 0]\n"
        "LightSource \"distant\" \"point3 from\" [1 0 0] \"point3 to\" [0 0 0]\n"
        "LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5] \"float illuminance\" [2]\n" +
            std::string(kPlane),
        "m.pbrt");
    ASSERT_EQ(scene.lights.size(), 3u);
    EXPECT_EQ(scene.lights[0].position, vec3(-1, 2, 3));
    EXPECT_EQ(scene.lights[0].direction, vec3(0, 0, -1));
    EXPECT_NEAR(scene.lights[0].cosFalloffEnd, std::cos(30.0 * kPiD / 180.0), 1e-6);
    EXPECT_NEAR(scene.lights[0].cosFalloffStart, std::cos(25.0 * kPiD / 180.0), 1e-6);
    EXPECT_EQ(scene.lights[0].radiance, vec3(1.0f));  // the default I: the illuminant, white
    EXPECT_EQ(scene.lights[1].direction, vec3(-1, 0, 0));
    // Illuminance E from a constant environment: L = E / pi per unit of L.
    EXPECT_NEAR(scene.lights[2].radiance.y, 0.5 * 2.0 / kPiD, 1e-6);
  }
}

TEST(AnalyticLights, BadLightsAreOneLineErrors) {
  const auto errorOf = [](const std::string& light) -> std::string {
    try {
      loadPbrtSceneText(header(8, 1, 1) + light + kPlane, "bad.pbrt");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(errorOf("LightSource \"laser\"\n").find("bad.pbrt:9:13: unknown light type"),
            std::string::npos)
      << errorOf("LightSource \"laser\"\n");
  EXPECT_NE(errorOf("LightSource \"point\" \"float scale\" [-1]\n").find("must not be negative"),
            std::string::npos);
  EXPECT_NE(errorOf("LightSource \"spot\" \"point3 from\" [1 1 1] \"point3 to\" [1 1 1]\n")
                .find("has no direction"),
            std::string::npos);
  EXPECT_NE(errorOf("LightSource \"point\" \"rgb I\" [1e39 1 1]\n").find("32-bit float"),
            std::string::npos);
  EXPECT_NE(errorOf("LightSource \"infinite\" \"string filename\" [\"missing.exr\"]\n")
                .find("bad.pbrt:9:"),
            std::string::npos);
}

TEST(AnalyticLights, JsonLights) {
  const test::TempDir dir;
  const std::string start =
      R"({"materials": [{"name": "m", "type": "diffuse", "reflectance": [0.5, 0.5, 0.5]}],
          "shapes": [{"type": "triangles", "material": "m",
                      "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 2]]}],
          "lights": )";
  const Scene scene = loadScene(dir.write(
      "ok.json", start + R"([{"type": "point", "position": [1, 2, 3], "intensity": [4, 5, 6]},
        {"type": "spot", "position": [0, 0, 1], "target": [0, 0, 0], "intensity": [1, 1, 1],
         "coneAngle": 40, "coneDeltaAngle": 10},
        {"type": "distant", "direction": [0, 0, 2], "radiance": [2, 2, 2]},
        {"type": "environment", "radiance": [0.1, 0.2, 0.3]}]})"));
  ASSERT_EQ(scene.lights.size(), 4u);
  EXPECT_EQ(scene.lights[0].type, kLightPoint);
  EXPECT_EQ(scene.lights[0].position, vec3(1, 2, 3));
  EXPECT_EQ(scene.lights[0].radiance, vec3(4, 5, 6));
  EXPECT_EQ(scene.lights[1].type, kLightSpot);
  EXPECT_EQ(scene.lights[1].direction, vec3(0, 0, -1));
  EXPECT_NEAR(scene.lights[1].cosFalloffEnd, std::cos(40.0 * kPiD / 180.0), 1e-6);
  EXPECT_NEAR(scene.lights[1].cosFalloffStart, std::cos(30.0 * kPiD / 180.0), 1e-6);
  EXPECT_EQ(scene.lights[2].direction, vec3(0, 0, 1));
  EXPECT_EQ(scene.lights[3].type, kLightInfinite);

  const auto errorOf = [&](const std::string& lights) -> std::string {
    try {
      loadScene(dir.write("bad.json", start + lights + "}"));
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(errorOf(R"([{"type": "laser"}])").find("lights[0].type: unknown light type"),
            std::string::npos)
      << errorOf(R"([{"type": "laser"}])");
  EXPECT_NE(errorOf(R"([{"type": "point", "position": [0, 0, 0], "intensity": [1, -1, 1]}])")
                .find("lights[0].intensity[1]"),
            std::string::npos);
  EXPECT_NE(errorOf(R"([{"type": "distant", "direction": [0, 0, 0], "radiance": [1, 1, 1]}])")
                .find("lights[0].direction: has no direction"),
            std::string::npos);
  EXPECT_NE(errorOf(R"([{"type": "environment", "radiance": [1, 1, 1], "L": 1}])")
                .find("lights[0].L: unknown key"),
            std::string::npos);
  EXPECT_NE(errorOf(R"([{"type": "point", "intensity": [1, 1, 1]}])").find("position"),
            std::string::npos);
}

// Pearson's chi-square test of a light's sampled directions (seen from `p`) against `pdf`
// (tests/chi2.h, as the BSDF tests use it): a grid focused where pilot samples fall, each
// cell's expected count the pdf's integral over it.
template <typename Pdf>
test::Chi2Result lightChi2(const Light& light, vec3 p, float sceneRadius, const Pdf& pdf,
                           uint32_t seed, bool isTheSamplersPdf = true) {
  constexpr int kSamples = 200000;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  const auto draw = [&] {
    const vec2 u(uniform(rng), uniform(rng));
    return sampleAnalyticLight(light, p, u, sceneRadius);
  };
  std::vector<glm::vec3> pilot;
  for (int i = 0; i < 2000; ++i) pilot.push_back(draw().wi);
  const test::SphereGrid grid = test::focusedGrid(pilot, 20, 40);
  std::vector<double> observed(size_t(grid.cellCount()), 0.0);
  for (int i = 0; i < kSamples; ++i) {
    const AnalyticLightSample s = draw();
    EXPECT_FALSE(s.delta);
    if (isTheSamplersPdf) {
      EXPECT_NEAR(double(s.pdf), pdf(s.wi), 1e-4 * pdf(s.wi)) << "the sample's own pdf";
    }
    observed[size_t(grid.cellOf(s.wi))] += 1.0;
  }
  return test::pearsonChi2(observed, test::expectedCounts(grid, pdf, kSamples));
}

TEST(AnalyticLights, InfiniteLightSamplerPassesChiSquare) {
  Light sky{};
  sky.type = kLightInfinite;
  sky.radiance = vec3(1.0f);
  const auto uniform = [](vec3) { return 1.0 / (4.0 * kPiD); };
  const test::Chi2Result good = lightChi2(sky, vec3(0.0f), 1.0f, uniform, 7u);
  EXPECT_GE(good.pValue, 1e-4) << "chi2 " << good.statistic << ", " << good.dof << " dof";
  // A density leaning 20 % towards +z is told apart.
  const auto leaning = [](vec3 w) { return (1.0 + 0.2 * double(w.z)) / (4.0 * kPiD); };
  const test::Chi2Result bad = lightChi2(sky, vec3(0.0f), 1.0f, leaning, 7u, false);
  EXPECT_LT(bad.pValue, 1e-4) << "chi2 " << bad.statistic;
}

// Pearson's chi-square test of a sphere light's sampled directions, seen from p, against the
// density uniform over the cone of a sphere of `coneRadius` (1 / (2 pi (1 - cos thetaMax))):
// uniform in (1 - cos theta) / (1 - cos thetaMax) and in the angle about the axis, the
// variables the histogram takes (a grid over directions would cut the cone's sharp edge into
// slivers no quadrature resolves).
test::Chi2Result sphereChi2(const Light& sphere, vec3 p, double coneRadius, uint32_t seed) {
  constexpr int kSamples = 200000, kRings = 20, kSectors = 20;
  const glm::dvec3 toCentre = glm::dvec3(sphere.position) - glm::dvec3(p);
  const glm::dvec3 axis = glm::normalize(toCentre);
  const glm::dvec3 t = glm::normalize(
      glm::cross(axis, std::fabs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  const glm::dvec3 b = glm::cross(axis, t);
  const double sin2 = coneRadius * coneRadius / glm::dot(toCentre, toCentre);
  const double oneMinusCosMax = sin2 / (1.0 + std::sqrt(1.0 - sin2));  // 1 - cos, no cancelling
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  // One cell more than the grid: samples outside the cone.
  std::vector<double> observed(size_t(kRings * kSectors) + 1, 0.0);
  for (int i = 0; i < kSamples; ++i) {
    const AnalyticLightSample s =
        sampleAnalyticLight(sphere, p, vec2(uniform(rng), uniform(rng)), 1.0f);
    const glm::dvec3 w(s.wi);
    const double sin2Theta = glm::dot(glm::cross(w, axis), glm::cross(w, axis));
    const double cosTheta = glm::dot(w, axis);
    const double v = (sin2Theta / (1.0 + cosTheta)) / oneMinusCosMax;
    double phi = std::atan2(glm::dot(w, b), glm::dot(w, t)) / (2.0 * kPiD);
    if (phi < 0.0) phi += 1.0;
    const int ring = int(v * kRings);
    const int sector = std::min(int(phi * kSectors), kSectors - 1);
    observed[ring < kRings ? size_t(ring * kSectors + sector) : observed.size() - 1] += 1.0;
  }
  std::vector<double> expected(observed.size(), double(kSamples) / (kRings * kSectors));
  expected.back() = 1e-6;  // nothing outside the cone
  return test::pearsonChi2(observed, expected);
}

TEST(AnalyticLights, SphereLightSamplerPassesChiSquare) {
  // Seen from 3 and from 200 radii away (pbrt-v4's small-angle branch below 1.5 degrees).
  for (float distance : {3.0f, 200.0f}) {
    SCOPED_TRACE(distance);
    Light sphere{};
    sphere.type = kLightSphere;
    sphere.position = vec3(0.3f, -0.2f, distance);
    sphere.radius = 1.0f;
    sphere.radiance = vec3(1.0f);
    const vec3 p(0.0f);
    const test::Chi2Result good = sphereChi2(sphere, p, 1.0, 11u);
    EXPECT_GE(good.pValue, 1e-4) << "chi2 " << good.statistic << ", " << good.dof << " dof";
    // The cone of a sphere 2 % larger, or 2 % smaller, is told apart.
    EXPECT_LT(sphereChi2(sphere, p, 1.02, 11u).pValue, 1e-4);
    EXPECT_LT(sphereChi2(sphere, p, 0.98, 11u).pValue, 1e-4);
    // Each sample's own density is the cone's, and its point on the sphere (the shadow ray
    // ends the ray offset beyond it), on the side facing p.
    const double dc = double(length(sphere.position));
    const double sin2 = 1.0 / (dc * dc);
    const double oneMinusCosMax = sin2 < 0.00068523 ? 0.5 * sin2 : 1.0 - std::sqrt(1.0 - sin2);
    for (int i = 0; i < 1000; ++i) {
      const vec2 u((float(i) + 0.5f) / 1000.0f, float((i * 7919) % 1000) / 1000.0f);
      const AnalyticLightSample ls = sampleAnalyticLight(sphere, p, u, 1.0f);
      EXPECT_FALSE(ls.delta);
      EXPECT_NEAR(ls.pdf, 1.0 / (2.0 * kPiD * oneMinusCosMax), 1e-4 * ls.pdf);
      const vec3 n = normalize(ls.target - sphere.position);
      EXPECT_NEAR(length(ls.target - sphere.position), 1.0f + dc / 65536.0, 1e-4f);
      EXPECT_LT(dot(n, ls.wi), 1e-3f);
      EXPECT_EQ(ls.Li, vec3(1.0f));
    }
    // From inside: no sample, density 0.
    EXPECT_EQ(sampleAnalyticLight(sphere, sphere.position, vec2(0.5f), 1.0f).Li, vec3(0.0f));
    EXPECT_EQ(sphereLightPdf(sphere, sphere.position), 0.0f);
  }
}

TEST(AnalyticLights, SphereLightIrradianceOnAPlaneOnBothBackends) {
  // A sphere of radius 0.5 and radiance 5 centred 1.2 above the plane (out of the camera's
  // view): irradiance
  // pi L sin^2(thetaMax) cos(theta) where it sees the whole sphere, so the plane shows
  // albedo * L * sin^2(thetaMax) * cos(theta). The sphere is drawn by solid angle; BSDF-sampled
  // rays find its 16128 triangles (1 - 2e-4 of its solid angle: the tolerance's floor).
  const glm::dvec3 centre(4.5, 0.5, 1.2);
  // 128 samples: MIS mixes in the rarer BSDF-sampled hits, the only noise here.
  const std::string text = header(24, 128, 1) +
                           "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [5 5 5]\n"
                           "Translate 4.5 0.5 1.2\nShape \"sphere\" \"float radius\" 0.5\n"
                           "AttributeEnd\n" +
                           kPlane;
  const SceneData data = prepareText(text);
  ASSERT_EQ(data.lights.size(), 1u);
  EXPECT_EQ(data.lights[0].type, kLightSphere);
  EXPECT_EQ(data.emitters.size(), 1u);  // the sphere, not its triangles
  EXPECT_NE(data.effects.toString().find("sphere-lights"), std::string::npos);
  expectClosedForm(
      text,
      [&](glm::dvec3 x) {
        const glm::dvec3 d = centre - x;
        const double dist2 = glm::dot(d, d);
        const double cosTheta = d.z / std::sqrt(dist2);
        // (It holds where the whole sphere is above the horizon: everywhere, the sphere's
        // lowest point being 0.7 above the plane.)
        return glm::dvec3(0.5 * 5.0 * (0.25 / dist2) * cosTheta);
      },
      0.01, 1e-4);
}

TEST(AnalyticLights, OnlyTrueSpheresAreSampledByTheirCone) {
  const auto lightsOf = [&](const std::string& shape) {
    return loadPbrtSceneText(
               header(8, 1, 1) + "AttributeBegin\n" + shape + "AttributeEnd\n" + kPlane, "s.pbrt")
        .lights;
  };
  const char* sphere = "Shape \"sphere\" \"float radius\" 0.5\n";
  const std::string light = "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n";
  // Rotated and uniformly scaled: a sphere of radius 0.5 x 3 about the moved centre.
  const auto scaled = lightsOf(light + "Translate 1 2 3\nRotate 30 1 1 0\nScale 3 3 3\n" + sphere);
  ASSERT_EQ(scaled.size(), 1u);
  EXPECT_NEAR(scaled[0].radius, 1.5f, 1e-6f);
  EXPECT_NEAR(distance(scaled[0].position, vec3(1, 2, 3)), 0.0f, 1e-6f);
  // An ellipsoid, a two-sided or an inward light, a sphere without light: triangles only.
  EXPECT_TRUE(lightsOf(light + "Scale 1 2 1\n" + sphere).empty());
  EXPECT_TRUE(lightsOf("AreaLightSource \"diffuse\" \"bool twosided\" true\n" + std::string(sphere))
                  .empty());
  EXPECT_TRUE(lightsOf(light + "ReverseOrientation\n" + sphere).empty());
  EXPECT_TRUE(lightsOf(sphere).empty());
}

}  // namespace
}  // namespace pt
