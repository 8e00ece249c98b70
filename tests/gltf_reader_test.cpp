// The glTF reader (host/scene/gltf/): small files written by the tests (tests/gltf_builder.h)
// read into a Scene, their triangles, transforms, cameras and materials checked against values
// computed by hand, and malformed files refused with the JSON path of the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/check.h"
#include "image/image.h"
#include "scene/gltf/gltf_scene.h"
#include "scene/load_scene.h"
#include "tests/gltf_builder.h"
#include "tests/test_util.h"
#include "texture.h"

namespace pt {
namespace {

using nlohmann::json;
using test::GltfBuilder;

// One triangle (0,0,0), (1,0,0), (0,1,0) as mesh 0; returns the builder with node 0 using it.
GltfBuilder oneTriangle() {
  GltfBuilder b;
  const int p = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  b.mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
  return b;
}

Scene read(const std::string& text, const SceneLoadOptions& options = {}) {
  return loadGltfSceneBytes(text, "test.gltf", options);
}

// The InputError's message, or "" where the file is accepted.
std::string gltfErrorOf(const std::string& text, const SceneLoadOptions& options = {}) {
  try {
    read(text, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expectNear(vec3 a, vec3 b, float tolerance = 1e-6f) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(GltfReader, OneTriangleWithDefaultMaterialCameraAndSky) {
  GltfBuilder b = oneTriangle();
  b.node({{"mesh", 0}});
  b.scene({0});
  const Scene s = read(b.gltf());
  ASSERT_EQ(s.triangles.size(), 1u);
  expectNear(s.triangles[0].v0, vec3(0, 0, 0));
  expectNear(s.triangles[0].v1, vec3(1, 0, 0));
  expectNear(s.triangles[0].v2, vec3(0, 1, 0));
  // The specification's default material: metallic 1, roughness 1, base colour 1.
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].type, kMaterialGltf);
  EXPECT_EQ(s.materials[0].thickness, 1.0f);
  EXPECT_EQ(s.materials[0].alphaX, 1.0f);
  EXPECT_EQ(s.materials[0].reflectance, vec3(1.0f));
  EXPECT_EQ(s.materials[0].eta.x, 1.5f);
  // No light of its own: the white sky.
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, kLightInfinite);
  // The default framing: along -z at the bounding sphere's distance for 45 degrees.
  const double radius = 0.5 * std::sqrt(2.0);
  expectNear(s.camera.target, vec3(0.5f, 0.5f, 0.0f));
  expectNear(s.camera.position,
             vec3(0.5f, 0.5f, float(radius / std::sin(22.5 * 3.14159265358979 / 180.0))), 1e-5f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(GltfReader, NestedTrsAndMatrixAgainstHandComputedTransform) {
  GltfBuilder b = oneTriangle();
  // Child: a matrix translating by (0, 1, 0), column-major.
  const int child =
      b.node({{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1}}});
  // Parent: translation (1, 2, 3), rotation 90 degrees about z, scale 2.
  const double h = std::sqrt(0.5);
  const int parent = b.node({{"children", {child}},
                             {"translation", {1, 2, 3}},
                             {"rotation", {0, 0, h, h}},
                             {"scale", {2, 2, 2}}});
  b.scene({parent});
  const Scene s = read(b.gltf());
  ASSERT_EQ(s.triangles.size(), 1u);
  // p -> child (x, y + 1, z) -> scale 2 -> rotate (x, y) to (-y, x) -> + (1, 2, 3):
  // (0,0,0) -> (0,1,0) -> (0,2,0) -> (-2,0,0) -> (-1,2,3)
  // (1,0,0) -> (1,1,0) -> (2,2,0) -> (-2,2,0) -> (-1,4,3)
  // (0,1,0) -> (0,2,0) -> (0,4,0) -> (-4,0,0) -> (-3,2,3)
  expectNear(s.triangles[0].v0, vec3(-1, 2, 3), 1e-5f);
  expectNear(s.triangles[0].v1, vec3(-1, 4, 3), 1e-5f);
  expectNear(s.triangles[0].v2, vec3(-3, 2, 3), 1e-5f);
}

// Triangles whose float geometric normal cannot be computed (the cross product's square
// underflows or overflows) are dropped like zero-area ones, so that no normal is NaN: the
// fuzzer found one with vertex normals, whose flat stand-in normal came out NaN.
TEST(GltfReader, TrianglesTooSmallOrLargeForAFloatNormalAreDropped) {
  for (double scale : {1e-20, 1e20}) {
    SCOPED_TRACE(scale);
    GltfBuilder b;
    const float s = float(scale);
    const int p = b.floats({0, 0, 0, s, 0, 0, 0, s, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int n = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
    b.mesh(json::array({{{"attributes", {{"POSITION", p}, {"NORMAL", n}}}}}));
    b.node({{"mesh", 0}});
    const Scene sc = read(b.gltf());
    ASSERT_EQ(sc.triangles.size(), 1u);
    expectNear(sc.triangles[0].v1, vec3(1, 0, 0));
    ASSERT_EQ(sc.warnings.size(), 1u);
    EXPECT_EQ(sc.warnings[0], "test.gltf: dropped 1 zero-area triangle");
  }
}

TEST(GltfReader, EveryInstanceOfAMeshIsEmitted) {
  GltfBuilder b = oneTriangle();
  const int a = b.node({{"mesh", 0}});
  const int c = b.node({{"mesh", 0}, {"translation", {10, 0, 0}}});
  const int d = b.node({{"mesh", 0}, {"translation", {0, 0, 5}}});
  const int group = b.node({{"children", {c, d}}, {"translation", {0, 1, 0}}});
  b.scene({a, group});
  const Scene s = read(b.gltf());
  ASSERT_EQ(s.triangles.size(), 3u);
  expectNear(s.triangles[0].v0, vec3(0, 0, 0));
  expectNear(s.triangles[1].v0, vec3(10, 1, 0));
  expectNear(s.triangles[2].v0, vec3(0, 1, 5));
}

TEST(GltfReader, MirroringTransformKeepsTheFrontAndNormalsUseTheInverseTranspose) {
  GltfBuilder b;
  const int p = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  // Normals tilted in x and z, so that a non-uniform scale changes their direction.
  const int n = b.floats({1, 0, 1, 1, 0, 1, 1, 0, 1}, "VEC3", 3);
  b.mesh(json::array({{{"attributes", {{"POSITION", p}, {"NORMAL", n}}}}}));
  b.node({{"mesh", 0}, {"scale", {-1, 1, 2}}});
  b.scene({0});
  const Scene s = read(b.gltf());
  ASSERT_EQ(s.triangles.size(), 1u);
  // Mirrored in x: the corners 1 and 2 swap, so the winding normal stays the front (+z).
  expectNear(s.triangles[0].v1, vec3(0, 1, 0));
  expectNear(s.triangles[0].v2, vec3(-1, 0, 0));
  const vec3 ng =
      glm::cross(s.triangles[0].v1 - s.triangles[0].v0, s.triangles[0].v2 - s.triangles[0].v0);
  EXPECT_GT(ng.z, 0.0f);
  // (1, 0, 1) by the inverse transpose diag(-1, 1, 1/2): (-1, 0, 0.5), normalized.
  ASSERT_EQ(s.normals.size(), 1u);
  expectNear(s.normals[0].n0, glm::normalize(vec3(-1, 0, 0.5f)), 1e-6f);
}

// Indices of every unsigned component type, and vertices in every component type (normalized
// integers as the specification maps them).
TEST(GltfReader, EveryComponentTypeOfIndicesAndVertices) {
  struct Case {
    int type;
    bool normalized;
    std::vector<std::uint8_t> bytes;  // three VEC3 elements
    float scale;                      // what one unit of the integer is worth
  };
  const auto le16 = [](std::vector<int> v) {
    std::vector<std::uint8_t> out;
    for (int x : v) {
      out.push_back(std::uint8_t(x & 0xFF));
      out.push_back(std::uint8_t((x >> 8) & 0xFF));
    }
    return out;
  };
  const std::vector<Case> cases = {
      {GltfBuilder::kUByte, true, {0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 0}, 1.0f},
      {GltfBuilder::kByte, true, {0, 0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 0}, 1.0f},
      {GltfBuilder::kUShort, true, le16({0, 0, 0, 65535, 0, 0, 0, 65535, 0}), 1.0f},
      {GltfBuilder::kShort, true, le16({0, 0, 0, 32767, 0, 0, 0, 32767, 0}), 1.0f},
      {GltfBuilder::kUByte, false, {0, 0, 0, 3, 0, 0, 0, 3, 0, 0, 0, 0}, 3.0f},
      {GltfBuilder::kShort, false, le16({0, 0, 0, -2, 0, 0, 0, 2, 0}), 2.0f},
  };
  for (const Case& c : cases) {
    for (int indexType : {GltfBuilder::kUByte, GltfBuilder::kUShort, GltfBuilder::kUInt}) {
      SCOPED_TRACE(std::to_string(c.type) + " indices " + std::to_string(indexType));
      GltfBuilder b;
      // Elements of three components padded to 4 bytes where they are shorter (the
      // specification's alignment): a stride of 4 for bytes, 8 for shorts.
      const std::size_t componentSize =
          c.type == GltfBuilder::kUByte || c.type == GltfBuilder::kByte ? 1 : 2;
      std::vector<std::uint8_t> padded;
      for (int e = 0; e < 3; ++e) {
        const std::size_t size = 3 * componentSize;
        padded.insert(padded.end(), c.bytes.begin() + e * size, c.bytes.begin() + (e + 1) * size);
        while (padded.size() % 4 != 0) padded.push_back(0);
      }
      const int p =
          b.accessor(b.view(padded, padded.size() / 3), c.type, 3, "VEC3", 0, c.normalized);
      // Indices 2, 0, 1: the triangle starts at vertex 2.
      std::vector<std::uint8_t> idx;
      const int width = indexType == GltfBuilder::kUByte    ? 1
                        : indexType == GltfBuilder::kUShort ? 2
                                                            : 4;
      for (int v : {2, 0, 1}) {
        for (int k = 0; k < width; ++k) idx.push_back(k == 0 ? std::uint8_t(v) : 0);
      }
      const int i = b.accessor(b.view(idx), indexType, 3, "SCALAR");
      b.mesh(json::array({{{"attributes", {{"POSITION", p}}}, {"indices", i}}}));
      b.node({{"mesh", 0}});
      const Scene s = read(b.gltf());
      ASSERT_EQ(s.triangles.size(), 1u);
      const float x = c.type == GltfBuilder::kShort && !c.normalized ? -2.0f : c.scale;
      expectNear(s.triangles[0].v0, vec3(0, c.scale, 0));
      expectNear(s.triangles[0].v1, vec3(0, 0, 0));
      expectNear(s.triangles[0].v2, vec3(x, 0, 0));
    }
  }
}

TEST(GltfReader, InterleavedAttributesWithAByteStride) {
  GltfBuilder b;
  // Position and normal interleaved: 24 bytes a vertex, the normal at byte 12.
  const std::vector<float> data = {0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1};
  const int v = b.view(data, 24);
  const int p = b.accessor(v, GltfBuilder::kFloat, 3, "VEC3");
  const int n = b.accessor(v, GltfBuilder::kFloat, 3, "VEC3", 12);
  b.mesh(json::array({{{"attributes", {{"POSITION", p}, {"NORMAL", n}}}}}));
  b.node({{"mesh", 0}});
  const Scene s = read(b.gltf());
  ASSERT_EQ(s.triangles.size(), 1u);
  expectNear(s.triangles[0].v1, vec3(1, 0, 0));
  expectNear(s.triangles[0].v2, vec3(0, 1, 0));
  expectNear(s.normals[0].n2, vec3(0, 0, 1));
}

TEST(GltfReader, SparseAccessorsOverAViewAndOverZeros) {
  for (bool withView : {true, false}) {
    SCOPED_TRACE(withView ? "over a view" : "over zeros");
    GltfBuilder b;
    const int base = b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
    // Vertex 2 replaced by (0, 5, 0) (and vertex 1 by (3, 0, 0) over zeros).
    const std::vector<std::uint16_t> indices =
        withView ? std::vector<std::uint16_t>{2} : std::vector<std::uint16_t>{1, 2};
    const std::vector<float> values =
        withView ? std::vector<float>{0, 5, 0} : std::vector<float>{3, 0, 0, 0, 5, 0};
    const int iv = b.view(indices), vv = b.view(values);
    const int p = b.accessor(withView ? base : -1, GltfBuilder::kFloat, 3, "VEC3");
    b.doc["accessors"][p]["sparse"] = {
        {"count", indices.size()},
        {"indices", {{"bufferView", iv}, {"componentType", GltfBuilder::kUShort}}},
        {"values", {{"bufferView", vv}}}};
    b.mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
    b.node({{"mesh", 0}});
    const Scene s = read(b.gltf());
    ASSERT_EQ(s.triangles.size(), 1u);
    expectNear(s.triangles[0].v0, vec3(0, 0, 0));
    expectNear(s.triangles[0].v1, withView ? vec3(1, 0, 0) : vec3(3, 0, 0));
    expectNear(s.triangles[0].v2, vec3(0, 5, 0));
  }
}

TEST(GltfReader, StripsAndFansInTheSpecificationsVertexOrder) {
  GltfBuilder b;
  // A square's four corners and a fifth point: three triangles as a strip, three as a fan.
  const int p = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 3, 0}, "VEC3", 3);
  b.mesh(json::array({{{"attributes", {{"POSITION", p}}}, {"mode", 5}}}));
  b.mesh(json::array({{{"attributes", {{"POSITION", p}}}, {"mode", 6}}}));
  b.node({{"mesh", 0}});
  b.node({{"mesh", 1}, {"translation", {0, 0, 1}}});
  const Scene s = read(b.gltf());
  // Strip: (0,1,2), then the specification's odd triangle (i, i+2, i+1) = (1,3,2), then
  // (2,3,4); fan: (1,2,0), (2,3,0), (3,4,0).
  ASSERT_EQ(s.triangles.size(), 6u);
  expectNear(s.triangles[1].v0, vec3(1, 0, 0));
  expectNear(s.triangles[1].v1, vec3(1, 1, 0));
  expectNear(s.triangles[1].v2, vec3(0, 1, 0));
  expectNear(s.triangles[2].v0, vec3(0, 1, 0));
  expectNear(s.triangles[2].v2, vec3(2, 3, 0));
  expectNear(s.triangles[3].v0, vec3(1, 0, 1));
  expectNear(s.triangles[3].v2, vec3(0, 0, 1));
  expectNear(s.triangles[5].v1, vec3(2, 3, 1));
}

TEST(GltfReader, GlbChunksAndExternalBuffersGiveTheSameScene) {
  GltfBuilder b = oneTriangle();
  b.node({{"mesh", 0}, {"translation", {0, 0, -2}}});
  const test::TempDir dir;
  dir.write("model.bin", b.binBytes());
  const auto external = dir.write("model.gltf", b.gltf("model.bin"));
  const auto glb = dir.write("model.glb", b.glb());
  const Scene fromData = read(b.gltf());
  for (const auto& path : {external, glb}) {
    SCOPED_TRACE(path.string());
    const Scene s = loadScene(path);
    ASSERT_EQ(s.triangles.size(), 1u);
    EXPECT_EQ(s.triangles[0].v2, fromData.triangles[0].v2);
    expectNear(s.triangles[0].v2, vec3(0, 1, -2));
  }
}

TEST(GltfReader, PerspectiveCameraOfTheFirstNodeOrTheOneNamed) {
  GltfBuilder b = oneTriangle();
  b.doc["cameras"] =
      json::array({{{"type", "perspective"},
                    {"name", "wide"},
                    {"perspective", {{"yfov", 1.0}, {"aspectRatio", 2.0}, {"znear", 0.1}}}},
                   {{"type", "perspective"},
                    {"name", "close"},
                    {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}});
  const double h = std::sqrt(0.5);
  b.node({{"mesh", 0}});
  // Camera 0 at (0, 0, 5) looking down -z; camera 1 at (3, 0, 0) turned 90 degrees about y
  // (its -z to -x).
  b.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  b.node({{"camera", 1}, {"translation", {3, 0, 0}}, {"rotation", {0, h, 0, h}}});
  b.scene({0, 1, 2});
  const Scene s = read(b.gltf());
  expectNear(s.camera.position, vec3(0, 0, 5));
  expectNear(s.camera.target, vec3(0, 0, 4));
  expectNear(s.camera.up, vec3(0, 1, 0));
  EXPECT_NEAR(s.camera.vfovDegrees, 180.0 / 3.14159265358979, 1e-4);
  EXPECT_EQ(s.camera.height, 512);
  EXPECT_EQ(s.camera.width, 1024);
  for (const std::string wanted : {"1", "close"}) {
    SCOPED_TRACE(wanted);
    const Scene c = read(b.gltf(), SceneLoadOptions{.camera = wanted});
    expectNear(c.camera.position, vec3(3, 0, 0));
    expectNear(c.camera.target, vec3(2, 0, 0), 1e-6f);
    EXPECT_EQ(c.camera.width, 512);
  }
  EXPECT_EQ(gltfErrorOf(b.gltf(), SceneLoadOptions{.camera = "clsoe"}),
            "test.gltf: cameras: no camera named 'clsoe' (did you mean 'close'?)");
  EXPECT_EQ(gltfErrorOf(b.gltf(), SceneLoadOptions{.camera = "7"}),
            "test.gltf: cameras: --camera 7 out of range (the file has 2 cameras)");
}

TEST(GltfReader, MaterialFactorsAndExtensions) {
  GltfBuilder b = oneTriangle();
  b.doc["materials"] = json::array(
      {{{"pbrMetallicRoughness",
         {{"baseColorFactor", {0.8, 0.4, 0.2, 1}},
          {"metallicFactor", 0.0},
          {"roughnessFactor", 0.5}}},
        {"extensions", {{"KHR_materials_ior", {{"ior", 1.4}}}}},
        {"emissiveFactor", {1, 0.5, 0}},
        {"doubleSided", true}},
       {{"pbrMetallicRoughness",
         {{"baseColorFactor", {0.9, 0.9, 0.9, 1}}, {"roughnessFactor", 0.2}}},
        {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 3}}}}},
        {"emissiveFactor", {0, 0, 1}}}});
  b.doc["meshes"][0]["primitives"][0]["material"] = 0;
  b.doc["meshes"].push_back(b.doc["meshes"][0]);
  b.doc["meshes"][1]["primitives"][0]["material"] = 1;
  b.node({{"mesh", 0}});
  b.node({{"mesh", 1}, {"translation", {0, 0, 1}}});
  const Scene s = read(b.gltf());
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& dielectric = s.materials[0];
  EXPECT_EQ(dielectric.type, kMaterialGltf);
  expectNear(dielectric.reflectance, vec3(0.8f, 0.4f, 0.2f));
  EXPECT_FLOAT_EQ(dielectric.eta.x, 1.4f);
  EXPECT_FLOAT_EQ(dielectric.alphaX, 0.25f);
  EXPECT_FLOAT_EQ(dielectric.alphaY, 0.25f);
  EXPECT_EQ(dielectric.thickness, 0.0f);
  expectNear(dielectric.emission, vec3(1, 0.5f, 0));
  EXPECT_EQ(dielectric.twoSided, 1u);
  const Material& metal = s.materials[1];
  EXPECT_EQ(metal.type, kMaterialGltf);
  EXPECT_EQ(metal.thickness, 1.0f);
  expectNear(metal.reflectance, vec3(0.9f));
  EXPECT_FLOAT_EQ(metal.alphaX, 0.04f);
  expectNear(metal.emission, vec3(0, 0, 3));
  EXPECT_EQ(metal.twoSided, 0u);
  // Emission lights the scene: no sky is added.
  EXPECT_TRUE(s.lights.empty());
}

