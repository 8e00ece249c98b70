// The scene as loaded from JSON: camera, materials and a flat triangle list in load order.
// Knows nothing of BVHs or Vulkan; the BVH builder reorders the triangles later.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/shared.h"
#include "image/image.h"

namespace pt {

// A pixel filter as pbrt-v4 describes it (its filters.h): the type (kFilter*), the radius on
// each axis in pixels, and gaussian's sigma or mitchell's B and C. The default is the box of
// one pixel, the renderer's filter before others were added (pbrt-v4's files default to
// gaussian: its reader says so).
struct PixelFilterDesc {
  uint type = kFilterBox;
  float radiusX = 0.5f;
  float radiusY = 0.5f;
  float sigma = 0.5f;     // gaussian
  float b = 1.0f / 3.0f;  // mitchell
  float c = 1.0f / 3.0f;
};

// The camera as the user describes it; makeCamera turns it into the GPU struct.
struct CameraDesc {
  vec3 position{0.0f, 0.0f, 0.0f};
  vec3 target{0.0f, 0.0f, 1.0f};
  vec3 up{0.0f, 1.0f, 0.0f};
  float vfovDegrees = 45.0f;
  int width = 256;  // the whole film, which a crop window cuts the image from
  int height = 256;
  PixelFilterDesc filter;
  // Thin lens (pbrt-v4's lensradius, focaldistance): 0 is a pinhole.
  float lensRadius = 0.0f;
  float focalDistance = 1e6f;  // pbrt-v4's default
  // The screen window [x0, x1, y0, y1] on the plane at unit distance along the view direction,
  // in units of tan(vfov / 2); unset: [-width/height, width/height, -1, 1], the field of view.
  std::optional<std::array<float, 4>> screenWindow;
  // The part of the film rendered (pbrt-v4's Film "cropwindow" and "pixelbounds"): fractions
  // [x0, x1, y0, y1] of the film, or pixels [x0, x1) x [y0, y1); the window wins when both are
  // set. Unset: the whole film.
  std::optional<std::array<float, 4>> cropWindow;
  std::optional<std::array<int, 4>> pixelBounds;
};

// Integrator settings from the scene's "integrator" object (command-line flags override).
struct IntegratorSettings {
  int spp = 16;
  int maxDepth = 64;  // maximum number of scattering events on a path
  uint seed = 0;
  bool russianRoulette = true;
  int rrStartDepth = 3;  // Russian roulette from this many scattering events on
  uint strategy = kStrategyMis;
  uint sampler = kSamplerSobol;  // see docs/accuracy.md for what it buys
};

// An infinite light whose radiance is an image over the directions (shaders/environment.h):
// pbrt-v4's "infinite" light with a "filename", or a JSON "environment" light with one.
struct EnvironmentImage {
  std::string file;  // the image file (its path resolved), for messages
  // Radiance (its scale applied, negative values clamped to 0), row 0 at the top. Octahedral
  // images are square.
  Image image;
  uint mapping = kEnvironmentOctahedral;  // kEnvironmentOctahedral or kEnvironmentLatLong
  // The image frame's axes in world space (the columns of the light-to-world rotation; a
  // mirror is allowed): unit and orthogonal.
  std::array<vec3, 3> toWorld{vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f),
                              vec3(0.0f, 0.0f, 1.0f)};
};

struct Scene {
  CameraDesc camera;
  IntegratorSettings integrator;
  std::vector<Material> materials;
  std::vector<std::string> materialNames;  // parallel to materials
  // Triangles in load order; Triangle::primitive is the index in this vector and
  // Triangle::emitter is kNoEmitter until buildEmitters assigns it.
  std::vector<Triangle> triangles;
  // Vertex normals per triangle, parallel to `triangles`, or empty when no mesh has normals
  // (triangles of meshes without them then repeat their geometric normal).
  std::vector<TriangleNormals> normals;
  // Texture coordinates per triangle, parallel to `triangles`, or empty when no mesh has any
  // (once some mesh has them, triangles of meshes without take pbrt-v4's (0,0), (1,0), (1,1)).
  std::vector<TriangleUVs> uvs;
  // The textures (shaders/texture.h): their programs' nodes, the image buffer they read, and
  // per material the textures of its parameters, parallel to `materials` (empty when no
  // material has a texture). host/scene/textures.h builds them.
  std::vector<TextureNode> textureNodes;
  std::vector<uint32_t> imageWords;
  std::vector<MaterialTextures> materialTextures;
  // Lights that are not triangles (point, spot, distant, infinite), in world space.
  std::vector<Light> lights;
  // At most one image environment (not in `lights`: prepareScene adds its Light); constant
  // infinite lights in `lights` add to its radiance.
  std::optional<EnvironmentImage> environment;
  std::vector<std::string> warnings;  // e.g. dropped zero-area triangles, one line each
};

// How a scene file is read.
struct SceneLoadOptions {
  // pbrt-v4 files: what the reader would warn about, something it ignores or renders
  // otherwise than pbrt-v4, is an InputError instead ("file:line:column: ..."), so that an
  // image is pbrt-v4's scene or nothing (pt render --strict). JSON scenes have no such warnings.
  bool strict = false;
};

