// Fuzz entry points: each feeds the bytes to one reader exactly as `pt` would and turns an
// InputError into Outcome::kInputError. Readers that take a path get the bytes through a file
// in a directory of this process's own.
#include "fuzz/fuzz_entry.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include "common/check.h"
#include "image/film_state.h"
#include "image/image.h"
#include "image/texture_image.h"
#include "scene/load_scene.h"
#include "scene/media.h"
#include "scene/mtl_materials.h"
#include "scene/obj_mesh.h"
#include "scene/ply_mesh.h"
#include "scene/scene.h"

namespace pt::fuzz {
namespace {

namespace fs = std::filesystem;

// Small meshes a fuzzed scene can reference by name ("mesh.obj", "mesh.ply", with "mesh.mtl"
// for the OBJ's mtllib): fixed, so that the scene fuzzer explores the JSON, not the meshes.
constexpr const char* kObj =
    "mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl lamp\n"
    "f 1 3 4\n";
constexpr const char* kMtl = "newmtl red\nKd 0.8 0.1 0.1\nnewmtl lamp\nKd 0 0 0\nKe 4 4 4\n";
constexpr const char* kPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

void writeFile(const fs::path& path, const void* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), std::streamsize(size));
  PT_CHECK(out.good(), "fuzz: cannot write " + path.string());
}