TEST(GltfReader, UnsimulatedFeaturesWarnOnceAndAreErrorsWithStrict) {
  GltfBuilder b = oneTriangle();
  b.doc["meshes"][0]["primitives"].push_back(
      {{"attributes", {{"POSITION", 0}}}, {"mode", 0}});  // points
  b.doc["extensionsUsed"] = {"KHR_materials_iridescence"};
  b.doc["animations"] = json::array({{{"channels", json::array()}, {"samplers", json::array()}}});
  b.node({{"mesh", 0}});
  const Scene s = read(b.gltf());
  EXPECT_EQ(s.triangles.size(), 1u);
  ASSERT_EQ(s.warnings.size(), 3u);
  EXPECT_EQ(s.warnings[0],
            "test.gltf: extensionsUsed[0]: KHR_materials_iridescence is not simulated (rendered "
            "without it)");
  EXPECT_EQ(s.warnings[1],
            "test.gltf: animations: animations are not simulated: the rest pose is rendered");
  EXPECT_EQ(s.warnings[2],
            "test.gltf: meshes[0].primitives[1].mode: points and lines have no "
            "area and are not rendered");
  EXPECT_EQ(gltfErrorOf(b.gltf(), SceneLoadOptions{.strict = true}),
            "test.gltf: extensionsUsed[0]: KHR_materials_iridescence is not simulated (rendered "
            "without it) (an error with --strict)");
}

