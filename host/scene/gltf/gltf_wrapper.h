// A glTF wrapper: a JSON file that names a glTF file and adds what glTF lacks or overrides
// what it says: the camera (one of the file's, or the JSON format's keys over it), the
// integrator's settings and an environment (docs/gltf.md, "A JSON wrapper").
#pragma once

#include <filesystem>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace pt::scene_detail {

// The wrapper whose parsed document is `root` (the file `path`): InputError
// "<wrapper>: <field>: <problem>" for its own fields; the glTF file's errors name that file.
// options: --strict applies to the glTF file; --camera and --env win over the wrapper's.
Scene loadGltfWrapper(const JsonNode& root, const std::filesystem::path& path,
                      const SceneLoadOptions& options);

}  // namespace pt::scene_detail
