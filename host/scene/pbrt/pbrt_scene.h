// pbrt-v4 scene files: the reader's entry points. The parser (pbrt_parser.h) reads the
// statements and the builder (pbrt_builder.h) applies them to pbrt's graphics state, giving the
// same Scene as the JSON reader: camera, integrator settings, materials and a flat triangle
// list. What is supported, what warns and how pbrt-v4 and this renderer differ:
// docs/pbrt-format.md.
#pragma once

#include <filesystem>
#include <string>

#include "scene/scene.h"

namespace pt {

// Reads a pbrt-v4 scene file and the files it includes. Throws InputError
// "file:line:column: message" for anything malformed; what it reads but does not simulate
// becomes one warning per kind in Scene::warnings ("file:line: message"), or with
// options.strict the InputError "file:line:column: message".
Scene loadPbrtScene(const std::filesystem::path& path, const SceneLoadOptions& options = {});

// The same for `text` given as the content of the file `path` (which need not exist;
// relative paths in it resolve against its directory).
Scene loadPbrtSceneText(std::string text, const std::filesystem::path& path,
                        const SceneLoadOptions& options = {});

}  // namespace pt
