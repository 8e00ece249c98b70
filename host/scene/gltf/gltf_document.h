// A glTF 2.0 file as tinygltf reads it: `.gltf` (JSON, its buffers external files or data URIs)
// or `.glb` (binary chunks), told apart by the GLB magic rather than the extension.
#pragma once

#include <filesystem>

#include "scene/gltf/tinygltf.h"

namespace pt::gltf {

// Reads and parses `path` and every buffer it references. Throws InputError "<file>: <what
// tinygltf found>" for a file it cannot parse. Images are left undecoded: an image file's or
// data URI's bytes as they are in Image::image (as_is), a buffer view's where they are.
tinygltf::Model readDocument(const std::filesystem::path& path);

// The same for `bytes` given as the content of `path` (which need not exist; external buffers
// resolve against its directory).
tinygltf::Model parseDocument(const std::string& bytes, const std::filesystem::path& path);

}  // namespace pt::gltf
