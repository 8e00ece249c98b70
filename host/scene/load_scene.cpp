// The format dispatch (load_scene.h): pbrt-v4 and glTF files by their extension, JSON otherwise.
#include "scene/load_scene.h"

#include "scene/gltf/gltf_scene.h"
#include "scene/json_scene.h"
#include "scene/pbrt/pbrt_scene.h"

namespace pt {

Scene loadScene(const std::filesystem::path& path, const SceneLoadOptions& options) {
  if (path.extension() == ".pbrt") return loadPbrtScene(path, options);  // docs/pbrt-format.md
  if (path.extension() == ".gltf" || path.extension() == ".glb") {
    return loadGltfScene(path, options);  // docs/gltf.md
  }
  return loadJsonScene(path, options);  // a JSON scene, or a glTF wrapper (docs/gltf.md)
}

}  // namespace pt
