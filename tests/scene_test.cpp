// Tests of the scene loader (host/scene): the triangles and settings a valid scene yields,
// the camera basis, and the one-line InputError every kind of bad input must produce.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/check.h"
#include "render/camera.h"
#include "scene/load_scene.h"
#include "scene/reader_helpers.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

const fs::path kData = fs::path(PT_SOURCE_DIR) / "tests" / "data" / "scene";

using test::TempDir;  // a fresh directory for the files one test writes

// Minimal scene around the given shapes/materials JSON fragments.
std::string sceneJson(const std::string& materials, const std::string& shapes,
                      const std::string& extra = "") {
  return "{" + extra + (extra.empty() ? "" : ", ") + "\"materials\": " + materials +
         ", \"shapes\": " + shapes + "}";
}

const std::string kWhite = R"([{"name": "white"}])";
const std::string kUnitQuad =
    R"([{"type": "quad", "material": "white", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]}])";

// Loads `path` and returns the InputError message; fails the test if it loads, throws
// anything else, or the message is not one line starting with `prefix` (the file name).
std::string loadError(const fs::path& path, const std::string& prefix) {
  try {
    loadScene(path);
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(prefix + ": ", 0), 0u) << message;
    return message;
  }
  ADD_FAILURE() << "expected InputError loading " << path;
  return {};
}

std::string loadError(const fs::path& path) {
  return loadError(path, path.string());
}

// Writes `json` to a temporary scene file and returns its load error.
std::string errorFor(const TempDir& dir, const std::string& json) {
  return loadError(dir.write("scene.json", json));
}