// /tmp/pt-fuzz-<pid>, made once with the fixed meshes in it and removed at exit.
const fs::path& workDir() {
  struct Dir {
    fs::path path = fs::temp_directory_path() / ("pt-fuzz-" + std::to_string(::getpid()));
    Dir() {
      fs::create_directories(path);
      writeFile(path / "mesh.obj", kObj, std::char_traits<char>::length(kObj));
      writeFile(path / "mesh.mtl", kMtl, std::char_traits<char>::length(kMtl));
      writeFile(path / "mesh.ply", kPly, std::char_traits<char>::length(kPly));
    }
    ~Dir() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  return dir.path;
}

template <typename F>
Outcome guarded(F&& f) {
  try {
    f();
    return Outcome::kAccepted;
  } catch (const InputError&) {
    return Outcome::kInputError;
  }
}

std::string text(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// What the mesh readers promise of an accepted file's normals: none, or one finite triple
// per triangle. A broken promise is a finding (PT_CHECK exits, which libFuzzer reports).
template <typename Mesh>
void checkNormals(const Mesh& mesh) {
  PT_CHECK(mesh.normals.empty() || mesh.normals.size() == mesh.triangles.size(),
           "mesh normals not parallel to its triangles");
  for (const auto& triple : mesh.normals) {
    for (const auto& n : triple) {
      PT_CHECK(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z),
               "non-finite mesh normal accepted");
    }
  }
  // Texture coordinates likewise: none, or one finite triple per triangle.
  PT_CHECK(mesh.uvs.empty() || mesh.uvs.size() == mesh.triangles.size(),
           "mesh texture coordinates not parallel to its triangles");
  for (const auto& triple : mesh.uvs) {
    for (const auto& uv : triple) {
      PT_CHECK(std::isfinite(uv.x) && std::isfinite(uv.y),
               "non-finite texture coordinate accepted");
    }
  }
}

// What the readers promise of an accepted scene's triangles: finite vertices, materials in
// range, unit finite normals and finite texture coordinates parallel to them (or none).
void checkTriangles(const Scene& scene) {
  const auto finite = [](vec3 v) { return std::isfinite(v.x + v.y + v.z); };
  PT_CHECK(scene.normals.empty() || scene.normals.size() == scene.triangles.size(),
           "scene normals not parallel to its triangles");
  PT_CHECK(scene.uvs.empty() || scene.uvs.size() == scene.triangles.size(),
           "scene texture coordinates not parallel to its triangles");
  for (const Triangle& t : scene.triangles) {
    PT_CHECK(finite(t.v0) && finite(t.v1) && finite(t.v2), "non-finite vertex accepted");
    PT_CHECK(t.material < scene.materials.size(), "material index out of range");
  }
  for (const TriangleNormals& n : scene.normals) {
    for (const vec3& v : {n.n0, n.n1, n.n2}) {
      PT_CHECK(finite(v) && std::abs(glm::length(v) - 1.0f) < 1e-3f, "bad normal accepted");
    }
  }
  for (const TriangleUVs& uv : scene.uvs) {
    PT_CHECK(std::isfinite(uv.uv0.x + uv.uv0.y + uv.uv1.x + uv.uv1.y + uv.uv2.x + uv.uv2.y),
             "non-finite texture coordinate accepted");
  }
}

// What the readers promise of an accepted scene's media (the renderer relies on them): no
// media fields without media, one interface per triangle with valid indices, grids inside the
// grid buffer, the majorants left to prepareScene, g in [-1, 1], finite non-negative values.
void checkMedia(const Scene& scene) {
  const std::size_t n = scene.media.size();
  PT_CHECK(scene.mediumNames.size() == n, "media: names not parallel");
  if (n == 0) {
    PT_CHECK(scene.mediumInterfaces.empty() && scene.mediumGrids.empty() &&
                 scene.cameraMedium == kNoMedium,
             "media: media fields without media");
    return;
  }
  PT_CHECK(scene.mediumInterfaces.size() == scene.triangles.size(),
           "media: interfaces not parallel to the triangles");
  const auto valid = [&](uint m) { return m == kNoMedium || m < n; };
  PT_CHECK(valid(scene.cameraMedium), "media: bad camera medium");
  for (const MediumInterface& mi : scene.mediumInterfaces) {
    PT_CHECK(valid(mi.inside) && valid(mi.outside), "media: bad interface index");
  }
  for (const Medium& m : scene.media) {
    PT_CHECK(m.type < kMediumTypeCount && m.g >= -1.0f && m.g <= 1.0f, "media: bad type or g");
    PT_CHECK(m.majorants == kNoGrid, "media: majorants set by a reader");
    // nanovdb and cloud media keep parameters in Le (shared_types.h), some of any sign.
    const bool LeIsRadiance = m.type != kMediumNanoVdb && m.type != kMediumCloud;
    for (const vec3& c : {m.sigmaA, m.sigmaS, LeIsRadiance ? m.Le : vec3(0.0f)}) {
      PT_CHECK(std::isfinite(c.x + c.y + c.z) && c.x >= 0 && c.y >= 0 && c.z >= 0,
               "media: bad coefficient");
    }
    PT_CHECK(std::isfinite(m.Le.x + m.Le.y + m.Le.z), "media: bad Le");
    const auto inside = [&](uint offset, std::size_t count) {
      return offset == kNoGrid ? count == 0
                               : std::size_t(offset) + count <= scene.mediumGrids.size();
    };
    PT_CHECK(inside(m.density, densityFloats(m, scene.mediumGrids)) &&
                 inside(m.emission, emissionFloats(m, scene.mediumGrids)),
             "media: grid outside the grid buffer");
    PT_CHECK(m.type == kMediumHomogeneous || m.density != kNoGrid, "media: grid without density");
    // Dense grids: values non-negative and finite (sparse grids hold integers as bits).
    if (m.type == kMediumUniformGrid || m.type == kMediumRgbGrid) {
      for (uint offset : {m.density, m.emission}) {
        if (offset == kNoGrid) continue;
        const std::size_t count = offset == m.density ? densityFloats(m, scene.mediumGrids)
                                                      : emissionFloats(m, scene.mediumGrids);
        for (std::size_t i = 0; i < count; ++i) {
          const float v = scene.mediumGrids[offset + i];
          PT_CHECK(std::isfinite(v) && v >= 0.0f, "media: bad grid value");
        }
      }
    }
  }
}

}  // namespace

Outcome fuzzScene(const std::uint8_t* data, std::size_t size) {
  const fs::path path = workDir() / "scene.json";
  writeFile(path, data, size);
  return guarded([&] { checkMedia(loadScene(path)); });
}

Outcome fuzzGltf(const std::uint8_t* data, std::size_t size) {
  const fs::path path = workDir() / "scene.gltf";  // a .glb too: the reader goes by its magic
  writeFile(path, data, size);
  return guarded([&] { checkTriangles(loadScene(path)); });
}

