// A glTF file's environment: Radiance .hdr images read (against known pixel values) and given
// by --env, and the JSON wrapper that names a glTF file with an environment, a camera and
// integrator settings, its errors one line naming the wrapper and the field.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "image/image.h"
#include "scene/load_scene.h"
#include "test_util.h"
#include "tests/gltf_builder.h"

namespace pt {
namespace {

using nlohmann::json;
using test::GltfBuilder;

// A flat (not run-length encoded) Radiance file of 2 x 1 pixels: RGBE (128, 64, 32, 129) is
// (1, 0.5, 0.25) and (128, 64, 32, 131) is (4, 2, 1), exactly (stb_image's m 2^(e - 136)).
std::string hdrFile() {
  std::string s = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
  for (unsigned char c : {128, 64, 32, 129, 128, 64, 32, 131}) s += char(c);
  return s;
}

GltfBuilder triangleWithTwoCameras() {
  GltfBuilder b;
  const int p = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  b.mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
  b.node({{"mesh", 0}});
  b.doc["cameras"] = json::array({{{"type", "perspective"},
                                   {"name", "near"},
                                   {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}},
                                  {{"type", "perspective"},
                                   {"name", "far"},
                                   {"perspective", {{"yfov", 0.25}, {"znear", 0.1}}}}});
  b.node({{"camera", 0}, {"translation", {0, 0, 3}}});
  b.node({{"camera", 1}, {"translation", {0, 0, 9}}});
  return b;
}

std::string errorOf(const std::filesystem::path& path, const SceneLoadOptions& options = {}) {
  try {
    loadScene(path, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(GltfEnvironment, RadianceHdrReadWithItsPixelValues) {
  const test::TempDir dir;
  const auto file = dir.write("sky.hdr", hdrFile());
  const Image image = readImage(file);
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 1);
  EXPECT_EQ(image.pixels[0], vec3(1.0f, 0.5f, 0.25f));
  EXPECT_EQ(image.pixels[1], vec3(4.0f, 2.0f, 1.0f));
  // --env with it lights a glTF file (no white sky then).
  const auto model = dir.write("model.gltf", triangleWithTwoCameras().gltf());
  const Scene scene = loadScene(model, SceneLoadOptions{.environment = file.string()});
  ASSERT_TRUE(scene.environment.has_value());
  EXPECT_TRUE(scene.lights.empty());
  EXPECT_EQ(scene.environment->image.pixels[1], vec3(4.0f, 2.0f, 1.0f));
  // A truncated file: one line naming it.
  const auto bad = dir.write("bad.hdr", hdrFile().substr(0, 50));
  const std::string message = errorOf(model, SceneLoadOptions{.environment = bad.string()});
  EXPECT_EQ(message.rfind(bad.string() + ": ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(GltfWrapper, NamesTheFileAndAddsEnvironmentCameraAndIntegrator) {
  const test::TempDir dir;
  dir.write("sky.hdr", hdrFile());
  dir.write("model.gltf", triangleWithTwoCameras().gltf());
  const auto wrapper =
      dir.write("scene.json", json({{"description", "a triangle under a sky"},
                                    {"gltf", "model.gltf"},
                                    {"camera", "far"},
                                    {"integrator", {{"spp", 7}, {"maxDepth", 3}}},
                                    {"environment", {{"filename", "sky.hdr"}, {"scale", 2}}}})
                                  .dump());
  const Scene scene = loadScene(wrapper);
  ASSERT_TRUE(scene.environment.has_value());
  EXPECT_TRUE(scene.lights.empty());  // the white sky replaced
  EXPECT_EQ(scene.environment->image.pixels[0], vec3(2.0f, 1.0f, 0.5f));
  EXPECT_EQ(scene.integrator.spp, 7);
  EXPECT_EQ(scene.integrator.maxDepth, 3);
  EXPECT_EQ(scene.camera.position, vec3(0.0f, 0.0f, 9.0f));  // the camera named "far"
  // A camera object: its keys over the file's camera; a constant environment.
  const auto second =
      dir.write("second.json", json({{"gltf", "model.gltf"},
                                     {"camera", {{"width", 64}, {"height", 32}, {"vfov", 30}}},
                                     {"environment", {{"radiance", {0.5, 0.5, 0.5}}}}})
                                   .dump());
  const Scene s2 = loadScene(second);
  EXPECT_EQ(s2.camera.width, 64);
  EXPECT_EQ(s2.camera.height, 32);
  EXPECT_EQ(s2.camera.vfovDegrees, 30.0f);
  EXPECT_EQ(s2.camera.position, vec3(0.0f, 0.0f, 3.0f));  // the file's first camera
  ASSERT_EQ(s2.lights.size(), 1u);
  EXPECT_EQ(s2.lights[0].radiance, vec3(0.5f));
  EXPECT_FALSE(s2.environment.has_value());
  // The command line's --camera wins over the wrapper's.
  EXPECT_EQ(loadScene(wrapper, SceneLoadOptions{.camera = "0"}).camera.position,
            vec3(0.0f, 0.0f, 3.0f));
  // And it renders from the command line.
  const test::PtResult ok = test::runPt("render " + wrapper.string() +
                                        " --backend cpu --width 8 --height 8 --spp 1 --out " +
                                        (dir / "out.exr").string());
  EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST(GltfWrapper, ErrorsNameTheWrapperAndTheField) {
  const test::TempDir dir;
  dir.write("model.gltf", triangleWithTwoCameras().gltf());
  dir.write("model.obj", "v 0 0 0\n");
  struct Case {
    json wrapper;
    std::string expected;  // after "<wrapper>: "
  };
  const std::vector<Case> cases = {
      {{{"gltf", 3}}, "gltf: expected a string"},
      {{{"gltf", "none.gltf"}}, "gltf: no such file: " + (dir / "none.gltf").string()},
      {{{"gltf", "model.obj"}}, "gltf: expected a .gltf or .glb file, got the string 'model.obj'"},
      {{{"gltf", "model.gltf"}, {"shapes", json::array()}}, "shapes: unknown key"},
      {{{"gltf", "model.gltf"}, {"camera", true}},
       "camera: expected a camera of the glTF file (its index or name) or a camera object, got "
       "true"},
      {{{"gltf", "model.gltf"}, {"camera", {{"vfov", 200}}}},
       "camera.vfov: expected a field of view in degrees strictly between 0 and 180, got the "
       "number 200"},
      {{{"gltf", "model.gltf"}, {"camera", {{"medium", "fog"}}}},
       "camera.medium: a glTF scene has no media"},
      {{{"gltf", "model.gltf"}, {"integrator", {{"spp", 0}}}}, "integrator.spp: "},
      {{{"gltf", "model.gltf"}, {"environment", {{"filename", "none.hdr"}}}},
       "environment.filename: "},
      {{{"gltf", "model.gltf"}, {"environment", {{"radiance", {1, -1, 1}}}}},
       "environment.radiance[1]: expected a non-negative number"},
      {{{"gltf", "model.gltf"}, {"environment", 1}}, "environment: expected an object"},
  };
  for (const Case& c : cases) {
    const auto wrapper = dir.write("w.json", c.wrapper.dump());
    const std::string message = errorOf(wrapper);
    EXPECT_EQ(message.rfind(wrapper.string() + ": " + c.expected, 0), 0u)
        << c.wrapper.dump() << "\n"
        << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // A camera the glTF file lacks: the glTF file's error.
  const auto wrapper = dir.write("w.json", json({{"gltf", "model.gltf"}, {"camera", 5}}).dump());
  EXPECT_EQ(errorOf(wrapper).rfind((dir / "model.gltf").string() + ": ", 0), 0u)
      << errorOf(wrapper);
  // From the command line: exit status 2, the one line.
  const auto bad = dir.write("bad.json", json({{"gltf", "none.glb"}}).dump());
  const test::PtResult r = test::runPt("render " + bad.string() + " --backend cpu");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, bad.string() + ": gltf: no such file: " + (dir / "none.glb").string() + "\n");
}

}  // namespace
}  // namespace pt