::testing::AssertionResult contains(const std::string& haystack, const std::string& needle) {
  if (haystack.find(needle) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "message: " << haystack << "\nexpected to contain: " << needle;
}

// Evaluates each argument once (the haystack is usually a load).
#define EXPECT_CONTAINS(haystack, needle) EXPECT_TRUE(contains((haystack), (needle)))

void expectTriangle(const Triangle& t, glm::vec3 v0, glm::vec3 v1, glm::vec3 v2, uint material,
                    uint primitive) {
  EXPECT_EQ(t.v0, v0) << "primitive " << primitive;
  EXPECT_EQ(t.v1, v1) << "primitive " << primitive;
  EXPECT_EQ(t.v2, v2) << "primitive " << primitive;
  EXPECT_EQ(t.material, material) << "primitive " << primitive;
  EXPECT_EQ(t.emitter, kNoEmitter);
  EXPECT_EQ(t.primitive, primitive);
}

// ---- valid scenes -----------------------------------------------------------------------

TEST(SceneLoad, ValidSceneGivesExpectedTriangles) {
  const Scene scene = loadScene(kData / "valid.json");
  EXPECT_TRUE(scene.warnings.empty());

  ASSERT_EQ(scene.materials.size(), 3u);
  EXPECT_EQ(scene.materialNames, (std::vector<std::string>{"white", "light", "mirror"}));
  EXPECT_EQ(scene.materials[0].type, kMaterialDiffuse);
  EXPECT_EQ(scene.materials[0].reflectance, glm::vec3(0.5f, 0.25f, 1.0f));
  EXPECT_EQ(scene.materials[0].emission, glm::vec3(0.0f));
  EXPECT_EQ(scene.materials[1].emission, glm::vec3(17.0f, 12.0f, 4.0f));
  EXPECT_EQ(scene.materials[1].reflectance, glm::vec3(0.0f));
  EXPECT_EQ(scene.materials[2].type, kMaterialMirror);
  EXPECT_EQ(scene.materials[2].reflectance, glm::vec3(1.0f));  // mirror default
  for (const Material& m : scene.materials) EXPECT_EQ(m.twoSided, 0u);

  const std::vector<Triangle>& t = scene.triangles;
  ASSERT_EQ(t.size(), 11u);
  // Quad: (v0, v1, v2) and (v0, v2, v3).
  expectTriangle(t[0], {1, 0, 0}, {0, 0, 0}, {0, 0, 1}, 0, 0);
  expectTriangle(t[1], {1, 0, 0}, {0, 0, 1}, {1, 0, 1}, 0, 1);
  // Quad scaled by 2, rotated 90 degrees about +y ((x, y, z) -> (z, y, -x)), moved by +10 x.
  expectTriangle(t[2], {10, 0, 0}, {10, 0, -2}, {10, 2, -2}, 1, 2);
  expectTriangle(t[3], {10, 0, 0}, {10, 2, -2}, {10, 2, 0}, 1, 3);
  // Indexed triangles scaled by (1, 2, 3) then moved by (0.5, 0.25, 0).
  expectTriangle(t[4], {0.5f, 0.25f, 0}, {1.5f, 0.25f, 0}, {0.5f, 2.25f, 0}, 2, 4);
  expectTriangle(t[5], {1.5f, 0.25f, 0}, {1.5f, 2.25f, 0}, {0.5f, 2.25f, 0}, 2, 5);
  // OBJ pentagon fanned from its first vertex.
  expectTriangle(t[6], {0, 0, 0}, {1, 0, 0}, {2, 1, 0}, 0, 6);
  expectTriangle(t[7], {0, 0, 0}, {2, 1, 0}, {1, 2, 0}, 0, 7);
  expectTriangle(t[8], {0, 0, 0}, {1, 2, 0}, {0, 1, 0}, 0, 8);
  // OBJ with negative indices, rotated 180 degrees about z ((x, y, z) -> (-x, -y, z)).
  expectTriangle(t[9], {0, 0, 0}, {-1, 0, 0}, {0, -1, 0}, 1, 9);
  expectTriangle(t[10], {-5, -5, 5}, {-6, -5, 5}, {-5, -6, 5}, 1, 10);
}

TEST(SceneLoad, CameraAndIntegratorSettings) {
  const Scene scene = loadScene(kData / "valid.json");
  EXPECT_EQ(scene.camera.position, glm::vec3(278, 273, -800));
  EXPECT_EQ(scene.camera.target, glm::vec3(278, 273, 0));
  EXPECT_EQ(scene.camera.up, glm::vec3(0, 1, 0));
  EXPECT_FLOAT_EQ(scene.camera.vfovDegrees, 39.3077f);
  EXPECT_EQ(scene.camera.width, 320);
  EXPECT_EQ(scene.camera.height, 240);
  EXPECT_EQ(scene.integrator.spp, 8);
  EXPECT_EQ(scene.integrator.maxDepth, 5);
  EXPECT_EQ(scene.integrator.seed, 7u);
  EXPECT_FALSE(scene.integrator.russianRoulette);
  EXPECT_EQ(scene.integrator.rrStartDepth, 2);
  EXPECT_EQ(scene.integrator.strategy, kStrategyNee);
}

TEST(SceneLoad, DefaultsWhenCameraAndIntegratorAreMissing) {
  TempDir dir;
  const Scene scene = loadScene(dir.write("scene.json", sceneJson(kWhite, kUnitQuad)));
  const CameraDesc camera;
  const IntegratorSettings integrator;
  EXPECT_EQ(scene.camera.position, camera.position);
  EXPECT_EQ(scene.camera.target, camera.target);
  EXPECT_EQ(scene.camera.vfovDegrees, camera.vfovDegrees);
  EXPECT_EQ(scene.camera.width, camera.width);
  EXPECT_EQ(scene.integrator.spp, integrator.spp);
  EXPECT_EQ(scene.integrator.maxDepth, integrator.maxDepth);
  EXPECT_EQ(scene.integrator.strategy, integrator.strategy);
  EXPECT_EQ(scene.integrator.sampler, integrator.sampler);
  EXPECT_EQ(scene.integrator.russianRoulette, integrator.russianRoulette);
  EXPECT_EQ(scene.materials[0].reflectance, glm::vec3(0.8f));  // diffuse default
  EXPECT_EQ(scene.triangles.size(), 2u);
}

TEST(SceneLoad, IntegratorEdgeValues) {
  TempDir dir;
  const Scene scene = loadScene(dir.write(
      "scene.json", sceneJson(kWhite, kUnitQuad,
                              R"("integrator": {"spp": 64.0, "maxDepth": 0, "seed": 4294967295,
                                  "rrStartDepth": 1, "strategy": "bsdf",
                                  "sampler": "independent"})")));
  EXPECT_EQ(scene.integrator.spp, 64);  // integral floats are accepted
  EXPECT_EQ(scene.integrator.maxDepth, 0);
  EXPECT_EQ(scene.integrator.seed, 4294967295u);
  EXPECT_EQ(scene.integrator.rrStartDepth, 1);
  EXPECT_EQ(scene.integrator.strategy, kStrategyBsdf);
  EXPECT_EQ(scene.integrator.sampler, kSamplerIndependent);
}

TEST(SceneLoad, MirroringTransformKeepsVertexOrder) {
  TempDir dir;
  const Scene scene = loadScene(
      dir.write("scene.json", sceneJson(kWhite, R"([{"type": "triangles", "material": "white",
          "vertices": [[1,0,0],[2,0,0],[1,1,0]], "indices": [[0,1,2]],
          "transform": {"scale": [-1, 1, 1]}}])")));
  ASSERT_EQ(scene.triangles.size(), 1u);
  // Vertices are mirrored one by one and not reordered, so the geometric normal
  // (v1 - v0) x (v2 - v0) turns from +z to -z: the emitting side flips.
  expectTriangle(scene.triangles[0], {-1, 0, 0}, {-2, 0, 0}, {-1, 1, 0}, 0, 0);
  const Triangle& t = scene.triangles[0];
  EXPECT_LT(glm::cross(t.v1 - t.v0, t.v2 - t.v0).z, 0.0f);
}

TEST(SceneLoad, RotationAboutArbitraryAxis) {
  TempDir dir;
  // 120 degrees about (1, 1, 1) cycles the axes: x -> y -> z -> x.
  const Scene scene = loadScene(
      dir.write("scene.json", sceneJson(kWhite, R"([{"type": "triangles", "material": "white",
          "vertices": [[1,0,0],[0,1,0],[0,0,1]], "indices": [[0,1,2]],
          "transform": {"rotate": {"axis": [2, 2, 2], "degrees": 120}}}])")));
  ASSERT_EQ(scene.triangles.size(), 1u);
  const Triangle& t = scene.triangles[0];
  const float eps = 1e-6f;
  EXPECT_NEAR(t.v0.x, 0, eps);
  EXPECT_NEAR(t.v0.y, 1, eps);
  EXPECT_NEAR(t.v0.z, 0, eps);
  EXPECT_NEAR(t.v1.z, 1, eps);
  EXPECT_NEAR(t.v2.x, 1, eps);
}

TEST(SceneLoad, StanfordBunny) {
  const fs::path bunny = "/usr/share/glmark2/models/bunny.obj";
  if (!fs::exists(bunny)) GTEST_SKIP() << bunny << " is not installed";
  TempDir dir;
  const Scene scene = loadScene(dir.write(
      "scene.json", sceneJson(kWhite, R"([{"type": "obj", "name": "bunny", "material": "white",
          "file": ")" + bunny.string() + R"(", "transform": {"scale": 100}}])")));
  // Every face is kept unless it has zero area, which is then reported.
  std::size_t dropped = 0;
  for (const std::string& w : scene.warnings) {
    EXPECT_CONTAINS(w, "shapes[0]: dropped ");
    dropped += std::stoul(w.substr(w.find("dropped ") + 8));
  }
  EXPECT_EQ(scene.triangles.size() + dropped, 69666u);
  EXPECT_GT(scene.triangles.size(), 69000u);
  EXPECT_EQ(scene.triangles.back().primitive, scene.triangles.size() - 1);
}

TEST(SceneLoad, ObjLineEndingsAndComments) {
  TempDir dir;
  // CRLF and lone CR line ends, comments, groups, a material library we ignore, extra
  // vertex colours and a w coordinate.
  dir.write("m.obj",
            "# comment\r\nmtllib none.mtl\r\ng a\r\nv 0 0 0 1\rv 1 0 0 0.5 0.5 0.5\r\n"
            "v 0 1 0\r\nusemtl x\r\ns off\r\nf 1 2 3\r\n");
  const Scene scene = loadScene(
      dir.write("scene.json",
                sceneJson(kWhite, R"([{"type": "obj", "material": "white", "file": "m.obj"}])")));
  ASSERT_EQ(scene.triangles.size(), 1u);
  expectTriangle(scene.triangles[0], {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0, 0);
}

TEST(SceneLoad, ObjSignsAndNumberForms) {
  TempDir dir;
  dir.write("m.obj", "v +.5 -0 1e0\nv 1.5E+0 0. -0.0\nv .5 1 0\nf +1 -2 3\n");
  const Scene scene = loadScene(
      dir.write("scene.json",
                sceneJson(kWhite, R"([{"type": "obj", "material": "white", "file": "m.obj"}])")));
  ASSERT_EQ(scene.triangles.size(), 1u);
  expectTriangle(scene.triangles[0], {0.5f, 0, 1}, {1.5f, 0, 0}, {0.5f, 1, 0}, 0, 0);
}

// ---- zero-area triangles ----------------------------------------------------------------

TEST(SceneDegenerate, ZeroAreaTrianglesAreDroppedWithOneWarning) {
  TempDir dir;
  const fs::path path = dir.write("scene.json", sceneJson(kWhite, R"([
        {"type": "quad", "material": "white", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]},
        {"type": "triangles", "material": "white",
         "vertices": [[0,0,0],[1,0,0],[0,1,0],[2,0,0],[0.5,1e-7,0],[1e6,1e6,1e6]],
         "indices": [[0,1,2],[0,0,1],[0,1,3],[0,1,4],[2,2,2],[5,5,0]]}])"));
  const Scene scene = loadScene(path);
  // Kept: the quad's two halves, the right triangle and the thin sliver (0, 1, 4); dropped:
  // repeated vertices, collinear vertices, one point, and two coincident vertices far away.
  ASSERT_EQ(scene.triangles.size(), 4u);
  EXPECT_EQ(scene.triangles[3].v2, glm::vec3(0.5f, 1e-7f, 0));
  EXPECT_EQ(scene.triangles[3].primitive, 3u);
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0], path.string() + ": shapes[1]: dropped 4 zero-area triangles (of 6)");
}

TEST(SceneDegenerate, CollapsingTransformDropsTriangles) {
  TempDir dir;
  // Coordinates far apart in magnitude: after translation by 1e8 in float the small
  // triangle's vertices coincide, so it has zero area as the renderer sees it.
  const Scene scene = loadScene(dir.write("scene.json", sceneJson(kWhite, R"([
        {"type": "quad", "material": "white", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]},
        {"type": "triangles", "material": "white",
         "vertices": [[0,0,0],[0.001,0,0],[0,0.001,0]], "indices": [[0,1,2]],
         "transform": {"translate": [1e8, 1e8, 0]}}])")));
  EXPECT_EQ(scene.triangles.size(), 2u);
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_CONTAINS(scene.warnings[0], "shapes[1]: dropped 1 zero-area triangle (of 1)");
}

TEST(SceneDegenerate, OnlyDegenerateTrianglesIsAnError) {
  TempDir dir;
  const std::string m = errorFor(dir, sceneJson(kWhite, R"([{"type": "quad", "material": "white",
      "vertices": [[0,0,0],[1,0,0],[2,0,0],[3,0,0]]}])"));
  EXPECT_CONTAINS(m, ": shapes: no triangles left");
}

// ---- camera -----------------------------------------------------------------------------