// Reads a scene file. Throws InputError with "<file>: <field or line>: <message>" for
// anything malformed (see docs/scene-format.md). Mesh paths are relative to the JSON file.
Scene loadScene(const std::filesystem::path& path, const SceneLoadOptions& options = {});

// pbrt-v4's texture coordinates for the triangles of a mesh without any: (0,0), (1,0), (1,1).
inline TriangleUVs defaultTriangleUVs() {
  return TriangleUVs{vec2(0.0f, 0.0f), vec2(1.0f, 0.0f), vec2(1.0f, 1.0f), vec2(0.0f)};
}

// A material of type `type` (kMaterial*) with the defaults of docs/scene-format.md (pbrt-v4's,
// for the types taken from pbrt-v4) and no emission. The JSON reader and the MTL mapping both
// start from it, so that a default is written in one place.
Material defaultMaterial(uint type);

// Makes `material` pbrt-v4's conductor of the given reflectance colour (its
// ConductorMaterial::GetBxDF): eta = 1 and k = 2 sqrt(r) / sqrt(1 - r) per channel, with r
// clamped to [0, 0.9999] so that white stays finite.
void setConductorReflectance(Material& material, vec3 reflectance);

// pbrt-v4's "roughness", "uroughness" and "vroughness" as a material stores them: Trowbridge-
// Reitz alphas, mapped by RoughnessToAlpha (alpha = sqrt(roughness)) when `remap` (pbrt-v4's
// "remaproughness", true by default). The JSON and pbrt readers both call it.
void setRoughness(Material& material, float uRoughness, float vRoughness, bool remap);

// diffusetransmission's "scale" as pbrt-v4 applies it: both colours scaled and the products
// clamped to [0, 1].
void scaleDiffuseTransmission(Material& material, float scale);

// The most random-walk steps or walks a coated material may ask for per evaluation: far more
// than pbrt-v4's defaults (10 and 1) need, and small enough that one evaluation stays short.
inline constexpr std::int64_t kMaxCoatedWalk = 1000;

// cos and sin of an angle in degrees, exact for multiples of 90 degrees so that axis-aligned
// geometry stays exactly axis-aligned (cos(radians(90)) is 6e-17, not 0). Both scene readers
// rotate with it.
std::pair<double, double> cosSinDegrees(double degrees);

// How appendTriangle ended.
enum class Appended { kAdded, kZeroArea, kTooMany };

// Appends triangle `t` (its vertices and material set; emitter and primitive are filled here)
// to scene.triangles, as both scene readers do: not if it has zero area (the edges at v0
// parallel to within double rounding, i.e. the sine of the angle between them at most 1e-12:
// scale-invariant, computed in double on the float vertices the renderer will see, so thin
// but real slivers are kept; coincident vertices too), nor beyond kNoEmitter - 1 triangles.
// `normals`: the vertex normals in world space (any length), or null where the mesh has none;
// each is made unit, the geometric normal standing in for one that is zero or not finite.
// Once some triangle has normals, every triangle has an entry in scene.normals (its geometric
// normal at all three vertices where its mesh has none).
// `uvs`: the vertices' texture coordinates, or null where the mesh has none (scene.uvs then
// gets pbrt-v4's defaults for it once some triangle has coordinates).
Appended appendTriangle(Scene& scene, Triangle t, const std::array<glm::dvec3, 3>* normals,
                        const std::array<glm::vec2, 3>* uvs = nullptr);

// Makes room for `size` elements, at least doubling the capacity when it grows, so that
// appending shape after shape costs amortized linear time (std::vector::reserve would allocate
// exactly `size`, and the next shape would copy everything again).
template <typename T>
void reserveGeometric(std::vector<T>& v, std::size_t size) {
  if (size > v.capacity()) v.reserve(std::max(size, 2 * v.capacity()));
}

// Builds the GPU camera for a film of width x height pixels: the image is the crop of it (the
// whole film without a crop window). Throws InputError when the crop selects no pixel of that
// film (the readers check the file's own film; --width and --height can make another).
Camera makeCamera(const CameraDesc& desc, int width, int height);

// The pixels a crop window or pixel bounds select of a width x height film, as pbrt-v4's film
// computes them: [x0, x1) x [y0, y1], in {x0, x1, y0, y1}; the whole film without either.
std::array<int, 4> cropPixels(const CameraDesc& desc, int width, int height);

// pbrt-v4's filter of type `type` (kFilter*) with its defaults: radius 0.5 for box, 2 for
// triangle, 1.5 and sigma 0.5 for gaussian, 2 and B = C = 1/3 for mitchell.
PixelFilterDesc defaultFilter(uint type);

// The constants of a filter that makeCamera puts in the Camera (filter.h reads them):
// filterWeight, filterScale, filterB, filterC, filterRootsNear/Far, filterExpX/Y. Throws
// InputError (naming `where`) for parameters no sampler can follow. Exposed for tests.
void setFilterConstants(Camera& camera, const PixelFilterDesc& filter, const std::string& where);

}  // namespace pt
