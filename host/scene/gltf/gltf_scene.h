// glTF 2.0 scenes (.gltf, .glb): the reader's entry points. What is read, what is warned and
// how the materials map onto the renderer's: docs/gltf.md.
#pragma once

#include <filesystem>
#include <string>

#include "scene/scene.h"

namespace pt {

// Reads a glTF 2.0 file and the buffers it references. Throws InputError "<file>: <JSON path>:
// <problem>" for anything malformed; what it reads but does not simulate becomes one warning
// per kind in Scene::warnings, or with options.strict that InputError.
Scene loadGltfScene(const std::filesystem::path& path, const SceneLoadOptions& options = {});

// The same for `bytes` given as the content of the file `path` (which need not exist; external
// buffers resolve against its directory).
Scene loadGltfSceneBytes(const std::string& bytes, const std::filesystem::path& path,
                         const SceneLoadOptions& options = {});

}  // namespace pt