TEST(SceneCamera, CornellBasis) {
  CameraDesc desc;
  desc.position = {278, 273, -800};
  desc.target = {278, 273, 0};
  desc.up = {0, 1, 0};
  desc.vfovDegrees = 39.3077f;
  const Camera c = makeCamera(desc, 512, 256);
  EXPECT_EQ(c.position, desc.position);
  EXPECT_EQ(c.forward, glm::vec3(0, 0, 1));
  EXPECT_EQ(c.right, glm::vec3(-1, 0, 0));
  EXPECT_EQ(c.up, glm::vec3(0, 1, 0));
  EXPECT_FLOAT_EQ(c.tanHalfFovY, std::tan(39.3077 * M_PI / 180.0 / 2.0));
  EXPECT_FLOAT_EQ(c.aspect, 2.0f);
  EXPECT_EQ(c.width, 512u);
  EXPECT_EQ(c.height, 256u);
}

TEST(SceneCamera, BasisIsOrthonormalForTiltedUp) {
  CameraDesc desc;
  desc.position = {1, 2, 3};
  desc.target = {4, -1, 7};
  desc.up = {0.3f, 1, 0.2f};  // not perpendicular to the view direction
  const Camera c = makeCamera(desc, 100, 50);
  EXPECT_NEAR(glm::length(c.forward), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::length(c.right), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::length(c.up), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(c.forward, c.right), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(c.forward, c.up), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(c.right, c.up), 0.0f, 1e-6f);
  EXPECT_GT(glm::dot(c.up, glm::vec3(0.3f, 1, 0.2f)), 0.0f);  // same side as the given up
}

TEST(SceneCamera, BadCameraValues) {
  TempDir dir;
  const auto withCamera = [&](const std::string& camera) {
    return errorFor(dir, sceneJson(kWhite, kUnitQuad, "\"camera\": " + camera));
  };
  EXPECT_CONTAINS(withCamera(R"({"width": 0})"), "camera.width: expected an integer in [1, ");
  EXPECT_CONTAINS(withCamera(R"({"height": -5})"), "camera.height: expected an integer");
  EXPECT_CONTAINS(withCamera(R"({"width": 2.5})"), "camera.width: expected an integer");
  EXPECT_CONTAINS(withCamera(R"({"width": "256"})"), "camera.width: expected an integer");
  EXPECT_CONTAINS(withCamera(R"({"vfov": 0})"), "camera.vfov: expected a field of view");
  EXPECT_CONTAINS(withCamera(R"({"vfov": 180})"), "camera.vfov:");
  EXPECT_CONTAINS(withCamera(R"({"vfov": -10})"), "camera.vfov:");
  EXPECT_CONTAINS(withCamera(R"({"position": [1, 2, 3], "target": [1, 2, 3]})"),
                  "camera.target: equals camera.position");
  EXPECT_CONTAINS(withCamera(R"({"target": [0, 5, 0], "up": [0, 1, 0]})"),
                  "camera.up: is parallel to the view direction");
  EXPECT_CONTAINS(withCamera(R"({"up": [0, 0, 0]})"), "camera.up: must not be the zero vector");
  EXPECT_CONTAINS(withCamera(R"({"position": [1, 2]})"),
                  "camera.position: expected an array of 3 numbers, got an array of 2 elements");
  EXPECT_CONTAINS(withCamera(R"({"position": [1, "2", 3]})"),
                  "camera.position[1]: expected a number, got a string");
  EXPECT_CONTAINS(withCamera(R"({"position": [1e39, 0, 0]})"), "camera.position[0]: number 1e+39");
  EXPECT_CONTAINS(withCamera(R"([1, 2])"), "camera: expected an object, got an array");
  EXPECT_CONTAINS(withCamera(R"({"fvo": 40})"), "camera.fvo: unknown key (did you mean 'vfov'?)");
  EXPECT_CONTAINS(withCamera(R"({"widht": 40})"),
                  "camera.widht: unknown key (did you mean 'width'?)");
}

// ---- integrator -------------------------------------------------------------------------

TEST(SceneIntegrator, BadIntegratorValues) {
  TempDir dir;
  const auto withIntegrator = [&](const std::string& integrator) {
    return errorFor(dir, sceneJson(kWhite, kUnitQuad, "\"integrator\": " + integrator));
  };
  EXPECT_CONTAINS(withIntegrator(R"({"spp": 0})"), "integrator.spp: expected an integer in [1, ");
  EXPECT_CONTAINS(withIntegrator(R"({"spp": -3})"), "integrator.spp:");
  EXPECT_CONTAINS(withIntegrator(R"({"spp": 1.5})"), "integrator.spp: expected an integer");
  EXPECT_CONTAINS(withIntegrator(R"({"spp": "64"})"), "got a string");
  EXPECT_CONTAINS(withIntegrator(R"({"spp": 1e30})"), "integrator.spp:");
  EXPECT_CONTAINS(withIntegrator(R"({"maxDepth": -1})"),
                  "integrator.maxDepth: expected an integer in [0, ");
  EXPECT_CONTAINS(withIntegrator(R"({"rrStartDepth": 0})"), "integrator.rrStartDepth:");
  EXPECT_CONTAINS(withIntegrator(R"({"seed": 4294967296})"),
                  "integrator.seed: expected an integer in [0, 4294967295]");
  EXPECT_CONTAINS(withIntegrator(R"({"seed": -1})"), "integrator.seed:");
  EXPECT_CONTAINS(withIntegrator(R"({"russianRoulette": 1})"),
                  "integrator.russianRoulette: expected true or false, got a number");
  EXPECT_CONTAINS(withIntegrator(R"({"strategy": "nie"})"),
                  "integrator.strategy: unknown strategy 'nie' (did you mean 'nee'?)");
  EXPECT_CONTAINS(
      withIntegrator(R"({"sampler": "halton"})"),
      "integrator.sampler: unknown sampler 'halton' (expected 'independent' or 'sobol')");
  EXPECT_CONTAINS(withIntegrator(R"({"strategy": "path"})"),
                  "integrator.strategy: unknown strategy 'path' (expected 'mis', 'nee' or 'bsdf')");
  EXPECT_CONTAINS(withIntegrator(R"({"samples": 4})"), "integrator.samples: unknown key");
}

// ---- materials --------------------------------------------------------------------------

TEST(SceneMaterials, BadMaterials) {
  TempDir dir;
  const auto withMaterials = [&](const std::string& materials) {
    return errorFor(dir, sceneJson(materials, kUnitQuad));
  };
  EXPECT_CONTAINS(
      withMaterials(R"([{"name": "white"}, {"name": "a"}, {"name": "b", "reflectance": "red"}])"),
      "materials[2].reflectance: unknown texture 'red' (a string names one of the scene's "
      "\"textures\"; a value is a number or an array of 3 numbers)");
  EXPECT_CONTAINS(withMaterials(R"([{"name": "white", "reflectance": [0.5, 1.5, 0]}])"),
                  "materials[0].reflectance[1]: expected a number in [0, 1], got the number 1.5");
  EXPECT_CONTAINS(withMaterials(R"([{"name": "white", "reflectance": [0.5, -0.1, 0]}])"),
                  "materials[0].reflectance[1]:");
  EXPECT_CONTAINS(withMaterials(R"([{"name": "white", "emission": [1, -1, 0]}])"),
                  "materials[0].emission[1]: expected a non-negative number");
  EXPECT_CONTAINS(withMaterials(R"([{"name": "white", "emission": [1, 1e300, 0]}])"),
                  "materials[0].emission[1]: number 1e+300 is too large");
  EXPECT_CONTAINS(withMaterials(R"([{"name": "white", "type": "mirorr"}])"),
                  "materials[0].type: unknown material type 'mirorr' (did you mean 'mirror'?)");
  EXPECT_CONTAINS(withMaterials(R"([{"name": "white"}, {"name": "white"}])"),
                  "materials[1].name: duplicate material name 'white' (also used by materials[0])");
  EXPECT_CONTAINS(withMaterials(R"([{"name": ""}])"), "materials[0].name: must not be empty");
  EXPECT_CONTAINS(withMaterials(R"([{"reflectance": [1, 1, 1]}])"),
                  "materials[0].name: required key is missing");
  EXPECT_CONTAINS(withMaterials(R"([{"name": "white", "emision": [1, 1, 1]}])"),
                  "materials[0].emision: unknown key (did you mean 'emission'?)");
  EXPECT_CONTAINS(withMaterials(R"([])"), "materials: expected at least one material");
  EXPECT_CONTAINS(withMaterials(R"({"white": {}})"), "materials: expected an array, got an object");
  EXPECT_CONTAINS(withMaterials(R"([3])"), "materials[0]: expected an object, got a number");
}