// Each malformed file gives one line naming the field by its JSON path.
TEST(GltfReader, ErrorsNameTheJsonPath) {
  struct Case {
    const char* name;
    void (*edit)(GltfBuilder&);
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"normal accessor out of range",
       [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 12; },
       "test.gltf: meshes[0].primitives[0].attributes.NORMAL: accessor 12 out of range (the "
       "file has 1)"},
      {"position of the wrong type", [](GltfBuilder& b) { b.doc["accessors"][0]["type"] = "VEC2"; },
       "test.gltf: meshes[0].primitives[0].attributes.POSITION: accessor 0 is VEC2, expected "
       "VEC3"},
      {"accessor past its view", [](GltfBuilder& b) { b.doc["accessors"][0]["count"] = 4; },
       "test.gltf: accessors[0].bufferView: 4 elements of 12 bytes from byte 0 run past the end "
       "of buffer view 0 (36 bytes)"},
      {"view past its buffer", [](GltfBuilder& b) { b.doc["bufferViews"][0]["byteLength"] = 40; },
       "test.gltf: bufferViews[0].byteLength: bytes 0 + 40 run past the end of buffer 0 (36 "
       "bytes)"},
      {"stride shorter than an element",
       [](GltfBuilder& b) { b.doc["bufferViews"][0]["byteStride"] = 8; },
       "test.gltf: bufferViews[0].byteStride: 8 is less than the element size 12"},
      {"index out of range",
       [](GltfBuilder& b) {
         const std::vector<std::uint16_t> idx = {0, 1, 3};
         b.doc["meshes"][0]["primitives"][0]["indices"] =
             b.accessor(b.view(idx), GltfBuilder::kUShort, 3, "SCALAR");
       },
       "test.gltf: meshes[0].primitives[0].indices: index 3 out of range (POSITION has 3 "
       "elements)"},
      {"float indices", [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["indices"] = 0; },
       "test.gltf: meshes[0].primitives[0].indices: accessor 0 is VEC3, expected SCALAR"},
      {"node mesh out of range", [](GltfBuilder& b) { b.doc["nodes"][0]["mesh"] = 3; },
       "test.gltf: nodes[0].mesh: mesh 3 out of range (the file has 1)"},
      {"two parents",
       [](GltfBuilder& b) {
         b.node({{"children", {0}}});
         b.node({{"children", {0}}});
       },
       "test.gltf: nodes[2].children[0]: node 0 is already a child of node 1 (a node has one "
       "parent)"},
      {"material factor out of range",
       [](GltfBuilder& b) {
         b.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"metallicFactor", 2}}}}});
         b.doc["meshes"][0]["primitives"][0]["material"] = 0;
       },
       "test.gltf: materials[0].pbrMetallicRoughness.metallicFactor: 2 is not in [0, 1]"},
      {"material out of range",
       [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["material"] = 4; },
       "test.gltf: meshes[0].primitives[0].material: material 4 out of range (the file has 0)"},
      {"bad rotation",
       [](GltfBuilder& b) {
         b.doc["nodes"][0]["rotation"] = {0, 0, 0, 0};
       },
       "test.gltf: nodes[0].rotation: not a unit quaternion (length 0)"},
      {"matrix not affine",
       [](GltfBuilder& b) {
         b.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2};
       },
       "test.gltf: nodes[0].matrix: the last row must be 0, 0, 0, 1 (an affine transform)"},
      {"bad sparse index",
       [](GltfBuilder& b) {
         const std::vector<std::uint16_t> idx = {5};
         const int iv = b.view(idx), vv = b.view(std::vector<float>{0, 0, 0});
         b.doc["accessors"][0]["sparse"] = {
             {"count", 1},
             {"indices", {{"bufferView", iv}, {"componentType", GltfBuilder::kUShort}}},
             {"values", {{"bufferView", vv}}}};
       },
       "test.gltf: accessors[0].sparse.indices: index 5 is not increasing or not below the "
       "count 3"},
      {"no triangles", [](GltfBuilder& b) { b.doc["nodes"][0].erase("mesh"); },
       "test.gltf: scene: the scene has no triangles to render"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    GltfBuilder b = oneTriangle();
    b.node({{"mesh", 0}});
    c.edit(b);
    EXPECT_EQ(gltfErrorOf(b.gltf()), c.expected);
  }
}

