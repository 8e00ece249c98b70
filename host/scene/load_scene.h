// Reads a scene file of any format: the reader chosen by the file's extension. The readers
// themselves are scene/json_scene.h and scene/pbrt/pbrt_scene.h.
#pragma once

#include <filesystem>

#include "scene/scene.h"

namespace pt {

// Reads a scene file. Throws InputError with "<file>: <field or line>: <message>" for
// anything malformed (see docs/scene-format.md). Mesh paths are relative to the JSON file.
Scene loadScene(const std::filesystem::path& path, const SceneLoadOptions& options = {});

}  // namespace pt