// The materials of a scene with the given "materials" array (and one quad of the first).
std::vector<Material> loadMaterials(const TempDir& dir, const std::string& materials) {
  const std::string first = nlohmann::json::parse(materials)[0]["name"];
  const std::string quad = R"([{"type": "quad", "material": ")" + first +
                           R"(", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]}])";
  return loadScene(dir.write("materials.json", sceneJson(materials, quad))).materials;
}

// Every field, so that a parameter landing in the wrong field, or a field a type does not
// use left non-zero, fails.
void expectMaterial(const Material& got, const Material& want, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(got.type, want.type);
  EXPECT_EQ(got.reflectance, want.reflectance);
  EXPECT_EQ(got.emission, want.emission);
  EXPECT_EQ(got.eta, want.eta);
  EXPECT_EQ(got.k, want.k);
  EXPECT_EQ(got.alphaX, want.alphaX);
  EXPECT_EQ(got.alphaY, want.alphaY);
  EXPECT_EQ(got.transmittance, want.transmittance);
  EXPECT_EQ(got.thickness, want.thickness);
  EXPECT_EQ(got.g, want.g);
  EXPECT_EQ(got.maxDepth, want.maxDepth);
  EXPECT_EQ(got.nSamples, want.nSamples);
  EXPECT_EQ(got.twoSided, 0u);
  EXPECT_EQ(got.reserved1, 0u);
}

// pbrt-v4's default copper, as RGB (docs/scene-format.md).
const vec3 kCopperEta(0.200438f, 0.924033f, 1.10221f);
const vec3 kCopperK(3.91295f, 2.45285f, 2.14219f);

TEST(SceneMaterials, EveryTypeWithItsDefaults) {
  TempDir dir;
  const std::vector<Material> m = loadMaterials(dir, R"([
      {"name": "d"}, {"name": "m", "type": "mirror"}, {"name": "c", "type": "conductor"},
      {"name": "g", "type": "dielectric"}, {"name": "t", "type": "thindielectric"},
      {"name": "s", "type": "diffusetransmission"}, {"name": "p", "type": "coateddiffuse"}])");
  ASSERT_EQ(m.size(), 7u);
  Material want{};
  want.type = kMaterialDiffuse;
  want.reflectance = vec3(0.8f);
  expectMaterial(m[0], want, "diffuse");
  want = Material{};
  want.type = kMaterialMirror;
  want.reflectance = vec3(1.0f);
  expectMaterial(m[1], want, "mirror");
  want = Material{};
  want.type = kMaterialConductor;  // smooth copper
  want.eta = kCopperEta;
  want.k = kCopperK;
  expectMaterial(m[2], want, "conductor");
  want = Material{};
  want.type = kMaterialDielectric;  // smooth, index 1.5 in eta.x
  want.eta = vec3(1.5f, 0.0f, 0.0f);
  expectMaterial(m[3], want, "dielectric");
  want.type = kMaterialThinDielectric;
  expectMaterial(m[4], want, "thindielectric");
  want = Material{};
  want.type = kMaterialDiffuseTransmission;
  want.reflectance = vec3(0.25f);
  want.transmittance = vec3(0.25f);
  expectMaterial(m[5], want, "diffusetransmission");
  want = Material{};
  want.type = kMaterialCoatedDiffuse;
  want.reflectance = vec3(0.5f);
  want.eta = vec3(1.5f, 0.0f, 0.0f);
  want.thickness = 0.01f;
  want.maxDepth = 10;
  want.nSamples = 1;
  expectMaterial(m[6], want, "coateddiffuse");
  // The public defaults are the same.
  for (const Material& material : m) {
    expectMaterial(material, defaultMaterial(material.type), "defaultMaterial");
  }
}

TEST(SceneMaterials, ConductorParameters) {
  TempDir dir;
  const std::vector<Material> m = loadMaterials(dir, R"([
      {"name": "gold", "type": "conductor", "eta": [0.143119, 0.374957, 1.44248],
       "k": [3.98316, 2.38572, 1.60322], "roughness": 0.04, "emission": [1, 2, 3]},
      {"name": "grey", "type": "conductor", "eta": 1.5, "k": 0, "uroughness": 0.25,
       "vroughness": 0.01},
      {"name": "raw", "type": "conductor", "roughness": 0.3, "uroughness": 0.2,
       "remaproughness": false},
      {"name": "etaOnly", "type": "conductor", "eta": 2},
      {"name": "refl", "type": "conductor", "reflectance": [0, 0.5, 1], "roughness": 0.09}])");
  Material want{};
  want.type = kMaterialConductor;
  want.eta = vec3(0.143119f, 0.374957f, 1.44248f);
  want.k = vec3(3.98316f, 2.38572f, 1.60322f);
  want.alphaX = want.alphaY = 0.2f;  // remapped: sqrt(0.04)
  want.emission = vec3(1, 2, 3);
  expectMaterial(m[0], want, "gold");
  want = Material{};
  want.type = kMaterialConductor;
  want.eta = vec3(1.5f);  // one number: all three channels
  want.k = vec3(0.0f);
  want.alphaX = 0.5f;  // uroughness 0.25
  want.alphaY = 0.1f;  // vroughness 0.01
  expectMaterial(m[1], want, "grey");
  // Without remapping the values are the alphas; uroughness wins over roughness for u only.
  want = defaultMaterial(kMaterialConductor);
  want.alphaX = 0.2f;
  want.alphaY = 0.3f;
  expectMaterial(m[2], want, "raw");
  // eta alone keeps pbrt-v4's default copper k.
  want = defaultMaterial(kMaterialConductor);
  want.eta = vec3(2.0f);
  expectMaterial(m[3], want, "etaOnly");
  // pbrt-v4's reflectance rule: eta 1, k = 2 sqrt(r) / sqrt(1 - r), r clamped to 0.9999.
  want = Material{};
  want.type = kMaterialConductor;
  want.eta = vec3(1.0f);
  want.k = vec3(0.0f, float(2.0 * std::sqrt(0.5) / std::sqrt(0.5)),
                float(2.0 * std::sqrt(0.9999) / std::sqrt(1.0 - 0.9999)));
  want.alphaX = want.alphaY = std::sqrt(0.09f);
  expectMaterial(m[4], want, "reflectance");
  EXPECT_FLOAT_EQ(m[4].k.y, 2.0f);
  EXPECT_NEAR(m[4].k.z, 199.99f, 0.01f);
}

