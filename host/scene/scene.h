// The scene as the readers give it: camera, materials and a flat triangle list in load order.
// Includes no reader (scene/load_scene.h reads one) and knows nothing of BVHs or Vulkan.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/named_values.h"
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
// Stochastic progressive photon mapping's own parameters (pbrt-v4's SPPMIntegrator, docs/sppm.md).
// pbrt-v4's defaults: maxdepth 5 (where the scene gives none) and the largest photon count one
// iteration traces (photons are numbered by 32-bit integers).
inline constexpr int kSppmDefaultMaxDepth = 5;
inline constexpr int64_t kSppmMaxPhotonsPerIteration = 0xFFFFFFFFll;

struct SppmSettings {
  float radius = 1.0f;               // the initial search radius, in scene units
  int64_t photonsPerIteration = -1;  // photons traced per iteration; -1: the image's pixel count
};

struct IntegratorSettings {
  uint integrator = kIntegratorPath;  // common/named_values.h's kIntegrator*
  int spp = 16;
  int maxDepth = 64;  // maximum number of scattering events on a path
  uint seed = 0;
  bool russianRoulette = true;
  int rrStartDepth = 3;  // Russian roulette from this many scattering events on
  uint strategy = kStrategyMis;
  uint sampler = kSamplerSobol;          // see docs/accuracy.md for what it buys
  uint lightSampler = kLightSamplerBvh;  // pbrt-v4's default
  SppmSettings sppm;                     // kIntegratorSppm
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
  // Participating media (shaders/medium.h), all empty in a scene without any: the media,
  // their names (parallel, for messages), the floats of their grids (Medium::density,
  // majorants and emission index into it; the majorant grids are prepareScene's), and per
  // triangle, parallel to `triangles`, the media on its two sides.
  std::vector<Medium> media;
  std::vector<std::string> mediumNames;
  std::vector<float> mediumGrids;
  std::vector<MediumInterface> mediumInterfaces;
  uint cameraMedium = kNoMedium;      // the medium the camera is in
  std::vector<std::string> warnings;  // e.g. dropped zero-area triangles, one line each
};

// How a scene file is read.
struct SceneLoadOptions {
  // pbrt-v4 files: what the reader would warn about, something it ignores or renders
  // otherwise than pbrt-v4, is an InputError instead ("file:line:column: ..."), so that an
  // image is pbrt-v4's scene or nothing (pt render --strict). JSON scenes have no such warnings.
  bool strict = false;
  // glTF files: the camera to render from, an index into the file's "cameras" or a camera's
  // name (pt render --camera); empty: the first camera a node of the scene places.
  std::string camera;
  // glTF files: an environment image (.exr, .pfm, .png or .hdr; latitude-longitude, +y up) that
  // lights the model instead of the white sky a file without lights gets (pt render --env).
  std::string environment;
};

// pbrt-v4's texture coordinates for the triangles of a mesh without any: (0,0), (1,0), (1,1).
inline TriangleUVs defaultTriangleUVs() {
  return TriangleUVs{vec2(0.0f, 0.0f), vec2(1.0f, 0.0f), vec2(1.0f, 1.0f), vec2(0.0f)};
}

}  // namespace pt
