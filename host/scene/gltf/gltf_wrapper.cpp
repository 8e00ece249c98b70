// loadGltfWrapper (gltf_wrapper.h).
#include "scene/gltf/gltf_wrapper.h"

#include <algorithm>
#include <optional>
#include <string>
#include <system_error>

#include "scene/gltf/gltf_scene.h"
#include "scene/json_sections.h"

namespace pt::scene_detail {

Scene loadGltfWrapper(const JsonNode& root, const std::filesystem::path& path,
                      const SceneLoadOptions& options) {
  root.checkKeys({"description", "gltf", "camera", "integrator", "environment"});
  if (auto n = root.find("description")) n->string();
  const JsonNode gltfNode = root.require("gltf");
  const std::filesystem::path gltfPath = path.parent_path() / gltfNode.string();
  const std::string extension = gltfPath.extension().string();
  if (extension != ".gltf" && extension != ".glb") {
    gltfNode.fail("expected a .gltf or .glb file, got " + gltfNode.describe());
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(gltfPath, error)) {
    gltfNode.fail("no such file: " + gltfPath.string());
  }
  SceneLoadOptions gltfOptions = options;
  std::optional<JsonNode> cameraObject;
  if (auto n = root.find("camera")) {
    if (n->json().is_object()) {
      if (n->find("medium")) n->require("medium").fail("a glTF scene has no media");
      cameraObject = n;
    } else if (n->json().is_string()) {
      if (options.camera.empty()) gltfOptions.camera = n->string();
    } else if (n->json().is_number()) {
      if (options.camera.empty()) gltfOptions.camera = std::to_string(n->integer(0, 1 << 30));
    } else {
      n->fail("expected a camera of the glTF file (its index or name) or a camera object, got " +
              n->describe());
    }
  }
  const std::optional<JsonNode> environment = root.find("environment");
  Scene scene = loadGltfScene(gltfPath, gltfOptions);
  if (cameraObject) scene.camera = readJsonCamera(*cameraObject, scene.camera);
  if (auto n = root.find("integrator")) scene.integrator = readJsonIntegrator(*n);
  if (environment && options.environment.empty()) {
    // The wrapper's environment replaces the white sky the reader lights a file without
    // lights of its own by (the only infinite light it makes).
    std::erase_if(scene.lights, [](const Light& l) { return l.type == kLightInfinite; });
    readJsonEnvironment(*environment, path, scene);
  }
  return scene;
}

}  // namespace pt::scene_detail