TEST(SceneMaterials, DielectricParameters) {
  TempDir dir;
  const std::vector<Material> m = loadMaterials(dir, R"([
      {"name": "glass", "type": "dielectric", "eta": 1.33, "roughness": 0.01},
      {"name": "frosted", "type": "dielectric", "uroughness": 0.5, "vroughness": 0.3,
       "remaproughness": false, "eta": 0.8},
      {"name": "pane", "type": "thindielectric", "eta": 1.2, "emission": [0, 0, 4]}])");
  Material want{};
  want.type = kMaterialDielectric;
  want.eta = vec3(1.33f, 0.0f, 0.0f);
  want.alphaX = want.alphaY = 0.1f;
  expectMaterial(m[0], want, "glass");
  want.eta = vec3(0.8f, 0.0f, 0.0f);
  want.alphaX = 0.5f;
  want.alphaY = 0.3f;
  expectMaterial(m[1], want, "frosted");
  want = Material{};
  want.type = kMaterialThinDielectric;
  want.eta = vec3(1.2f, 0.0f, 0.0f);
  want.emission = vec3(0, 0, 4);
  expectMaterial(m[2], want, "pane");
}

TEST(SceneMaterials, DiffuseTransmissionParameters) {
  TempDir dir;
  const std::vector<Material> m = loadMaterials(dir, R"([
      {"name": "leaf", "type": "diffusetransmission", "reflectance": [0.1, 0.5, 0.2],
       "transmittance": [0.2, 0.6, 0.1]},
      {"name": "scaled", "type": "diffusetransmission", "reflectance": [0.1, 0.5, 0.2],
       "transmittance": [0.2, 0.6, 0.1], "scale": 2},
      {"name": "dflt", "type": "diffusetransmission", "scale": 0.5}])");
  Material want{};
  want.type = kMaterialDiffuseTransmission;
  want.reflectance = vec3(0.1f, 0.5f, 0.2f);
  want.transmittance = vec3(0.2f, 0.6f, 0.1f);
  expectMaterial(m[0], want, "leaf");
  // pbrt-v4 multiplies both by scale and clamps to [0, 1].
  want.reflectance = vec3(0.2f, 1.0f, 0.4f);
  want.transmittance = vec3(0.4f, 1.0f, 0.2f);
  expectMaterial(m[1], want, "scaled");
  want.reflectance = want.transmittance = vec3(0.125f);
  expectMaterial(m[2], want, "dflt");
}

TEST(SceneMaterials, CoatedDiffuseParameters) {
  TempDir dir;
  const std::vector<Material> m = loadMaterials(dir, R"([
      {"name": "wood", "type": "coateddiffuse", "reflectance": [0.3, 0.2, 0.1],
       "roughness": 0.0625, "thickness": 0.1, "eta": 1.33, "albedo": [0.5, 0.25, 0],
       "g": -0.5, "maxdepth": 20, "nsamples": 4, "emission": [1, 1, 1]},
      {"name": "aniso", "type": "coateddiffuse", "uroughness": 0.01, "vroughness": 0.04,
       "remaproughness": false, "maxdepth": 1000.0, "nsamples": 1}])");
  Material want{};
  want.type = kMaterialCoatedDiffuse;
  want.reflectance = vec3(0.3f, 0.2f, 0.1f);
  want.alphaX = want.alphaY = 0.25f;
  want.thickness = 0.1f;
  want.eta = vec3(1.33f, 0.0f, 0.0f);
  want.transmittance = vec3(0.5f, 0.25f, 0.0f);  // the medium's albedo
  want.g = -0.5f;
  want.maxDepth = 20;
  want.nSamples = 4;
  want.emission = vec3(1.0f);
  expectMaterial(m[0], want, "wood");
  want = defaultMaterial(kMaterialCoatedDiffuse);
  want.alphaX = 0.01f;
  want.alphaY = 0.04f;
  want.maxDepth = 1000;
  expectMaterial(m[1], want, "aniso");
}

TEST(SceneMaterials, BadParametersOfTheNewTypes) {
  TempDir dir;
  // One material of the given JSON object text, and its error.
  const auto withMaterial = [&](const std::string& material) {
    return errorFor(dir, sceneJson("[" + material + "]", kUnitQuad));
  };
  const std::string file = (dir.path() / "scene.json").string();
  // A key of another type: named with the type and what it takes.
  EXPECT_EQ(withMaterial(R"({"name": "white", "type": "dielectric", "k": 1})"),
            file +
                ": materials[0].k: not a parameter of 'dielectric' (a 'dielectric' material "
                "takes 'eta', 'roughness', 'uroughness', 'vroughness', 'remaproughness', "
                "'emission', 'twoSided', 'alpha' and 'displacement')");
  EXPECT_EQ(withMaterial(R"({"name": "white", "roughness": 0.1})"),
            file +
                ": materials[0].roughness: not a parameter of 'diffuse' (a 'diffuse' material "
                "takes 'reflectance', 'emission', 'twoSided', 'alpha' and 'displacement')");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "mirror", "eta": 1.5})"),
                  "materials[0].eta: not a parameter of 'mirror'");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "thindielectric", "roughness": 0})"),
                  "materials[0].roughness: not a parameter of 'thindielectric' (a "
                  "'thindielectric' material takes 'eta', 'emission', 'twoSided', 'alpha' and "
                  "'displacement')");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "conductor", "albedo": [0, 0, 0]})"),
                  "materials[0].albedo: not a parameter of 'conductor'");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "diffusetransmission", "g": 0})"),
                  "materials[0].g: not a parameter of 'diffusetransmission'");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "coateddiffuse", "scale": 1})"),
                  "materials[0].scale: not a parameter of 'coateddiffuse'");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "coateddiffuse", "k": [1, 1, 1]})"),
                  "materials[0].k: not a parameter of 'coateddiffuse'");
  // A key no type takes: unknown, with a suggestion among the type's keys.
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "dielectric", "rougness": 0.1})"),
                  "materials[0].rougness: unknown key (did you mean 'roughness'?)");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "conductor", "normalmap": 1})"),
                  "materials[0].normalmap: unknown key (expected 'name', 'type', 'eta', 'k', "
                  "'reflectance', 'roughness', 'uroughness', 'vroughness', 'remaproughness', "
                  "'emission', 'twoSided', 'alpha' or 'displacement')");
  EXPECT_CONTAINS(withMaterial(R"({"name": "white", "type": "metal"})"),
                  "materials[0].type: unknown material type 'metal' (expected 'diffuse', "
                  "'mirror', 'conductor', 'dielectric', 'thindielectric', 'diffusetransmission', "
                  "'coateddiffuse' or 'interface')");

  // Conductor: reflectance or eta and k, not both (pbrt-v4's rule).
  EXPECT_EQ(withMaterial(R"({"name": "w", "type": "conductor", "reflectance": [1, 1, 1],
                             "eta": 1.5})"),
            file +
                ": materials[0].reflectance: a conductor takes either 'reflectance' or 'eta' "
                "and 'k', not both (as in pbrt-v4); this one also has 'eta'");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "reflectance": [1, 1, 1],
                                   "k": [1, 2, 3]})"),
                  "materials[0].reflectance: a conductor takes either 'reflectance' or 'eta' and "
                  "'k', not both (as in pbrt-v4); this one also has 'k'");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "reflectance": [1, 1.5, 1]})"),
                  "materials[0].reflectance[1]: expected a number in [0, 1], got the number 1.5");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "eta": [1, 0, 1]})"),
                  "materials[0].eta[1]: expected a positive number, got the number 0");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "eta": 1e-50})"),
                  "materials[0].eta: expected a positive number, got the number 1e-50");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "k": -1})"),
                  "materials[0].k: expected a non-negative number, got the number -1");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "k": [1, 2]})"),
                  "materials[0].k: expected a number or an array of 3 numbers, got an array of 2 "
                  "elements");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "k": "gold"})"),
                  "materials[0].k: unknown texture 'gold'");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "eta": [1, 1e300, 1]})"),
                  "materials[0].eta[1]: number 1e+300 is too large");
  // Roughness.
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "conductor", "roughness": -0.1})"),
                  "materials[0].roughness: expected a non-negative number, got the number -0.1");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "dielectric", "vroughness": -1})"),
                  "materials[0].vroughness: expected a non-negative number");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "uroughness": 1e39})"),
                  "materials[0].uroughness: number 1e+39 is too large");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "dielectric", "remaproughness": 1})"),
                  "materials[0].remaproughness: expected true or false, got a number");
  // Indices of refraction.
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "dielectric", "eta": 0})"),
                  "materials[0].eta: expected a positive number, got the number 0");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "dielectric", "eta": [1.5, 1.5, 1.5]})"),
                  "materials[0].eta: expected a number, got an array");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "thindielectric", "eta": -1.5})"),
                  "materials[0].eta: expected a positive number, got the number -1.5");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "eta": 0})"),
                  "materials[0].eta: expected a positive number");
  // Diffuse transmission.
  EXPECT_CONTAINS(
      withMaterial(R"({"name": "w", "type": "diffusetransmission", "transmittance": [2, 0, 0]})"),
      "materials[0].transmittance[0]: expected a number in [0, 1], got the number 2");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "diffusetransmission", "scale": -1})"),
                  "materials[0].scale: expected a non-negative number, got the number -1");
  // Coated diffuse.
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "thickness": 0})"),
                  "materials[0].thickness: expected a positive number, got the number 0");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "albedo": [0, 0, 1.1]})"),
                  "materials[0].albedo[2]: expected a number in [0, 1], got the number 1.1");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "g": 1})"),
                  "materials[0].g: expected a number strictly between -1 and 1, got the number 1");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "g": -1})"),
                  "materials[0].g: expected a number strictly between -1 and 1");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "maxdepth": 0})"),
                  "materials[0].maxdepth: expected an integer in [1, 1000], got the number 0");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "nsamples": 1.5})"),
                  "materials[0].nsamples: expected an integer in [1, 1000], got the number 1.5");
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "coateddiffuse", "nsamples": 1001})"),
                  "materials[0].nsamples: expected an integer in [1, 1000], got the number 1001");
  // Emission stays allowed, and checked, on every type.
  EXPECT_CONTAINS(withMaterial(R"({"name": "w", "type": "dielectric", "emission": [0, -1, 0]})"),
                  "materials[0].emission[1]: expected a non-negative number");
}