Outcome fuzzObj(const std::uint8_t* data, std::size_t size) {
  return guarded(
      [&] { checkNormals(scene_detail::loadObjMesh(text(data, size), "fuzz.obj", "")); });
}

Outcome fuzzMtl(const std::uint8_t* data, std::size_t size) {
  return guarded([&] { scene_detail::loadMtlMaterials(text(data, size), "fuzz.mtl"); });
}

Outcome fuzzPly(const std::uint8_t* data, std::size_t size) {
  return guarded(
      [&] { checkNormals(scene_detail::loadPlyMesh(text(data, size), "fuzz.ply", "")); });
}

// The format is chosen by the magic number, as a user's misnamed file would not be: each
// decoder then sees mostly inputs meant for it. Anything else goes to the PNG decoder.
Outcome fuzzImage(const std::uint8_t* data, std::size_t size) {
  const char* extension = ".png";
  if (size >= 2 && data[0] == 'P' && (data[1] == 'F' || data[1] == 'f')) extension = ".pfm";
  if (size >= 4 && data[0] == 0x76 && data[1] == 0x2f && data[2] == 0x31 && data[3] == 0x01) {
    extension = ".exr";
  }
  const fs::path path = workDir() / (std::string("image") + extension);
  writeFile(path, data, size);
  return guarded([&] { readImage(path); });
}

// A film state as `pt render --resume` and `pt merge` read it; an accepted one must keep the
// promises resume and merge rely on: one count a pixel, its samples those of its ranges (one
// for an sppm render, whose records are one a pixel), an open batch ending the ranges. The
// input is the file less its checksum, which is appended here: otherwise nearly every mutation
// would stop at the checksum, and the fuzzer would never reach the body's parser.
Outcome fuzzFilmState(const std::uint8_t* data, std::size_t size) {
  const fs::path path = workDir() / "film.ptstate";
  std::string bytes(reinterpret_cast<const char*>(data), size);
  const uint64_t checksum = hashBytes(data, size);
  for (int b = 0; b < 8; ++b) bytes.push_back(char(checksum >> (8 * b)));
  writeFile(path, bytes.data(), bytes.size());
  return guarded([&] {
    const FilmState state = readFilmState(path);
    const Film& film = state.film;
    const size_t pixels = film.pixelCount();
    PT_CHECK(film.width > 0 && film.height > 0 && film.sampleCount.size() == pixels &&
                 film.invalidCount.size() == pixels && film.exact.size() == pixels,
             "fuzz: an accepted film state's film is whole");
    PT_CHECK(state.sppm.empty() || (state.sppm.size() == pixels && state.open.empty()),
             "fuzz: an accepted sppm state has a record a pixel and no open batch");
    PT_CHECK(state.open.empty() || (state.open.sum.size() == pixels &&
                                    state.open.first + state.open.count == state.ranges.back().end),
             "fuzz: an accepted open batch ends the ranges");
    const uint64_t expected =
        !state.sppm.empty() ? 1u : uint64_t(state.samplesPerPixel()) - state.open.count;
    for (size_t i = 0; i < pixels; ++i) {
      PT_CHECK(film.sampleCount[i] + film.invalidCount[i] == expected,
               "fuzz: an accepted film state's pixels hold its ranges' samples");
    }
    state.combinedFilm().resolve();
  });
}

