// readDocument (gltf_document.h): tinygltf's loaders behind the reader's error messages.
#include "scene/gltf/gltf_document.h"

#include <cstring>
#include <exception>
#include <string>

#include "scene/json_reader.h"

namespace pt::gltf {

namespace {

// Images stay undecoded: the bytes of a file or data URI are kept as they are (as_is), for the
// texture reader (gltf_textures.h) to decode. Those of a buffer view are not copied: tinygltf
// hands them over unchecked against the buffer, and the texture reader reads them itself.
bool keepImageBytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                    const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && bytes != nullptr && size > 0) {
    image->image.assign(bytes, bytes + size);
    image->as_is = true;
  }
  return true;
}

// tinygltf's messages, one per line, as one line.
std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (std::size_t i = text.find('\n'); i != std::string::npos; i = text.find('\n', i)) {
    text.replace(i, 1, "; ");
  }
  return text;
}

}  // namespace

tinygltf::Model parseDocument(const std::string& bytes, const std::filesystem::path& path) {
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keepImageBytes, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const std::string baseDir = path.parent_path().string();
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  bool ok = false;
  try {
    if (binary) {
      ok = loader.LoadBinaryFromMemory(&model, &err, &warn,
                                       reinterpret_cast<const unsigned char*>(bytes.data()),
                                       static_cast<unsigned int>(bytes.size()), baseDir);
    } else {
      ok = loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                      static_cast<unsigned int>(bytes.size()), baseDir);
    }
  } catch (const std::exception& e) {
    ok = false;
    err = e.what();
  }
  if (!ok) {
    if (err.empty()) err = "not a glTF 2.0 file";
    scene_detail::throwInputError(path.string(), "", oneLine(err));
  }
  return model;
}

tinygltf::Model readDocument(const std::filesystem::path& path) {
  std::string bytes, why;
  if (!scene_detail::readTextFile(path, &bytes, &why)) {
    scene_detail::throwInputError(path.string(), "", "cannot open scene file (" + why + ")");
  }
  if (bytes.size() > 0xFFFFFFFFull) {
    scene_detail::throwInputError(path.string(), "", "larger than 4 GiB, glTF's limit");
  }
  return parseDocument(bytes, path);
}

}  // namespace pt::gltf