// The example scenes of the new materials load, with the materials they describe.
TEST(SceneMaterials, ExampleScenesLoad) {
  const Scene cornell = loadScene(test::kConfigs / "cornell-materials.json");
  EXPECT_TRUE(cornell.warnings.empty());
  ASSERT_EQ(cornell.triangles.size(), 32u);
  std::vector<uint> types;
  for (const Triangle& t : cornell.triangles) types.push_back(cornell.materials[t.material].type);
  EXPECT_EQ(std::count(types.begin(), types.end(), kMaterialConductor), 10);   // tall block
  EXPECT_EQ(std::count(types.begin(), types.end(), kMaterialDielectric), 10);  // short block
  for (const Material& m : cornell.materials) {
    if (m.type == kMaterialConductor) EXPECT_FLOAT_EQ(m.alphaX, std::sqrt(0.1f));
    if (m.type == kMaterialDielectric) EXPECT_EQ(m.eta.x, 1.5f);
  }

  // Four plates of increasing alpha; four spherical lights of equal power (radiance times
  // area), over a floor, a back wall and a dim fill.
  const Scene veach = loadScene(test::kConfigs / "veach-mis.json");
  EXPECT_TRUE(veach.warnings.empty());
  std::vector<float> alphas;
  for (const Material& m : veach.materials) {
    if (m.type == kMaterialConductor) alphas.push_back(m.alphaX);
  }
  EXPECT_EQ(alphas, (std::vector<float>{0.005f, 0.02f, 0.05f, 0.1f}));
  std::map<uint, double> power;  // per emissive material: emission.x times its area
  for (const Triangle& t : veach.triangles) {
    const Material& m = veach.materials[t.material];
    if (m.emission.x == 0.0f) continue;
    const double area =
        0.5 * glm::length(glm::cross(glm::dvec3(t.v1 - t.v0), glm::dvec3(t.v2 - t.v0)));
    power[t.material] += area * m.emission.x;
  }
  ASSERT_EQ(power.size(), 5u);  // the four lights and the fill
  std::vector<double> lights;
  for (const auto& [material, p] : power) {
    if (veach.materialNames[material].rfind("light", 0) == 0) lights.push_back(p);
  }
  ASSERT_EQ(lights.size(), 4u);
  for (const double p : lights) EXPECT_NEAR(p / lights[0], 1.0, 1e-3);
}

// ---- shapes -----------------------------------------------------------------------------

TEST(SceneShapes, BadShapes) {
  TempDir dir;
  const auto withShapes = [&](const std::string& shapes) {
    return errorFor(dir, sceneJson(kWhite, shapes));
  };
  const std::string quad = R"("vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]])";
  EXPECT_CONTAINS(withShapes(R"([{"type": "quad", "material": "whte", )" + quad + "}]"),
                  "shapes[0].material: unknown material 'whte' (did you mean 'white'?)");
  EXPECT_CONTAINS(withShapes(R"([{"type": "quad", )" + quad + "}]"),
                  "shapes[0].material: required key is missing");
  EXPECT_CONTAINS(withShapes(R"([{"material": "white", )" + quad + "}]"),
                  "shapes[0].type: required key is missing");
  EXPECT_CONTAINS(withShapes(R"([{"type": "quads", "material": "white", )" + quad + "}]"),
                  "shapes[0].type: unknown shape type 'quads' (did you mean 'quad'?)");
  EXPECT_CONTAINS(
      withShapes(R"([{"type": "sphere", "material": "white"}])"),
      "shapes[0].type: unknown shape type 'sphere' (expected 'quad', 'triangles', 'obj' or 'ply')");
  EXPECT_CONTAINS(
      withShapes(
          R"([{"type": "quad", "material": "white", "vertices": [[0,0,0],[1,0,0],[1,1,0]]}])"),
      "shapes[0].vertices: expected an array of 4 points, got an array of 3 elements");
  EXPECT_CONTAINS(
      withShapes(R"([{"type": "quad", "material": "white", "indices": [], )" + quad + "}]"),
      "shapes[0].indices: unknown key");
  EXPECT_CONTAINS(withShapes(R"([{"type": "quad", "material": "white", "name": 3, )" + quad + "}]"),
                  "shapes[0].name: expected a string, got a number");
  EXPECT_CONTAINS(withShapes(R"([{"type": "triangles", "material": "white",
                     "vertices": [[0,0,0],[1,0,0],[0,1,0]], "indices": [[0, 1, 5]]}])"),
                  "shapes[0].indices[0][2]: vertex index 5 out of range (the shape has 3 vertices");
  EXPECT_CONTAINS(withShapes(R"([{"type": "triangles", "material": "white",
                     "vertices": [[0,0,0],[1,0,0],[0,1,0]], "indices": [[0, 1, -1]]}])"),
                  "shapes[0].indices[0][2]: expected an integer in [0, ");
  EXPECT_CONTAINS(withShapes(R"([{"type": "triangles", "material": "white",
                     "vertices": [[0,0,0],[1,0,0],[0,1,0]], "indices": [[0, 1]]}])"),
                  "shapes[0].indices[0]: expected an array of 3 vertex indices");
  EXPECT_CONTAINS(withShapes(R"([{"type": "triangles", "material": "white",
                     "vertices": [[0,0,0],[1,0,0],[0,1,0]], "indices": []}])"),
                  "shapes[0].indices: expected at least one triangle");
  EXPECT_CONTAINS(withShapes(R"([{"type": "triangles", "material": "white",
                     "vertices": [[0,0,0],[1,0,0],[0,1,0]]}])"),
                  "shapes[0].indices: required key is missing");
  EXPECT_CONTAINS(withShapes(R"([{"type": "obj", "material": "white"}])"),
                  "shapes[0].file: required key is missing");
  EXPECT_CONTAINS(withShapes(R"([{"type": "obj", "material": "white", "file": ""}])"),
                  "shapes[0].file: expected a file name");
  EXPECT_CONTAINS(withShapes("[]"), "shapes: expected at least one shape");
}

