// The entry points the fuzz targets (fuzz/*_fuzzer.cpp) and the regression replay
// (tests/fuzz_regression_test.cpp) share: one per reader of outside data.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pt::fuzz {

// What an input did: accepted, or refused with an InputError (the only allowed failure).
// Any other exception propagates, and a crash is a crash: both are bugs.
enum class Outcome { kAccepted, kInputError };

Outcome fuzzScene(const std::uint8_t* data, std::size_t size);  // JSON beside fixed meshes
Outcome fuzzObj(const std::uint8_t* data, std::size_t size);    // loadObjMesh, its normals checked
Outcome fuzzMtl(const std::uint8_t* data, std::size_t size);    // loadMtlMaterials
Outcome fuzzPly(const std::uint8_t* data, std::size_t size);    // loadPlyMesh, its normals checked
Outcome fuzzImage(const std::uint8_t* data, std::size_t size);  // readImage: EXR, PFM, PNG
Outcome fuzzPbrt(const std::uint8_t* data, std::size_t size);   // a .pbrt scene beside fixed meshes
Outcome fuzzGltf(const std::uint8_t* data, std::size_t size);   // a .gltf or .glb scene
Outcome fuzzNanoVdb(const std::uint8_t* data, std::size_t size);  // readNanoVdbMedium, packed
// readFilmState: the input is a film state file less its checksum (appended by the entry).
Outcome fuzzFilmState(const std::uint8_t* data, std::size_t size);
// readTextureImage: the first byte picks the extension (textureExtension), the rest is the file.
Outcome fuzzTexture(const std::uint8_t* data, std::size_t size);
const char* textureExtension(std::uint8_t selector);  // ".png", ".jpg", ... by selector % 7

struct Target {
  const char* name;  // the directory name under fuzz/corpus/ and tests/data/fuzz-regressions/
  Outcome (*run)(const std::uint8_t*, std::size_t);
};
const std::vector<Target>& targets();

}  // namespace pt::fuzz