TEST(GltfReader, UnparsableFilesGiveOneLineNamingTheFile) {
  for (const std::string text : {std::string("{"), std::string("{\"asset\": {}}"),
                                 std::string("glTF\x02\0\0\0\x08\0\0\0", 12)}) {
    const std::string e = gltfErrorOf(text);
    EXPECT_EQ(e.rfind("test.gltf: ", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(GltfReader, PunctualLightsAtTheirNodesShiningAlongMinusZ) {
  GltfBuilder b = oneTriangle();
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
      json::array({{{"type", "point"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 8.0}},
                   {{"type", "spot"},
                    {"intensity", 2.0},
                    {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}},
                   {{"type", "directional"}, {"intensity", 3.0}}});
  const double h = std::sqrt(0.5);
  b.node({{"mesh", 0}});
  const int point = b.node(
      {{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  // The spot turned 90 degrees about x: its -z to -y (shining down), under a parent's offset.
  const int spot = b.node({{"translation", {0, 5, 0}},
                           {"rotation", {-h, 0, 0, h}},
                           {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  const int parent = b.node({{"translation", {10, 0, 0}}, {"children", {spot}}});
  const int sun = b.node(
      {{"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  b.scene({0, point, parent, sun});
  const Scene s = read(b.gltf());
  EXPECT_TRUE(s.warnings.empty());
  ASSERT_EQ(s.lights.size(), 3u);  // and no sky
  EXPECT_EQ(s.lights[0].type, kLightPoint);
  expectNear(s.lights[0].position, vec3(1, 2, 3));
  expectNear(s.lights[0].radiance, vec3(8, 4, 2));
  EXPECT_EQ(s.lights[1].type, kLightSpot);
  expectNear(s.lights[1].position, vec3(10, 5, 0));
  expectNear(s.lights[1].direction, vec3(0, -1, 0));
  expectNear(s.lights[1].radiance, vec3(2));
  EXPECT_FLOAT_EQ(s.lights[1].cosFalloffStart, std::cos(0.2f));
  EXPECT_FLOAT_EQ(s.lights[1].cosFalloffEnd, std::cos(0.5f));
  // A distant light's direction points towards the light: up, for a sun shining down.
  EXPECT_EQ(s.lights[2].type, kLightDistant);
  expectNear(s.lights[2].direction, vec3(0, 1, 0));
  expectNear(s.lights[2].radiance, vec3(3));
  b.doc["nodes"][point]["extensions"]["KHR_lights_punctual"]["light"] = 7;
  EXPECT_EQ(gltfErrorOf(b.gltf()),
            "test.gltf: nodes[1].extensions.KHR_lights_punctual.light: light 7 out of range (the "
            "file has 3)");
}

// A 2 x 2 base colour texture: red, green (top row), blue, white; read from a data URI and from
// a buffer view, times the factor, its v axis flipped to the renderer's, KHR_texture_transform's
// offset and scale applied.
TEST(GltfReader, BaseColorTextureTimesFactorFromDataUriAndBufferView) {
  const test::TempDir dir;
  Image texels(2, 2);
  texels.at(0, 0) = vec3(1, 0, 0);
  texels.at(1, 0) = vec3(0, 1, 0);
  texels.at(0, 1) = vec3(0, 0, 1);
  texels.at(1, 1) = vec3(1, 1, 1);
  writeImage(texels, dir / "t.png");
  std::ifstream in(dir / "t.png", std::ios::binary);
  const std::vector<std::uint8_t> png((std::istreambuf_iterator<char>(in)),
                                      std::istreambuf_iterator<char>());
  GltfBuilder b = oneTriangle();
  b.doc["images"] =
      json::array({{{"uri", "data:image/png;base64," + test::base64(png)}},
                   {{"bufferView", b.view(png.data(), png.size())}, {"mimeType", "image/png"}}});
  b.doc["samplers"] = json::array({{{"wrapS", 33071}, {"wrapT", 33071}}});
  b.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}, {{"source", 1}}});
  const auto material = [](int texture, json extensions) {
    json info = {{"index", texture}};
    if (!extensions.is_null()) info["extensions"] = extensions;
    return json{{"pbrMetallicRoughness",
                 {{"baseColorFactor", {0.5, 1.0, 0.25, 1.0}}, {"baseColorTexture", info}}}};
  };
  b.doc["materials"] =
      json::array({material(0, nullptr), material(1, nullptr),
                   material(1, {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}}}}),
                   material(1, {{"KHR_texture_transform", {{"scale", {2.0, 2.0}}}}})});
  for (int m = 0; m < 4; ++m) {
    b.doc["meshes"].push_back(b.doc["meshes"][0]);
    b.doc["meshes"][m + 1]["primitives"][0]["material"] = m;
    b.node({{"mesh", m + 1}, {"translation", {0, 0, m}}});
  }
  b.doc["extensionsUsed"] = {"KHR_texture_transform"};
  const Scene s = read(b.gltf());
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.materialTextures.size(), 4u);
  const TextureTables tables{s.textureNodes.data(), s.imageWords.data(), nullptr, nullptr};
  // glTF's (u, v) is the renderer's (u, 1 - v).
  const auto at = [&](int m, float u, float v) {
    return evalTexture(tables, s.materialTextures[std::size_t(m)].reflectance, vec2(u, 1.0f - v));
  };
  const vec3 factor(0.5f, 1.0f, 0.25f);
  for (int m : {0, 1}) {
    SCOPED_TRACE(m);
    expectNear(at(m, 0.25f, 0.25f), factor * vec3(1, 0, 0), 1e-6f);  // top left
    expectNear(at(m, 0.75f, 0.25f), factor * vec3(0, 1, 0), 1e-6f);
    expectNear(at(m, 0.25f, 0.75f), factor * vec3(0, 0, 1), 1e-6f);
  }
  EXPECT_EQ((s.textureNodes[s.materialTextures[0].reflectance].flags >> 4u) & 15u, kWrapClamp);
  EXPECT_EQ((s.textureNodes[s.materialTextures[1].reflectance].flags >> 4u) & 15u, kWrapRepeat);
  // Offset (0.5, 0): u 0.25 reads u 0.75; scale 2: (0.125, 0.125) reads (0.25, 0.25), a texel's
  // centre (bilinear filtering blends nothing in there).
  expectNear(at(2, 0.25f, 0.25f), factor * vec3(0, 1, 0), 1e-6f);
  expectNear(at(3, 0.125f, 0.125f), factor * vec3(1, 0, 0), 1e-6f);
  expectNear(at(3, 0.125f, 0.375f), factor * vec3(0, 0, 1), 1e-6f);
}

TEST(GltfReader, EnvironmentImageReplacesTheSky) {
  const test::TempDir dir;
  Image sky;
  sky.width = 8;
  sky.height = 4;
  sky.pixels.assign(32, vec3(0.5f, 0.25f, 2.0f));
  sky.pixels[3] = vec3(-1.0f);  // negative radiance is no radiance
  const auto file = dir / "sky.pfm";
  writeImage(sky, file);
  GltfBuilder b = oneTriangle();
  b.node({{"mesh", 0}});
  const Scene s = read(b.gltf(), SceneLoadOptions{.environment = file.string()});
  EXPECT_TRUE(s.lights.empty());
  ASSERT_TRUE(s.environment.has_value());
  EXPECT_EQ(s.environment->mapping, kEnvironmentLatLong);
  EXPECT_EQ(s.environment->image.width, 8);
  EXPECT_EQ(s.environment->image.pixels[0], vec3(0.5f, 0.25f, 2.0f));
  EXPECT_EQ(s.environment->image.pixels[3], vec3(0.0f));
  const std::string missing = (dir / "none.exr").string();
  EXPECT_EQ(gltfErrorOf(b.gltf(), SceneLoadOptions{.environment = missing}).rfind(missing, 0), 0u);
}

TEST(GltfReader, CommandLineRendersAGltfAndRefusesABadOneWithStatus2) {
  const test::TempDir dir;
  GltfBuilder b = oneTriangle();
  b.node({{"mesh", 0}});
  const auto good = dir.write("good.gltf", b.gltf());
  const test::PtResult ok =
      test::runPt("render " + good.string() + " --backend cpu --width 8 --height 8 --spp 1 --out " +
                  (dir / "good.exr").string());
  EXPECT_EQ(ok.status, 0) << ok.err;
  b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 12;
  const auto bad = dir.write("bad.gltf", b.gltf());
  const test::PtResult r = test::runPt("render " + bad.string() + " --backend cpu");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, bad.string() +
                       ": meshes[0].primitives[0].attributes.NORMAL: accessor 12 out of range "
                       "(the file has 1)\n");
}

}  // namespace
}  // namespace pt