TEST(SceneShapes, BadTransforms) {
  TempDir dir;
  const auto withTransform = [&](const std::string& transform) {
    return errorFor(dir, sceneJson(kWhite, R"([{"type": "quad", "material": "white",
        "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]], "transform": )" +
                                               transform + "}]"));
  };
  EXPECT_CONTAINS(withTransform(R"({"scale": 0})"),
                  "shapes[0].transform.scale: scale factor must be non-zero");
  EXPECT_CONTAINS(withTransform(R"({"scale": [1, 0, 1]})"),
                  "shapes[0].transform.scale[1]: scale factors must be non-zero");
  EXPECT_CONTAINS(withTransform(R"({"scale": "big"})"),
                  "shapes[0].transform.scale: expected a number or an array of 3 numbers");
  EXPECT_CONTAINS(withTransform(R"({"rotate": {"axis": [0, 0, 0], "degrees": 10}})"),
                  "shapes[0].transform.rotate.axis: rotation axis must not be the zero vector");
  EXPECT_CONTAINS(withTransform(R"({"rotate": {"axis": [0, 1, 0]}})"),
                  "shapes[0].transform.rotate.degrees: required key is missing");
  EXPECT_CONTAINS(withTransform(R"({"rotate": {"axis": [0, 1, 0], "degree": 5}})"),
                  "shapes[0].transform.rotate.degree: unknown key (did you mean 'degrees'?)");
  EXPECT_CONTAINS(withTransform(R"({"translation": [1, 2, 3]})"),
                  "shapes[0].transform.translation: unknown key (did you mean 'translate'?)");
  EXPECT_CONTAINS(errorFor(dir, sceneJson(kWhite, R"([{"type": "quad", "material": "white",
                      "vertices": [[0,0,0],[1e9,0,0],[1e9,1e9,0],[0,1e9,0]],
                      "transform": {"scale": 1e30}}])")),
                  "shapes[0]: transform moves vertices beyond the range of 32-bit floats");
}

// ---- document-level errors --------------------------------------------------------------

TEST(SceneDocument, SyntaxErrorNamesLineAndColumn) {
  const std::string m = loadError(kData / "syntax_error.json");
  EXPECT_CONTAINS(m, "syntax_error.json: line 12, column 5: syntax error: ");
}

TEST(SceneDocument, SyntaxErrorColumnCountsCharactersNotBytes) {
  TempDir dir;
  // "é" is two bytes in UTF-8 but one column; the stray 'x' is at line 2, column 22.
  const std::string m = errorFor(dir, "{\n  \"description\": \"é\" x}");
  EXPECT_CONTAINS(m, ": line 2, column 22: syntax error: ");
  EXPECT_CONTAINS(errorFor(dir, ""), ": line 1, column 1: syntax error: ");
  EXPECT_CONTAINS(errorFor(dir, "{\"materials\": [1,]}"), ": line 1, column 18: syntax error: ");
}

TEST(SceneDocument, HugeNumberNamesFieldAndLine) {
  TempDir dir;
  const std::string m = errorFor(
      dir, "{\"camera\": {\n  \"position\": [0, 1e999, 0]}, \"materials\": [], \"shapes\": []}");
  EXPECT_CONTAINS(m, ": camera.position[1]: number 1e999 is out of range (line 2, column 19)");
}

TEST(SceneDocument, TopLevelErrors) {
  TempDir dir;
  EXPECT_CONTAINS(errorFor(dir, "[1, 2]"), ": top level: expected an object, got an array");
  EXPECT_CONTAINS(errorFor(dir, sceneJson(kWhite, kUnitQuad, R"("material": 1)")),
                  ": material: unknown key (did you mean 'materials'?)");
  EXPECT_CONTAINS(errorFor(dir, sceneJson(kWhite, kUnitQuad, R"("light": 1)")),
                  ": light: unknown key (did you mean 'lights'?)");
  EXPECT_CONTAINS(errorFor(dir, sceneJson(kWhite, kUnitQuad, R"("lights": 1)")),
                  ": lights: expected an array, got a number");
  EXPECT_CONTAINS(errorFor(dir, R"({"shapes": [1]})"), ": materials: required key is missing");
  EXPECT_CONTAINS(errorFor(dir, R"({"materials": [{"name": "a"}]})"),
                  ": shapes: required key is missing");
  EXPECT_CONTAINS(errorFor(dir, sceneJson(kWhite, kUnitQuad, R"("description": 5)")),
                  ": description: expected a string, got a number");
  // Duplicate keys would otherwise silently keep the last value.
  EXPECT_CONTAINS(errorFor(dir, R"({"materials": [{"name": "a", "name": "b"}], "shapes": []})"),
                  ": materials[0].name: duplicate key");
}

TEST(SceneDocument, MissingSceneFile) {
  const fs::path path = kData / "does_not_exist.json";
  EXPECT_CONTAINS(loadError(path), "cannot open scene file (No such file or directory)");
  EXPECT_CONTAINS(loadError(kData), "cannot open scene file (is a directory)");
}

TEST(SceneDocument, ControlCharactersInKeysStayOnOneLine) {
  TempDir dir;
  const std::string m = errorFor(dir, sceneJson(kWhite, kUnitQuad, R"("bad\nkey": 1)"));
  EXPECT_CONTAINS(m, ": bad\\nkey: unknown key");
}

TEST(SceneDocument, RelativePathIsKeptInMessages) {
  // The message starts with the path exactly as given, relative or not.
  const fs::path cwd = fs::current_path();
  fs::current_path(kData);
  std::string m;
  try {
    loadScene("syntax_error.json");
  } catch (const InputError& e) {
    m = e.what();
  }
  fs::current_path(cwd);
  EXPECT_EQ(m.rfind("syntax_error.json: line 12, column 5: ", 0), 0u) << m;
}

// ---- OBJ files --------------------------------------------------------------------------

TEST(SceneObj, MissingFileNamesFieldAndPath) {
  TempDir dir;
  const std::string m = errorFor(dir, sceneJson(kWhite, R"([
      {"type": "quad", "material": "white", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]},
      {"type": "obj", "material": "white", "file": "meshes/foo.obj"}])"));
  EXPECT_CONTAINS(m, ": shapes[1].file: cannot open 'meshes/foo.obj' (looked for '" +
                         (dir.path() / "meshes/foo.obj").string() +
                         "': No such file or directory)");
}

TEST(SceneObj, IndexOutOfRangeNamesObjFileAndLine) {
  const fs::path obj = kData / "meshes" / "bad_range.obj";
  const std::string m = loadError(kData / "bad_obj_range.json", obj.string());
  EXPECT_CONTAINS(m, "bad_range.obj: line 7: vertex index 12 out of range (file has 8 vertices)");
  EXPECT_CONTAINS(m, "bad_obj_range.json: shapes[1].file");  // which scene entry used it
}

TEST(SceneObj, ZeroIndexNamesObjFileAndLine) {
  TempDir dir;
  const fs::path obj = kData / "meshes" / "bad_zero.obj";
  const std::string m =
      loadError(dir.write("scene.json", sceneJson(kWhite, R"([{"type": "obj", "material": "white",
                                                    "file": ")" +
                                                              obj.string() + R"("}])")),
                obj.string());
  EXPECT_CONTAINS(m, "bad_zero.obj: line 7: vertex index 0 is invalid (OBJ indices start at 1)");
}