// A pbrt-v4 scene through loadScene, as `pt render scene.pbrt` reads it, with "mesh.ply" to
// include; an accepted scene must keep the Scene's promises (the renderer relies on them).
Outcome fuzzPbrt(const std::uint8_t* data, std::size_t size) {
  const fs::path path = workDir() / "scene.pbrt";
  writeFile(path, data, size);
  return guarded([&] {
    const Scene scene = loadScene(path);
    PT_CHECK(!scene.triangles.empty(), "pbrt: a scene without triangles accepted");
    PT_CHECK(scene.normals.empty() || scene.normals.size() == scene.triangles.size(),
             "pbrt: normals not parallel to the triangles");
    PT_CHECK(scene.materials.size() == scene.materialNames.size(), "pbrt: material names");
    for (std::size_t i = 0; i < scene.triangles.size(); ++i) {
      const Triangle& t = scene.triangles[i];
      PT_CHECK(t.material < scene.materials.size() && t.primitive == i,
               "pbrt: triangle with a bad material or primitive index");
      for (const vec3& v : {t.v0, t.v1, t.v2}) {
        PT_CHECK(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                 "pbrt: non-finite vertex accepted");
      }
    }
    for (const Material& m : scene.materials) {
      PT_CHECK(std::isfinite(m.emission.x + m.emission.y + m.emission.z) && m.emission.x >= 0 &&
                   m.emission.y >= 0 && m.emission.z >= 0,
               "pbrt: bad emission accepted");
    }
    checkMedia(scene);
    PT_CHECK(scene.camera.width >= 1 && scene.camera.height >= 1 &&
                 scene.camera.vfovDegrees > 0.0f && scene.camera.vfovDegrees < 180.0f,
             "pbrt: bad camera accepted");
  });
}

const char* textureExtension(std::uint8_t selector) {
  static constexpr const char* kExtensions[] = {".png", ".jpg", ".tga", ".bmp",
                                                ".hdr", ".exr", ".pfm"};
  return kExtensions[selector % std::size(kExtensions)];
}

// Every texture format, the decoder picked by the first byte as a file's extension picks it,
// so that inputs of one format also reach the others' decoders (as misnamed files would). An
// accepted image must keep TextureImage's promises.
Outcome fuzzTexture(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return Outcome::kInputError;
  const fs::path path = workDir() / (std::string("texture") + textureExtension(data[0]));
  writeFile(path, data + 1, size - 1);
  return guarded([&] {
    const TextureImage image = readTextureImage(path);
    PT_CHECK(image.width > 0 && image.height > 0 &&
                 int64_t(image.width) * image.height <= kMaxTextureTexels,
             "texture: bad size accepted");
    PT_CHECK(image.channels == 1 || image.channels == 3 || image.channels == 4,
             "texture: bad channel count");
    const std::size_t count =
        std::size_t(image.width) * std::size_t(image.height) * std::size_t(image.channels);
    PT_CHECK(image.eightBit() ? image.bytes.size() == count && image.floats.empty()
                              : image.floats.size() == count && image.bytes.empty(),
             "texture: texel count does not match the size");
    PT_CHECK(!image.floatsEncoded || !image.eightBit(), "texture: encoded bytes flagged");
  });
}

// A NanoVDB file as a nanovdb medium reads it; an accepted one must pack into a sparse grid
// whose brick map points inside it.
Outcome fuzzNanoVdb(const std::uint8_t* data, std::size_t size) {
  const fs::path path = workDir() / "grids.nvdb";
  writeFile(path, data, size);
  return guarded([&] {
    const NanoVdbMediumGrids grids = readNanoVdbMedium(path, "density", "temperature");
    for (const VoxelBricks* g :
         {&grids.density, grids.temperature ? &*grids.temperature : nullptr}) {
      if (g == nullptr) continue;
      const std::vector<float> packed = packVoxelGrid(*g);
      PT_CHECK(packedVoxelGridFloats(packed.data()) == packed.size(), "nvdb: packed size");
      for (uint32_t entry : g->map) {
        PT_CHECK((entry & kConstantBrick) ? (entry & ~kConstantBrick) < g->constants.size()
                                          : std::size_t(entry) * kBrickVoxels < g->values.size(),
                 "nvdb: a brick map entry outside the grid");
      }
    }
    PT_CHECK(grids.boundsMin.x < grids.boundsMax.x && grids.boundsMin.y < grids.boundsMax.y &&
                 grids.boundsMin.z < grids.boundsMax.z,
             "nvdb: empty bounds accepted");
  });
}

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {{"scene", fuzzScene},     {"obj", fuzzObj},
                                          {"mtl", fuzzMtl},         {"ply", fuzzPly},
                                          {"image", fuzzImage},     {"pbrt", fuzzPbrt},
                                          {"texture", fuzzTexture}, {"nvdb", fuzzNanoVdb},
                                          {"gltf", fuzzGltf},       {"state", fuzzFilmState}};
  return all;
}

}  // namespace pt::fuzz
