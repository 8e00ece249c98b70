// The format dispatch (load_scene.h): pbrt-v4 files by their extension, JSON otherwise.
#include "scene/load_scene.h"

#include "scene/json_scene.h"
#include "scene/pbrt/pbrt_scene.h"

namespace pt {

Scene loadScene(const std::filesystem::path& path, const SceneLoadOptions& options) {
  if (path.extension() == ".pbrt") return loadPbrtScene(path, options);  // docs/pbrt-format.md
  return loadJsonScene(path);
}

}  // namespace pt