TEST(SceneObj, ObjErrors) {
  TempDir dir;
  const auto objError = [&](const std::string& obj) {
    const fs::path objPath = dir.write("bad.obj", obj);
    const fs::path scene = dir.write(
        "scene.json",
        sceneJson(kWhite, R"([{"type": "obj", "material": "white", "file": "bad.obj"}])"));
    return loadError(scene, objPath.string());
  };
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_CONTAINS(objError(v3 + "f 1 2 0\n"),
                  "bad.obj: line 4: vertex index 0 is invalid (OBJ indices start at 1)");
  EXPECT_CONTAINS(objError(v3 + "f 1 2 4\n"),
                  "line 4: vertex index 4 out of range (file has 3 vertices)");
  EXPECT_CONTAINS(objError(v3 + "f 1 2 -4\n"),
                  "line 4: vertex index -4 out of range (3 vertices defined before this line)");
  // A relative index may only look back, even if more vertices follow.
  EXPECT_CONTAINS(objError("v 0 0 0\nv 1 0 0\nf 1 2 -3\nv 0 1 0\n"),
                  "line 3: vertex index -3 out of range (2 vertices defined before this line)");
  EXPECT_CONTAINS(objError(v3 + "f 1/0 2 3\n"), "line 4: texture coordinate index 0 is invalid");
  EXPECT_CONTAINS(objError(v3 + "vn 0 0 1\nf 1//2 2//1 3//1\n"),
                  "line 5: normal index 2 out of range (file has 1 normals)");
  EXPECT_CONTAINS(objError(v3 + "f 1 2 x\n"), "line 4: vertex index 'x' is not an integer");
  EXPECT_CONTAINS(objError(v3 + "f 1 2 +-3\n"), "line 4: vertex index '+-3' is not an integer");
  EXPECT_CONTAINS(objError("v 0 0 0\nv 1 +-1 0\nv 0 1 0\nf 1 2 3\n"),
                  "line 2: vertex coordinate '+-1' is not a number");
  EXPECT_CONTAINS(objError(v3 + "f 1 2 3 # comment\n"),
                  "line 4: vertex index '#' is not an integer");
  EXPECT_CONTAINS(objError(v3 + "f 1/ 2 3\n"), "line 4: malformed vertex reference '1/'");
  EXPECT_CONTAINS(objError(v3 + "f 1/1/1/1 2 3\n"), "line 4: malformed vertex reference");
  EXPECT_CONTAINS(objError(v3 + "f 1 2\n"), "line 4: face has 2 vertices (need at least 3)");
  EXPECT_CONTAINS(objError(v3 + "l 0 1\nf 1 2 3\n"), "line 4: vertex index 0 is invalid");
  EXPECT_CONTAINS(objError("v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n"),
                  "bad.obj: line 2: non-finite vertex coordinate '1e999'");
  EXPECT_CONTAINS(objError("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n"),
                  "line 2: non-finite vertex coordinate 'nan'");
  EXPECT_CONTAINS(objError("v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n"),
                  "line 2: non-finite vertex coordinate 'inf'");
  EXPECT_CONTAINS(objError("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"),
                  "line 2: non-finite vertex coordinate '1e39' (too large for a 32-bit float)");
  EXPECT_CONTAINS(objError("v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n"),
                  "line 2: vertex coordinate 'abc' is not a number");
  EXPECT_CONTAINS(objError("v 0 0 0\nv 0x10 0 0\nv 0 1 0\nf 1 2 3\n"),
                  "line 2: vertex coordinate '0x10' is not a number");
  EXPECT_CONTAINS(objError("v 0 0\n"), "line 1: vertex has 2 coordinates (need 3)");
  EXPECT_CONTAINS(objError(v3), "bad.obj: no faces");
  EXPECT_CONTAINS(objError(""), "bad.obj: no faces");
  // CRLF line ends count as one line end.
  EXPECT_CONTAINS(objError("v 0 0 0\r\nv 1 0 0\r\nf 1 2 3\r\n"),
                  "line 3: vertex index 3 out of range");

  // tinyobjloader keeps the vertex count of a face in a byte.
  std::string big;
  std::string face = "f";
  for (int i = 0; i < 256; ++i) {
    big += "v " + std::to_string(std::cos(i * 0.0245)) + " " +
           std::to_string(std::sin(i * 0.0245)) + " 0\n";
    face += " " + std::to_string(i + 1);
  }
  EXPECT_CONTAINS(objError(big + face + "\n"),
                  "line 257: face has 256 vertices (at most 255 supported)");
}

TEST(SceneObj, LargePolygonIsFanned) {
  TempDir dir;
  std::string obj;
  std::string face = "f";
  for (int i = 0; i < 255; ++i) {
    const double a = 2 * M_PI * i / 255;
    obj += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
    face += " " + std::to_string(i + 1);
  }
  dir.write("disc.obj", obj + face + "\n");
  const Scene scene = loadScene(dir.write(
      "scene.json",
      sceneJson(kWhite, R"([{"type": "obj", "material": "white", "file": "disc.obj"}])")));
  ASSERT_EQ(scene.triangles.size(), 253u);
  for (const Triangle& t : scene.triangles) EXPECT_EQ(t.v0, scene.triangles[0].v0);
}

// ---- robustness -------------------------------------------------------------------------

// Replaces every value of the scene `base`, one at a time, by values of every JSON type and
// some awkward numbers: each variant must load or throw InputError with a one-line message
// that starts with the file name, and nothing else.
void replaceEveryValueByEveryKind(const fs::path& base) {
  TempDir dir;
  fs::copy(kData / "meshes", dir.path() / "meshes");
  std::ifstream in(base);
  const nlohmann::json valid = nlohmann::json::parse(in);

  std::vector<nlohmann::json::json_pointer> pointers;
  const std::function<void(const nlohmann::json&, const nlohmann::json::json_pointer&)> collect =
      [&](const nlohmann::json& j, const nlohmann::json::json_pointer& p) {
        pointers.push_back(p);
        if (j.is_object()) {
          for (const auto& [key, value] : j.items()) collect(value, p / key);
        } else if (j.is_array()) {
          for (std::size_t i = 0; i < j.size(); ++i) collect(j[i], p / i);
        }
      };
  collect(valid, nlohmann::json::json_pointer());

  const std::vector<nlohmann::json> replacements = {nullptr,
                                                    true,
                                                    "x",
                                                    -1,
                                                    0,
                                                    0.5,
                                                    1e30,
                                                    -1e-30,
                                                    4294967296.0,
                                                    nlohmann::json::array(),
                                                    nlohmann::json::object(),
                                                    {1, 2},
                                                    {1, 2, 3},
                                                    {{"a", 1}}};
  int loaded = 0;
  int rejected = 0;
  for (const auto& pointer : pointers) {
    for (const auto& replacement : replacements) {
      nlohmann::json variant = valid;
      variant[pointer] = replacement;
      const fs::path path = dir.write("variant.json", variant.dump());
      try {
        loadScene(path);
        ++loaded;
      } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        EXPECT_EQ(m.rfind(path.string() + ": ", 0), 0u) << m;
        ++rejected;
      }
    }
    if (pointer.empty()) continue;
    // And with the key or element removed.
    nlohmann::json variant = valid;
    nlohmann::json& parent = variant.at(pointer.parent_pointer());
    if (parent.is_object()) {
      parent.erase(pointer.back());
    } else {
      parent.erase(static_cast<std::size_t>(std::stoul(pointer.back())));
    }
    const fs::path path = dir.write("variant.json", variant.dump());
    try {
      loadScene(path);
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(loaded, 0);
  EXPECT_GT(rejected, 0);
}

TEST(SceneRobustness, EveryValueReplacedByEveryKind) {
  replaceEveryValueByEveryKind(kData / "valid.json");
}

// The same for every material type and parameter (the scene fuzzer's seed of them).
TEST(SceneRobustness, EveryMaterialParameterReplacedByEveryKind) {
  replaceEveryValueByEveryKind(fs::path(PT_SOURCE_DIR) / "fuzz/corpus/scene/materials.json");
}

}  // namespace
}  // namespace pt
