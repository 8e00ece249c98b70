// The JSON scene format (docs/scene-format.md): its reader, which validates everything and
// names the field of any error. Choosing the reader by file name is scene/load_scene.h's.
#pragma once

#include <filesystem>

#include "scene/scene.h"

namespace pt {

// Reads a JSON scene file into a Scene with a flat triangle list. Throws InputError with
// "<file>: <field>: <message>" for anything malformed. Mesh paths are relative to the file.
// A file with a "gltf" key is a glTF wrapper (docs/gltf.md); options are for those
// (--camera and --env are refused for other JSON scenes).
Scene loadJsonScene(const std::filesystem::path& path,
                    const SceneLoadOptions& options = SceneLoadOptions());

}  // namespace pt
