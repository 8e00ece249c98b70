// pbrt-v4's graphics state over the parser's statements (its scene.cpp is the definition),
// building a Scene: transforms, named and inline materials, area lights, object instances
// (flattened), the camera, film, sampler and integrator. Everything read but not simulated is
// a warning, once per kind; everything malformed an InputError naming file:line:column.
#include "scene/pbrt/pbrt_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "common/check.h"
#include "environment.h"
#include "image/image.h"
#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_parser.h"
#include "scene/pbrt/spectra.h"
#include "scene/ply_mesh.h"
#include "scene/textures.h"

namespace pt {

namespace fs = std::filesystem;

namespace pbrt {

glm::dmat4 translateMatrix(glm::dvec3 delta) {
  glm::dmat4 m(1.0);
  m[3] = glm::dvec4(delta, 1.0);
  return m;
}

glm::dmat4 scaleMatrix(glm::dvec3 factors) {
  glm::dmat4 m(1.0);
  m[0][0] = factors.x;
  m[1][1] = factors.y;
  m[2][2] = factors.z;
  return m;
}

glm::dmat4 rotateMatrix(double degrees, glm::dvec3 axis) {
  const glm::dvec3 a = glm::normalize(axis);
  const auto [c, s] = cosSinDegrees(degrees);
  // Rodrigues' formula as a matrix; glm indexes [column][row].
  glm::dmat4 m(1.0);
  m[0][0] = a.x * a.x + (1 - a.x * a.x) * c;
  m[1][0] = a.x * a.y * (1 - c) - a.z * s;
  m[2][0] = a.x * a.z * (1 - c) + a.y * s;
  m[0][1] = a.x * a.y * (1 - c) + a.z * s;
  m[1][1] = a.y * a.y + (1 - a.y * a.y) * c;
  m[2][1] = a.y * a.z * (1 - c) - a.x * s;
  m[0][2] = a.x * a.z * (1 - c) - a.y * s;
  m[1][2] = a.y * a.z * (1 - c) + a.x * s;
  m[2][2] = a.z * a.z + (1 - a.z * a.z) * c;
  return m;
}

namespace {

// World from camera for LookAt: the camera's axes and position as columns.
glm::dmat4 lookAtInverse(glm::dvec3 eye, glm::dvec3 look, glm::dvec3 up) {
  const glm::dvec3 dir = glm::normalize(look - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(glm::normalize(up), dir));
  const glm::dvec3 newUp = glm::cross(dir, right);
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(right, 0.0);
  m[1] = glm::dvec4(newUp, 0.0);
  m[2] = glm::dvec4(dir, 0.0);
  m[3] = glm::dvec4(eye, 1.0);
  return m;
}

// The inverse of an orthonormal-basis-plus-translation matrix, exactly as pbrt's inversion
// of it would give up to rounding: the transposed rotation and the rotated translation.
glm::dmat4 rigidInverse(const glm::dmat4& m) {
  const glm::dmat3 rt = glm::transpose(glm::dmat3(m));
  glm::dmat4 inverse(rt);
  inverse[3] = glm::dvec4(-(rt * glm::dvec3(m[3])), 1.0);
  return inverse;
}

}  // namespace

glm::dmat4 lookAtMatrix(glm::dvec3 eye, glm::dvec3 look, glm::dvec3 up) {
  return rigidInverse(lookAtInverse(eye, look, up));
}

glm::dmat4 fileMatrix(const double* numbers) {
  return glm::make_mat4(numbers);
}

}  // namespace pbrt

namespace {

using namespace pbrt;
using scene_detail::quotedPath;
using scene_detail::singleQuoted;
using Tri = std::array<glm::dvec3, 3>;

constexpr int kMaxResolution = 16384;  // as the JSON reader: keeps width * height inside int
constexpr int kMaxMixDepth = 16;       // mix materials naming mix materials, at most this deep

// pbrt-v4's defaults where they differ from the JSON reader's (its scene.cpp, film.cpp,
// integrators.cpp, materials.cpp).
constexpr int kDefaultWidth = 1280;
constexpr int kDefaultHeight = 720;
constexpr int kDefaultMaxDepth = 5;
constexpr double kDefaultFov = 90.0;
constexpr float kDefaultDiffuseReflectance = 0.5f;

// ---- named spectra ------------------------------------------------------------------------

// How a spectrum parameter is used: pbrt-v4's SpectrumType. Spectra become RGB accordingly
// (host/scene/pbrt/spectra.h): a reflectance as its colour under D65, a light's emission
// normalized to luminance 1, an index as its per-channel average.
enum class Use { kAlbedo, kUnbounded, kIlluminant };

// A single index of refraction from an RGB one: the value itself when the channels agree
// (a "float eta"), so that it is not rounded by the mean.
float meanIndex(vec3 eta) {
  if (eta.x == eta.y && eta.y == eta.z) return eta.x;
  return (eta.x + eta.y + eta.z) / 3.0f;
}

// ---- transforms ---------------------------------------------------------------------------

// A matrix with its inverse, kept side by side as pbrt's Transform keeps them, so that the
// camera's position comes out exactly (no inversion of a product).
struct Xform {
  glm::dmat4 m{1.0};
  glm::dmat4 inverse{1.0};
};

Xform operator*(const Xform& a, const Xform& b) {
  return {a.m * b.m, b.inverse * a.inverse};
}

glm::dvec3 transformPoint(const glm::dmat4& m, glm::dvec3 p) {
  const glm::dvec4 h = m * glm::dvec4(p, 1.0);
  return h.w == 1.0 ? glm::dvec3(h) : glm::dvec3(h) / h.w;
}

// ---- meshes -------------------------------------------------------------------------------

// Triangles with, optionally, the vertex normals of each (parallel to `triangles`). Once
// oriented (orient below), a triangle's front side is the side of its winding's normal
// (v1 - v0) x (v2 - v0), or, where it has vertex normals, the side they point to.
using UVs = std::array<glm::vec2, 3>;

struct Mesh {
  std::vector<Tri> triangles;
  std::vector<Tri> normals;
  std::vector<UVs> uvs;  // per triangle, or empty: the mesh has none
};

// ReverseOrientation in object space, as pbrt-v4 does it: the front becomes the back, which
// here means the other winding (and negated vertex normals).
void reverseMesh(Mesh& mesh) {
  for (Tri& t : mesh.triangles) std::swap(t[1], t[2]);
  for (UVs& uv : mesh.uvs) std::swap(uv[1], uv[2]);
  for (Tri& n : mesh.normals) {
    std::swap(n[1], n[2]);
    for (glm::dvec3& v : n) v = -v;
  }
}

// `mesh` under the matrix `m`: points transformed, normals by the inverse transpose. A
// matrix that swaps handedness reverses the winding of the transformed points, so each
// triangle is rewound to keep its front (pbrt-v4 flips its normal instead, by
// transformSwapsHandedness). A triangle with vertex normals is wound to face where they
// point, as pbrt-v4 faces its geometric normal towards the interpolated one.
Mesh transformMesh(const Mesh& mesh, const glm::dmat4& m) {
  const glm::dmat3 linear(m);
  const double det = glm::determinant(linear);
  const bool swap = det < 0.0;
  const bool invertible = det != 0.0 && std::isfinite(det);
  const glm::dmat3 normalMatrix =
      invertible ? glm::transpose(glm::inverse(linear)) : glm::dmat3(0.0);
  Mesh out;
  out.triangles.reserve(mesh.triangles.size());
  out.normals.reserve(mesh.normals.size());
  out.uvs.reserve(mesh.uvs.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    Tri t = mesh.triangles[i];
    UVs uv = mesh.uvs.empty() ? UVs{} : mesh.uvs[i];
    for (glm::dvec3& p : t) p = transformPoint(m, p);
    if (swap) {
      std::swap(t[1], t[2]);
      std::swap(uv[1], uv[2]);
    }
    if (!mesh.normals.empty()) {
      Tri n = mesh.normals[i];
      for (glm::dvec3& v : n) v = normalMatrix * v;  // zero where singular: see emit
      if (swap) std::swap(n[1], n[2]);
      glm::dvec3 sum(0.0);
      for (const glm::dvec3& v : n) {
        const double len = glm::length(v);
        if (len > 0.0 && std::isfinite(len)) sum += v / len;
      }
      if (glm::dot(glm::cross(t[1] - t[0], t[2] - t[0]), sum) < 0.0) {
        std::swap(t[1], t[2]);
        std::swap(n[1], n[2]);
        std::swap(uv[1], uv[2]);
      }
      out.normals.push_back(n);
    }
    out.triangles.push_back(t);
    if (!mesh.uvs.empty()) out.uvs.push_back(uv);
  }
  return out;
}

// ---- parameters ---------------------------------------------------------------------------

class Builder;

// A directive's parameter list with the graphics state's Attribute parameters of the same
// kind behind it (pbrt-v4 looks in the directive's own first). Each read checks the type and
// the count of values and marks the parameter used; the rest are reported as ignored.
class Params {
 public:
  Params(Builder& builder, const Statement& s, const std::vector<Param>* attributes,
         std::string context)
      : builder_(builder), own_(s.params), attributes_(attributes), context_(std::move(context)) {}

  const std::string& context() const { return context_; }

  // The parameter `name` (the last one given, as in pbrt-v4), marked used; or null.
  const Param* find(std::string_view name) const {
    for (auto it = own_.rbegin(); it != own_.rend(); ++it) {
      if (it->name == name) return mark(*it);
    }
    if (attributes_ != nullptr) {
      for (auto it = attributes_->rbegin(); it != attributes_->rend(); ++it) {
        if (it->name == name) return mark(*it);
      }
    }
    return nullptr;
  }

  // The same, failing when its type is none of `types`.
  const Param* find(std::string_view name, std::initializer_list<ParamType> types) const {
    const Param* p = find(name);
    if (p == nullptr) return nullptr;
    if (std::find(types.begin(), types.end(), p->type) == types.end()) {
      std::string expected;
      std::size_t i = 0;
      for (ParamType t : types) {
        if (i > 0) expected += i + 1 == types.size() ? " or " : ", ";
        expected += paramTypeName(t);
        ++i;
      }
      fail(p->location, singleQuoted(p->name) + " of " + context_ + " must be " +
                            (types.size() == 1 ? "a " : "") + expected + ", got " +
                            singleQuoted(p->declaration()));
    }
    return p;
  }

  // Fails unless `p` has exactly `count` values of its type.
  void expectCount(const Param& p, std::size_t count, std::size_t perValue = 1) const {
    const std::size_t n = p.valueCount() / perValue;
    if (n != count) {
      fail(p.location, singleQuoted(p.name) + " of " + context_ + " takes " +
                           std::to_string(count) + (count == 1 ? " value" : " values") + ", got " +
                           std::to_string(n));
    }
  }

  std::optional<double> number(std::string_view name) const {
    const Param* p = find(name, {ParamType::kFloat});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return p->numbers[0];
  }
  std::optional<int> integer(std::string_view name) const {
    const Param* p = find(name, {ParamType::kInteger});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return static_cast<int>(p->numbers[0]);
  }
  std::optional<bool> boolean(std::string_view name) const {
    const Param* p = find(name, {ParamType::kBool});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return static_cast<bool>(p->bools[0]);
  }
  std::optional<std::string> string(std::string_view name) const {
    const Param* p = find(name, {ParamType::kString});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return p->strings[0];
  }

  // A float that must lie in a range; `bounds` names it for the message.
  std::optional<double> bounded(std::string_view name, double lo, bool loOpen, double hi,
                                bool hiOpen, const char* bounds) const {
    const Param* p = find(name, {ParamType::kFloat});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    checkBounded(*p, p->numbers[0], lo, loOpen, hi, hiOpen, bounds);
    return p->numbers[0];
  }
  void checkBounded(const Param& p, double v, double lo, bool loOpen, double hi, bool hiOpen,
                    const char* bounds) const {
    // Checked after rounding to float too, as the JSON reader does (1e-50 rounds to 0).
    const double rounded = static_cast<float>(v);
    const bool aboveLo = loOpen ? rounded > lo : rounded >= lo;
    const bool belowHi = hiOpen ? rounded < hi : rounded <= hi;
    if (!(aboveLo && belowHi)) {
      fail(p.location, singleQuoted(p.name) + " of " + context_ + ": expected " + bounds +
                           ", got " + scene_detail::formatNumber(v));
    }
  }

  // Marks every parameter used: for directives ignored as a whole, whose one warning says so.
  void markAllUsed() const {
    for (const Param& p : own_) p.used = true;
  }

  // One warning per parameter (of this context and name) that nothing read.
  void reportUnused() const;

 private:
  const Param* mark(const Param& p) const {
    p.used = true;
    return &p;
  }

  Builder& builder_;
  const std::vector<Param>& own_;
  const std::vector<Param>* attributes_;
  std::string context_;
};

// ---- the graphics state and what it refers to ---------------------------------------------

// The material a shape takes: an inline Material (by its index) or a named one, resolved at
// the end of the file as pbrt-v4 resolves them (so a name may be defined after its use).
struct MaterialRef {
  bool named = false;
  std::size_t inlineIndex = 0;  // 0: pbrt-v4's default material, a diffuse of 0.5
  std::string name;
  Location location;  // of the NamedMaterial that chose it
};

struct AreaLight {
  vec3 radiance{1.0f};  // "L": the colour space's illuminant, normalized, is white
  double scale = 1.0;
  double power = -1.0;  // pbrt-v4's "power" when positive (watts, as it defines them)
  bool twoSided = false;
  Location location;
};

struct GraphicsState {
  Xform ctm;
  bool startActive = true;  // ActiveTransform: whether transforms apply to the start time
  bool reverseOrientation = false;
  MaterialRef material;
  std::optional<AreaLight> areaLight;
  std::vector<Param> shapeAttributes, lightAttributes, materialAttributes, mediumAttributes,
      textureAttributes;
};

// A material as defined; a mix or an interface until resolved.
struct MaterialDef {
  enum class Kind { kSurface, kInterface, kMix };
  Kind kind = Kind::kSurface;
  Material material{};
  std::string label;
  Location location;
  std::array<std::string, 2> mix;                    // kMix: the named materials
  Location mixLocation;                              // of "string materials"
  double amount = 0.5;                               // kMix: pbrt-v4's probability of the second
  MaterialTextures textures = noMaterialTextures();  // parameters given by textures
};

// A scene material: a reference to a definition, with an area light's emission for the
// shapes that have one (each such shape gets its own).
struct Slot {
  MaterialRef ref;
  std::optional<vec3> emission;
  std::string lightLabel;
  bool twoSided = false;    // the emission leaves both sides
  uint alpha = kNoTexture;  // the shapes' "alpha" (a cut-out), a texture
};

struct Texture {
  std::string className;
  std::vector<Param> params;
  Location location;
};

struct InstanceShape {
  Mesh mesh;  // oriented, in the world space of the definition
  uint slot;
  Location location;
  std::string context;
};

struct Instance {
  std::vector<InstanceShape> shapes;
  Location location;
  bool defined = false;
};

struct InstanceUse {
  std::string name;
  glm::dmat4 m;
  Location location;
};

// The file's statements applied in order to pbrt-v4's graphics state.
class Builder {
 public:
  Builder(fs::path mainFile, bool strict) : mainFile_(std::move(mainFile)), strict_(strict) {
    scene_.camera.width = kDefaultWidth;
    scene_.camera.height = kDefaultHeight;
    scene_.camera.filter = defaultFilter(kFilterGaussian);  // pbrt-v4's without a PixelFilter
    scene_.integrator.maxDepth = kDefaultMaxDepth;
    MaterialDef fallback;
    fallback.material = defaultMaterial(kMaterialDiffuse);
    fallback.material.reflectance = vec3(kDefaultDiffuseReflectance);
    fallback.label = "default diffuse";
    inlineMaterials_.push_back(fallback);
  }

  void handle(Statement& s);
  Scene finish(const Location& end);

  // A warning once per `key`: "file:line: message". Every one says what is ignored or
  // rendered otherwise than pbrt-v4 renders it; with --strict it is an error instead.
  void warnOnce(const std::string& key, const Location& where, const std::string& message) {
    if (strict_) fail(where, message + " (an error with --strict)");
    if (warned_.insert(key).second) scene_.warnings.push_back(where.fileLine() + ": " + message);
  }

 private:
  // Directives by group.
  void options(Statement& s);
  void transform(const Statement& s);
  void apply(const Xform& t) {
    if (gs_.startActive) gs_.ctm = gs_.ctm * t;
  }
  void requireWorld(const Statement& s) const {
    if (!inWorld_) {
      fail(s.location, s.directive + " is allowed only after WorldBegin (in the world block)");
    }
  }
  void requireOptions(const Statement& s) const {
    if (inWorld_) {
      fail(s.location, s.directive + " is allowed only before WorldBegin (first at " +
                           worldBegin_.fileLine() + ")");
    }
  }
  void worldBegin(const Statement& s);
  void setupCamera(const Location& where);
  void material(Statement& s, bool named);
  MaterialDef makeMaterial(const std::string& type, const Params& p, const Location& where);
  void areaLightSource(Statement& s);
  void lightSource(Statement& s);
  void imageInfiniteLight(Params& p, const std::string& file, double scale,
                          std::optional<double> wanted, const std::string& context);
  void texture(Statement& s);
  void shape(Statement& s);
  bool buildShape(const std::string& type, const Params& p, const Statement& s, Mesh& mesh);
  void objectBegin(const Statement& s);
  void objectEnd(const Statement& s);

  // Spectrum and float parameters, with textures and named spectra resolved to constants.
  std::optional<vec3> spectrum(const Params& p, std::string_view name, Use use,
                               bool allowFloat = false);
  vec3 spectrumValue(const Params& p, const Param& q, Use use, int depth = 0);
  std::optional<double> floatOrTexture(const Params& p, std::string_view name);
  // The mean value of a texture over its (u, v) square, standing in for it until textures
  // exist (issue 25); nullopt where it cannot be told (the parameter keeps its default).
  std::optional<vec3> textureMean(const Texture& t, bool isFloat, const Location& use, int depth);
  std::optional<vec3> textureParamMean(const Texture& t, const char* name, bool isFloat,
                                       vec3 fallback, int depth);
  // Textures (shaders/texture.h) from the Texture directives that materials and shapes use:
  // a texture's program, built once per texture and kind (float or spectrum); nullopt for the
  // classes not simulated (a parameter then takes the texture's mean, textureMean).
  std::optional<uint> buildTexture(Texture& t, bool isFloat, const Location& use, int depth);
  // An operand of a composite texture: a value, or a texture (its mean where not simulated).
  uint textureOperand(Texture& t, const char* name, bool isFloat, vec3 fallback, int depth);
  // The texture a parameter names (a "texture" parameter of a simulated class), or kNoTexture
  // where it has a value (or is absent).
  uint textureParam(const Params& p, std::string_view name, bool isFloat);
  void readRoughness(const Params& p, MaterialDef& def, const std::string& prefix = "");

  uint slotFor(const MaterialRef& ref, uint alpha = kNoTexture);
  const MaterialDef& resolve(const MaterialRef& ref);
  const MaterialDef& followMix(const MaterialDef& def);
  bool isKnownInterface(const MaterialRef& ref) const;
  void emit(const Mesh& mesh, uint slot, const Location& where, const std::string& context);

  fs::path mainFile_;
  bool strict_ = false;  // warnings are errors
  Scene scene_;
  std::set<std::string> warned_;
  // Zero-area triangles dropped so far, in how many shapes, and where the first was.
  // Sphere area lights (their Light, with the material slot of their triangles), sampled by the
  // cone they subtend once the slots are materials (finish).
  std::vector<std::pair<Light, uint>> sphereLights_;
  std::size_t droppedTriangles_ = 0;
  std::size_t droppedShapes_ = 0;
  std::string firstDrop_;

  GraphicsState gs_;
  struct Pushed {
    GraphicsState state;
    char kind;  // 'a': AttributeBegin or TransformBegin, 'o': ObjectBegin
    Location location;
    std::string directive;
  };
  std::vector<Pushed> stack_;
  std::map<std::string, Xform> coordinateSystems_;

  bool inWorld_ = false;
  Location worldBegin_;

  // Camera and film, read before WorldBegin and applied there.
  Xform cameraFromWorld_;
  Location cameraLocation_;
  double fov_ = kDefaultFov;
  std::optional<double> frameAspect_;
  // "screenwindow": pbrt-v4's, in units of tan(fov / 2).
  std::optional<std::array<float, 4>> screenWindow_;
  bool mirrored_ = false;  // world x negated: see setupCamera

  std::vector<MaterialDef> inlineMaterials_;
  std::map<std::string, MaterialDef> namedMaterials_;
  std::vector<Slot> slots_;
  std::map<std::string, uint> slotIndex_;  // non-emissive slots by reference
  std::map<std::string, Texture> floatTextures_, spectrumTextures_;
  TextureBuilder textures_{scene_};
  std::map<std::pair<const Texture*, bool>, uint> builtTextures_;

  std::map<std::string, Instance> instances_;
  std::string activeInstance_;  // empty: not inside ObjectBegin
  std::vector<InstanceUse> instanceUses_;
  std::size_t skippedShapes_ = 0;
};

void Params::reportUnused() const {
  for (const Param& p : own_) {
    if (!p.used) {
      builder_.warnOnce("unused " + context_ + " " + p.name, p.location,
                        context_ + ": parameter " + singleQuoted(p.declaration()) +
                            " ignored (not used by this renderer)");
    }
  }
}

// ---- statements ---------------------------------------------------------------------------

void Builder::handle(Statement& s) {
  const std::string& d = s.directive;
  if (d == "Translate" || d == "Scale" || d == "Rotate" || d == "LookAt" || d == "Transform" ||
      d == "ConcatTransform" || d == "Identity" || d == "CoordinateSystem" ||
      d == "CoordSysTransform" || d == "ActiveTransform" || d == "TransformTimes") {
    transform(s);
  } else if (d == "Camera" || d == "Film" || d == "PixelFilter" || d == "Sampler" ||
             d == "Integrator" || d == "Accelerator" || d == "ColorSpace" || d == "Option") {
    options(s);
  } else if (d == "WorldBegin") {
    worldBegin(s);
  } else if (d == "WorldEnd") {
    // pbrt-v3's end of the world block: nothing to do (pbrt-v4 files end at their end).
  } else if (d == "AttributeBegin" || d == "TransformBegin") {
    requireWorld(s);
    stack_.push_back(Pushed{gs_, 'a', s.location, d});
  } else if (d == "AttributeEnd" || d == "TransformEnd") {
    requireWorld(s);
    if (stack_.empty()) {
      // pbrt-v4 reports it and goes on; so does this reader.
      warnOnce("unmatched " + d, s.location, d + " without a matching AttributeBegin ignored");
      return;
    }
    if (stack_.back().kind == 'o') {
      fail(s.location, d + " closes the ObjectBegin at " + stack_.back().location.fileLine());
    }
    gs_ = std::move(stack_.back().state);
    stack_.pop_back();
  } else if (d == "Attribute") {
    requireWorld(s);
    const std::string& target = s.strings[0];
    std::vector<Param>* list = target == "shape"      ? &gs_.shapeAttributes
                               : target == "light"    ? &gs_.lightAttributes
                               : target == "material" ? &gs_.materialAttributes
                               : target == "medium"   ? &gs_.mediumAttributes
                               : target == "texture"  ? &gs_.textureAttributes
                                                      : nullptr;
    if (list == nullptr) {
      fail(s.stringLocations[0], "unknown Attribute target " + singleQuoted(target) +
                                     " (expected \"shape\", \"light\", \"material\", "
                                     "\"medium\" or \"texture\")");
    }
    for (Param& p : s.params) {
      p.used = true;  // reported, if at all, where a directive reads the list
      list->push_back(std::move(p));
    }
  } else if (d == "ReverseOrientation") {
    requireWorld(s);
    gs_.reverseOrientation = !gs_.reverseOrientation;
  } else if (d == "Material" || d == "MakeNamedMaterial") {
    requireWorld(s);
    material(s, d == "MakeNamedMaterial");
  } else if (d == "NamedMaterial") {
    requireWorld(s);
    gs_.material = MaterialRef{true, 0, s.strings[0], s.location};
  } else if (d == "Texture") {
    requireWorld(s);
    texture(s);
  } else if (d == "AreaLightSource") {
    requireWorld(s);
    areaLightSource(s);
  } else if (d == "LightSource") {
    requireWorld(s);
    lightSource(s);
  } else if (d == "Shape") {
    requireWorld(s);
    shape(s);
  } else if (d == "ObjectBegin") {
    requireWorld(s);
    objectBegin(s);
  } else if (d == "ObjectEnd") {
    requireWorld(s);
    objectEnd(s);
  } else if (d == "ObjectInstance") {
    requireWorld(s);
    if (!activeInstance_.empty()) {
      fail(s.location, "ObjectInstance inside the definition of object " +
                           singleQuoted(activeInstance_) + " (pbrt-v4 does not nest instances)");
    }
    instanceUses_.push_back(InstanceUse{s.strings[0], gs_.ctm.m, s.location});
  } else if (d == "MakeNamedMedium") {
    Params p(*this, s, &gs_.mediumAttributes, "MakeNamedMedium");
    p.markAllUsed();
    warnOnce("MakeNamedMedium", s.location,
             "MakeNamedMedium ignored: participating media are not simulated");
  } else if (d == "MediumInterface") {
    bool any = false;
    for (const std::string& name : s.strings) any = any || !name.empty();
    if (any) {
      warnOnce("MediumInterface", s.location,
               "MediumInterface ignored: participating media are not simulated");
    }
  } else {
    PT_CHECK(false, "pbrt directive without a handler: " + d);
  }
}

void Builder::transform(const Statement& s) {
  const std::string& d = s.directive;
  const std::vector<double>& n = s.numbers;
  if (d == "Translate") {
    const glm::dvec3 v(n[0], n[1], n[2]);
    apply(Xform{translateMatrix(v), translateMatrix(-v)});
  } else if (d == "Scale") {
    const glm::dvec3 v(n[0], n[1], n[2]);
    apply(Xform{scaleMatrix(v), scaleMatrix(1.0 / v)});  // a zero factor: see emit
  } else if (d == "Rotate") {
    const glm::dvec3 axis(n[1], n[2], n[3]);
    if (!(glm::length(axis) > 0.0) || !std::isfinite(glm::length(axis))) {
      fail(s.location, "Rotate about the zero vector (the axis is the last three numbers)");
    }
    const glm::dmat4 r = rotateMatrix(n[0], axis);
    apply(Xform{r, glm::transpose(r)});
  } else if (d == "LookAt") {
    const glm::dvec3 eye(n[0], n[1], n[2]), look(n[3], n[4], n[5]), up(n[6], n[7], n[8]);
    const glm::dvec3 dir = look - eye;
    if (!(glm::length(dir) > 0.0))
      fail(s.location, "LookAt: the eye and the look-at point are equal");
    if (!(glm::length(up) > 0.0)) fail(s.location, "LookAt: the up vector is zero");
    const double sine = glm::length(glm::cross(glm::normalize(up), glm::normalize(dir)));
    if (!(sine > 1e-9)) {
      fail(s.location, "LookAt: the up vector is parallel to the view direction");
    }
    const glm::dmat4 worldFromCamera = lookAtInverse(eye, look, up);
    apply(Xform{rigidInverse(worldFromCamera), worldFromCamera});
  } else if (d == "Transform" || d == "ConcatTransform") {
    const glm::dmat4 m = fileMatrix(n.data());
    const Xform t{m, glm::inverse(m)};  // NaN where singular, as in pbrt-v4
    if (d == "Transform") {
      if (gs_.startActive) gs_.ctm = t;
    } else {
      apply(t);
    }
  } else if (d == "Identity") {
    if (gs_.startActive) gs_.ctm = Xform{};
  } else if (d == "CoordinateSystem") {
    coordinateSystems_[s.strings[0]] = gs_.ctm;
  } else if (d == "CoordSysTransform") {
    const auto it = coordinateSystems_.find(s.strings[0]);
    if (it == coordinateSystems_.end()) {
      warnOnce("CoordSysTransform " + s.strings[0], s.location,
               "CoordSysTransform: no coordinate system named " + singleQuoted(s.strings[0]) +
                   " (ignored, as pbrt-v4 does)");
    } else {
      gs_.ctm = it->second;
    }
  } else if (d == "ActiveTransform") {
    gs_.startActive = s.strings[0] != "EndTime";
    if (s.strings[0] != "All") {
      warnOnce("ActiveTransform", s.location,
               "ActiveTransform " + s.strings[0] +
                   ": motion blur is not simulated; only the start-time transforms are used");
    }
  } else if (d == "TransformTimes") {
    requireOptions(s);  // the times only matter with motion blur, which is not simulated
  }
}

void Builder::options(Statement& s) {
  const std::string& d = s.directive;
  if (d == "ColorSpace") {
    if (s.strings[0] != "srgb") {
      warnOnce("ColorSpace", s.location,
               "ColorSpace " + singleQuoted(s.strings[0]) +
                   " ignored: RGB values are taken as linear sRGB (Rec. 709 primaries)");
    }
    return;
  }
  if (d == "Option") {
    if (s.strings[0] == "seed") {
      double seed = 0.0;
      const std::string& v = s.strings[1];
      char* end = nullptr;
      seed = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || seed < 0 || seed > 4294967295.0 ||
          seed != std::floor(seed)) {
        fail(s.stringLocations[1],
             "Option \"seed\": expected an integer from 0 to 4294967295, got " + singleQuoted(v));
      }
      scene_.integrator.seed = static_cast<uint>(seed);
    } else {
      warnOnce("Option " + s.strings[0], s.location,
               "Option " + singleQuoted(s.strings[0]) + " ignored");
    }
    return;
  }
  requireOptions(s);
  const std::string& type = s.strings[0];
  Params p(*this, s, nullptr, d + " \"" + type + "\"");
  if (d == "Camera") {
    // pbrt-v4: the camera's transform is the CTM (camera from world) and "camera" names the
    // coordinate system of its inverse.
    cameraFromWorld_ = gs_.ctm;
    cameraLocation_ = s.location;
    coordinateSystems_["camera"] = Xform{gs_.ctm.inverse, gs_.ctm.m};
    if (type != "perspective") {
      warnOnce("Camera", s.location,
               "Camera " + singleQuoted(type) +
                   " is rendered as a perspective camera (the only one simulated)");
      p.markAllUsed();
    }
    if (auto v = p.bounded("fov", 0.0, true, 180.0, true,
                           "a field of view in degrees strictly "
                           "between 0 and 180")) {
      fov_ = *v;
    }
    // A thin lens as pbrt-v4's: a radius of 0 (its default) or less is a pinhole.
    if (auto v = p.number("lensradius")) {
      if (!std::isfinite(static_cast<float>(*v))) {
        fail(p.find("lensradius")->location, "lensradius must be a finite number");
      }
      scene_.camera.lensRadius = static_cast<float>(std::max(0.0, *v));
    }
    if (auto v = p.number("focaldistance")) {
      const float rounded = static_cast<float>(*v);
      if (!(rounded > 0.0f) || !std::isfinite(rounded)) {
        fail(p.find("focaldistance")->location,
             "focaldistance must be a positive distance, got " + scene_detail::formatNumber(*v));
      }
      scene_.camera.focalDistance = rounded;
    }
    if (auto v = p.number("frameaspectratio")) {
      frameAspect_ = *v;
      if (!(*v > 0.0) || !std::isfinite(static_cast<float>(*v)))
        fail(p.find("frameaspectratio")->location, "frameaspectratio must be positive");
    }
    if (const Param* q = p.find("screenwindow", {ParamType::kFloat})) {
      p.expectCount(*q, 4);
      std::array<float, 4> w{};
      for (std::size_t i = 0; i < 4; ++i) {
        w[i] = static_cast<float>(q->numbers[i]);
        if (!std::isfinite(w[i])) fail(q->location, "screenwindow: the numbers must be finite");
      }
      if (!(w[0] != w[1] && w[2] != w[3])) {
        fail(q->location, "screenwindow [x0 x1 y0 y1] must have some width and height");
      }
      screenWindow_ = w;
    }
    p.number("shutteropen");
    p.number("shutterclose");
  } else if (d == "Film") {
    if (type != "rgb") {
      warnOnce("Film", s.location,
               "Film " + singleQuoted(type) + " is rendered as an RGB film (\"rgb\")");
    }
    const auto resolution = [&](const char* name, int* out) {
      if (auto v = p.integer(name)) {
        if (*v < 1 || *v > kMaxResolution) {
          fail(p.find(name)->location, std::string(name) + ": expected an integer from 1 to " +
                                           std::to_string(kMaxResolution) + ", got " +
                                           std::to_string(*v));
        }
        *out = *v;
      }
    };
    resolution("xresolution", &scene_.camera.width);
    resolution("yresolution", &scene_.camera.height);
    p.string("filename");  // the images are the command line's --out
    // The crop, as pbrt-v4's film takes it: "cropwindow" (fractions of the film, ordered and
    // clamped to [0, 1]) wins over "pixelbounds" (pixels [x0, x1) x [y0, y1), clipped to the
    // film); the image is the crop.
    const Param* crop = p.find("cropwindow", {ParamType::kFloat});
    const Param* bounds = p.find("pixelbounds", {ParamType::kInteger});
    if (crop != nullptr) {
      p.expectCount(*crop, 4);
      std::array<float, 4> c{};
      for (std::size_t i = 0; i < 4; ++i) {
        c[i] = static_cast<float>(crop->numbers[i]);
        if (!std::isfinite(c[i])) fail(crop->location, "cropwindow: the numbers must be finite");
      }
      scene_.camera.cropWindow = c;
      if (bounds != nullptr) {
        warnOnce("pixelbounds and cropwindow", bounds->location,
                 "Film: both \"pixelbounds\" and \"cropwindow\" given: the crop window is used "
                 "(as pbrt-v4 does)");
      }
    } else if (bounds != nullptr) {
      p.expectCount(*bounds, 4);
      std::array<int, 4> b{};
      for (std::size_t i = 0; i < 4; ++i) b[i] = static_cast<int>(bounds->numbers[i]);
      const int w = scene_.camera.width, h = scene_.camera.height;
      if (std::min(b[0], b[1]) < 0 || std::max(b[0], b[1]) > w || std::min(b[2], b[3]) < 0 ||
          std::max(b[2], b[3]) > h) {
        warnOnce("pixelbounds", bounds->location,
                 "Film: \"pixelbounds\" reach beyond the " + std::to_string(w) + "x" +
                     std::to_string(h) + " film: clipped to it (as pbrt-v4 does)");
      }
      scene_.camera.pixelBounds = b;
    }
    if (crop != nullptr || bounds != nullptr) {
      const std::array<int, 4> c =
          cropPixels(scene_.camera, scene_.camera.width, scene_.camera.height);
      if (!(c[1] > c[0] && c[3] > c[2])) {
        fail((crop != nullptr ? crop : bounds)->location,
             std::string(crop != nullptr ? "cropwindow" : "pixelbounds") +
                 " selects no pixel of the " + std::to_string(scene_.camera.width) + "x" +
                 std::to_string(scene_.camera.height) + " film");
      }
    }
    if (auto v = p.number("iso"); v && *v != 100.0) {
      warnOnce("iso", s.location, "Film: \"iso\" ignored: the image is not scaled by exposure");
    }
    if (auto v = p.number("whitebalance"); v && *v != 0.0) {
      warnOnce("whitebalance", s.location, "Film: \"whitebalance\" ignored");
    }
    if (auto v = p.string("sensor"); v && *v != "cie1931") {
      warnOnce("sensor", s.location, "Film: \"sensor\" ignored: the RGB is the scene's own");
    }
    if (auto v = p.number("maxcomponentvalue"); v && std::isfinite(*v)) {
      warnOnce("maxcomponentvalue", s.location,
               "Film: \"maxcomponentvalue\" ignored: samples are not clamped");
    }
    p.number("diagonal");
    p.boolean("savefp16");
  } else if (d == "PixelFilter") {
    // pbrt-v4's filters, parameters and defaults (its filters.cpp); "sinc" is not simulated.
    const uint filterType = type == "box"        ? kFilterBox
                            : type == "triangle" ? kFilterTriangle
                            : type == "gaussian" ? kFilterGaussian
                            : type == "mitchell" ? kFilterMitchell
                                                 : ~0u;
    if (filterType == ~0u) {
      if (type != "sinc") {
        fail(s.stringLocations[0], "unknown PixelFilter type " + singleQuoted(type) +
                                       " (pbrt-v4 has \"box\", \"gaussian\", \"mitchell\", "
                                       "\"sinc\" and \"triangle\")");
      }
      warnOnce("PixelFilter", s.location,
               "PixelFilter \"sinc\" is rendered with pbrt-v4's default filter, \"gaussian\" "
               "(the windowed sinc is not simulated)");
      p.markAllUsed();
      scene_.camera.filter = defaultFilter(kFilterGaussian);
    } else {
      PixelFilterDesc filter = defaultFilter(filterType);
      const auto readFloat = [&](const char* name, float& out) {
        if (auto v = p.number(name)) {
          out = static_cast<float>(*v);
          if (!std::isfinite(out)) {
            fail(p.find(name)->location, std::string(name) + " must be finite");
          }
        }
      };
      readFloat("xradius", filter.radiusX);
      readFloat("yradius", filter.radiusY);
      if (filterType == kFilterGaussian) readFloat("sigma", filter.sigma);
      if (filterType == kFilterMitchell) {
        readFloat("B", filter.b);
        readFloat("C", filter.c);
      }
      Camera check{};
      try {
        setFilterConstants(check, filter, "");
      } catch (const InputError& e) {
        fail(s.location, "PixelFilter " + singleQuoted(type) + ": " + e.what());
      }
      scene_.camera.filter = filter;
    }
  } else if (d == "Sampler") {
    if (type == "stratified") {
      const int x = p.integer("xsamples").value_or(4);
      const int y = p.integer("ysamples").value_or(4);
      if (x < 1 || y < 1)
        fail(s.location, "Sampler \"stratified\": xsamples and ysamples must be positive");
      scene_.integrator.spp = x * y;
      p.boolean("jitter");
    } else if (auto v = p.integer("pixelsamples")) {
      if (*v < 1)
        fail(p.find("pixelsamples")->location,
             "pixelsamples must be at least 1, got " + std::to_string(*v));
      scene_.integrator.spp = *v;
    }
    if (auto v = p.integer("seed")) {
      if (*v < 0) fail(p.find("seed")->location, "seed must not be negative");
      scene_.integrator.seed = static_cast<uint>(*v);
    }
    p.string("randomization");  // which scrambling: the noise's pattern, not the image
  } else if (d == "Integrator") {
    if (type != "path" && type != "volpath") {
      warnOnce("Integrator", s.location,
               "Integrator " + singleQuoted(type) +
                   " is rendered with the path tracer (\"path\": light and BSDF sampling with "
                   "MIS)");
    }
    if (auto v = p.integer("maxdepth")) {
      if (*v < 0) fail(p.find("maxdepth")->location, "maxdepth must not be negative");
      scene_.integrator.maxDepth = *v;
    }
    if (auto v = p.boolean("regularize"); v && *v) {
      warnOnce("regularize", s.location, "Integrator: \"regularize\" ignored");
    }
    p.string("lightsampler");  // how lights are chosen: the noise, not the image
    if (type != "path" && type != "volpath") p.markAllUsed();
  } else if (d == "Accelerator") {
    p.markAllUsed();  // the BVH is this renderer's own: nothing to take from the file
  }
  p.reportUnused();
}

void Builder::worldBegin(const Statement& s) {
  if (inWorld_)
    fail(s.location, "WorldBegin appears twice (first at " + worldBegin_.fileLine() + ")");
  inWorld_ = true;
  worldBegin_ = s.location;
  gs_.ctm = Xform{};
  gs_.startActive = true;
  coordinateSystems_["world"] = Xform{};
  setupCamera(s.location);
}

// The camera as CameraDesc describes it. pbrt's camera space is left-handed: its +x is the
// image's right where CameraDesc's right is forward x up, i.e. a camera placed by LookAt alone
// shows the mirror image of what this renderer's camera at the same place shows. Where the
// camera is so (the determinant of its axes is positive), the whole world is mirrored in x
// (geometry, normals and camera: `mirrored_`), which gives pbrt's image exactly; files that
// start with Scale -1 1 1 (Bitterli's, converted from Mitsuba) need no mirroring.
void Builder::setupCamera(const Location& where) {
  const Location& at = cameraLocation_.file.empty() ? where : cameraLocation_;
  const glm::dmat4& c = cameraFromWorld_.inverse;
  glm::dvec3 position = transformPoint(c, glm::dvec3(0.0));
  glm::dvec3 right(c[0]), up(c[1]), forward(c[2]);
  const double det = glm::dot(right, glm::cross(up, forward));
  if (!(std::isfinite(det) && det != 0.0)) {
    fail(at, "the camera transform (the CTM at Camera) is singular");
  }
  mirrored_ = det > 0.0;
  if (mirrored_) {
    position.x = -position.x;
    right.x = -right.x;
    up.x = -up.x;
    forward.x = -forward.x;
  }
  const double lr = glm::length(right), lu = glm::length(up), lf = glm::length(forward);
  const double tolerance = 1e-6;
  if (std::abs(lr - lf) > tolerance * lf || std::abs(lu - lf) > tolerance * lf ||
      std::abs(glm::dot(right, up)) > tolerance * lr * lu ||
      std::abs(glm::dot(right, forward)) > tolerance * lr * lf ||
      std::abs(glm::dot(up, forward)) > tolerance * lu * lf) {
    warnOnce("camera shear", at,
             "the camera transform has a shear or a non-uniform scale: the camera takes its "
             "position, view direction and up direction only");
  }
  forward /= lf;
  up /= lu;
  const double sine = glm::length(glm::cross(forward, up));
  if (!(sine > 1e-6)) fail(at, "the camera's up direction is parallel to its view direction");
  // The target one scene-size away, so that rounding it to float moves the direction least.
  const double reach = std::max(1.0, glm::length(position));
  CameraDesc& desc = scene_.camera;
  desc.position = vec3(position);
  desc.target = vec3(position + forward * reach);
  desc.up = vec3(up);
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(desc.position[i]) || !std::isfinite(desc.target[i])) {
      fail(at, "the camera position is beyond the range of 32-bit floats");
    }
  }
  if (glm::dvec3(desc.target) == glm::dvec3(desc.position)) {
    fail(at, "the camera's view direction is lost to float rounding");
  }
  // The lens in world units: camera space's scaled by the camera transform's (uniform) scale.
  desc.lensRadius = static_cast<float>(double(desc.lensRadius) * lf);
  desc.focalDistance = static_cast<float>(double(desc.focalDistance) * lf);
  if (!std::isfinite(desc.lensRadius) || !(desc.focalDistance > 0.0f) ||
      !std::isfinite(desc.focalDistance)) {
    fail(at, "the lens (lensradius, focaldistance) is beyond the range of 32-bit floats");
  }
  // pbrt-v4's screen window: [-frame, frame] x [-1, 1] for a landscape frame, [-1, 1] x
  // [-1/frame, 1/frame] for a portrait one, times tan(fov / 2), the frame being the film's
  // aspect unless "frameaspectratio" says otherwise; or "screenwindow" times tan(fov / 2).
  // CameraDesc's is in units of tan(vfov / 2): the fov spans the shorter axis, so vfov is fov
  // for a landscape frame and 2 atan(tan(fov / 2) / frame) for a portrait one, and both give
  // [-frame, frame, -1, 1]: with the film's aspect that is CameraDesc's default, which keeps
  // the window's shape when --width and --height change the film's. An explicit
  // "screenwindow" keeps vfov = fov and its own numbers.
  const double frame =
      frameAspect_.value_or(static_cast<double>(desc.width) / static_cast<double>(desc.height));
  if (screenWindow_) {
    desc.screenWindow = screenWindow_;
  } else if (frameAspect_) {
    const float f = static_cast<float>(frame);
    desc.screenWindow = std::array<float, 4>{-f, f, -1.0f, 1.0f};
  }
  double vfov = fov_;
  if (frame < 1.0 && !screenWindow_) {
    const double halfRadians = fov_ * (3.14159265358979323846 / 360.0);
    vfov = 2.0 * std::atan(std::tan(halfRadians) / frame) * (180.0 / 3.14159265358979323846);
  }
  const float rounded = static_cast<float>(vfov);
  if (!(rounded > 0.0f && rounded < 180.0f)) {
    fail(at, "the vertical field of view (" + scene_detail::formatNumber(vfov) +
                 " degrees) is not strictly between 0 and 180");
  }
  desc.vfovDegrees = rounded;
}

// ---- materials ----------------------------------------------------------------------------

constexpr std::string_view kMaterialTypeNames[] = {
    "coatedconductor",     "coateddiffuse", "conductor", "dielectric", "diffuse",
    "diffusetransmission", "hair",          "interface", "measured",   "mix",
    "subsurface",          "thindielectric"};

void Builder::material(Statement& s, bool named) {
  Params p(*this, s, &gs_.materialAttributes,
           named ? "MakeNamedMaterial " + singleQuoted(s.strings[0]) : "Material");
  std::string type;
  if (named) {
    const Param* t = p.find("type", {ParamType::kString});
    if (t == nullptr) {
      fail(s.location, "MakeNamedMaterial " + singleQuoted(s.strings[0]) +
                           " needs a \"string type\" parameter");
    }
    p.expectCount(*t, 1);
    type = t->strings[0];
  } else {
    type = s.strings[0];
  }
  MaterialDef def = makeMaterial(type, p, named ? s.location : s.stringLocations[0]);
  def.location = s.location;
  p.reportUnused();
  if (named) {
    const std::string& name = s.strings[0];
    def.label = name;
    const auto [it, inserted] = namedMaterials_.emplace(name, def);
    if (!inserted) {
      fail(s.location, "named material " + singleQuoted(name) + " redefined (first at " +
                           it->second.location.fileLine() + ")");
    }
  } else {
    def.label = "Material \"" + type + "\" at " + s.location.fileLine();
    inlineMaterials_.push_back(def);
    gs_.material = MaterialRef{false, inlineMaterials_.size() - 1, "", s.location};
  }
}

MaterialDef Builder::makeMaterial(const std::string& type, const Params& p, const Location& where) {
  MaterialDef def;
  Material& m = def.material;
  if (type == "interface" || type == "none" || type.empty()) {
    def.kind = MaterialDef::Kind::kInterface;
    return def;
  }
  if (type == "mix") {
    def.kind = MaterialDef::Kind::kMix;
    const Param* names = p.find("materials", {ParamType::kString});
    if (names == nullptr) fail(where, "Material \"mix\" needs \"string materials\" (two names)");
    p.expectCount(*names, 2);
    def.mix = {names->strings[0], names->strings[1]};
    def.mixLocation = names->location;
    if (auto a = floatOrTexture(p, "amount")) def.amount = *a;
    warnOnce("mix", where,
             "Material \"mix\" is rendered as the one of its two materials that \"amount\" makes "
             "more likely (pbrt-v4 picks one at random per point)");
    return def;
  }
  MaterialTextures& tex = def.textures;
  const auto commonParams = [&] {
    // pbrt-v4's bump map: a float texture (or a number, which bumps nothing).
    if (const Param* d = p.find("displacement", {ParamType::kFloat, ParamType::kTexture})) {
      tex.displacement = textureParam(p, "displacement", true);
      if (tex.displacement == kNoTexture && d->type == ParamType::kTexture) {
        warnOnce("displacement", d->location,
                 "\"displacement\" of a texture class that is not simulated is ignored");
      }
    }
    if (p.find("normalmap")) {
      warnOnce("normalmap", p.find("normalmap")->location,
               "\"normalmap\" ignored: normal maps are not simulated");
    }
  };
  // A colour parameter: its texture where it names one, else its value.
  const auto colour = [&](const char* name, uint& slot, vec3& value) {
    slot = textureParam(p, name, false);
    if (slot != kNoTexture) return;
    if (auto v = spectrum(p, name, Use::kAlbedo)) value = *v;
  };
  if (type == "diffuse") {
    m = defaultMaterial(kMaterialDiffuse);
    m.reflectance = vec3(kDefaultDiffuseReflectance);
    colour("reflectance", tex.reflectance, m.reflectance);
  } else if (type == "conductor" || type == "coatedconductor") {
    // coatedconductor: its conductor alone, the coat left out (warned).
    const std::string prefix = type == "coatedconductor" ? "conductor." : "";
    m = defaultMaterial(kMaterialConductor);
    // pbrt-v4's default conductor is its measured copper, "metal-Cu-eta" and "metal-Cu-k".
    const spectra::NamedMetal* copper = spectra::namedMetal("Cu");
    PT_CHECK(copper != nullptr, "the named metal table has copper");
    m.eta = copper->eta;
    m.k = copper->k;
    tex.reflectance = textureParam(p, "reflectance", false);
    const auto reflectance = tex.reflectance != kNoTexture
                                 ? std::optional<vec3>(vec3(0.5f))
                                 : spectrum(p, "reflectance", Use::kAlbedo);
    const Param* etaParam = p.find(prefix + "eta");
    const Param* kParam = p.find(prefix + "k");
    if (reflectance && (etaParam || kParam)) {
      fail(etaParam ? etaParam->location : kParam->location,
           "a conductor takes either \"reflectance\" or \"eta\" and \"k\", not both (as in "
           "pbrt-v4)");
    }
    if (reflectance) setConductorReflectance(m, *reflectance);
    tex.eta = textureParam(p, prefix + "eta", false);
    tex.k = textureParam(p, prefix + "k", false);
    if (tex.eta != kNoTexture) {
      // (the texture gives eta at each hit)
    } else if (auto eta = spectrum(p, prefix + "eta", Use::kUnbounded, true)) {
      for (int c = 0; c < 3; ++c) {
        p.checkBounded(*etaParam, (*eta)[c], 0.0, true, 3.4e38, false, "a positive index");
      }
      m.eta = *eta;
    }
    if (tex.k == kNoTexture) {
      if (auto k = spectrum(p, prefix + "k", Use::kUnbounded, true)) m.k = *k;
    }
    readRoughness(p, def, prefix);
    if (type == "coatedconductor") {
      warnOnce("coatedconductor", where,
               "Material \"coatedconductor\" is rendered as its conductor without the coat "
               "(later work)");
      p.markAllUsed();
    }
  } else if (type == "dielectric" || type == "thindielectric") {
    m = defaultMaterial(type == "dielectric" ? kMaterialDielectric : kMaterialThinDielectric);
    if (auto eta = spectrum(p, "eta", Use::kUnbounded, true)) {
      const Param* e = p.find("eta");
      const float index = meanIndex(*eta);
      if ((*eta)[0] != (*eta)[1] || (*eta)[1] != (*eta)[2]) {
        warnOnce("dispersion", e->location,
                 "an \"eta\" that varies with wavelength is taken as its mean (dispersion is "
                 "not simulated)");
      }
      p.checkBounded(*e, index, 0.0, true, 3.4e38, false, "a positive index");
      m.eta = vec3(index, 0.0f, 0.0f);
    }
    if (type == "dielectric") readRoughness(p, def);
  } else if (type == "diffusetransmission") {
    m = defaultMaterial(kMaterialDiffuseTransmission);
    colour("reflectance", tex.reflectance, m.reflectance);
    colour("transmittance", tex.transmittance, m.transmittance);
    if (auto v = p.bounded("scale", 0.0, false, 3.4e38, false, "a non-negative number")) {
      scaleDiffuseTransmission(m, static_cast<float>(*v));
      tex.scale = static_cast<float>(*v);  // textured colours are scaled at each hit
    }
  } else if (type == "coateddiffuse") {
    m = defaultMaterial(kMaterialCoatedDiffuse);
    colour("reflectance", tex.reflectance, m.reflectance);
    readRoughness(p, def);
    tex.thickness = textureParam(p, "thickness", true);
    tex.g = textureParam(p, "g", true);
    if (tex.thickness != kNoTexture) {
      // (the texture gives it at each hit)
    } else if (auto v = floatOrTexture(p, "thickness")) {
      p.checkBounded(*p.find("thickness"), *v, 0.0, true, 3.4e38, false, "a positive number");
      m.thickness = static_cast<float>(*v);
    }
    if (auto eta = spectrum(p, "eta", Use::kUnbounded, true)) {
      const float index = meanIndex(*eta);
      p.checkBounded(*p.find("eta"), index, 0.0, true, 3.4e38, false, "a positive index");
      m.eta = vec3(index, 0.0f, 0.0f);
    }
    colour("albedo", tex.transmittance, m.transmittance);
    if (tex.g != kNoTexture) {
      // (the texture gives it at each hit)
    } else if (auto g = floatOrTexture(p, "g")) {
      p.checkBounded(*p.find("g"), *g, -1.0, true, 1.0, true, "a number strictly between -1 and 1");
      m.g = static_cast<float>(*g);
    }
    for (const char* name : {"maxdepth", "nsamples"}) {
      if (auto v = p.integer(name)) {
        if (*v < 1 || *v > kMaxCoatedWalk) {
          fail(p.find(name)->location, std::string(name) + ": expected an integer from 1 to " +
                                           std::to_string(kMaxCoatedWalk) + ", got " +
                                           std::to_string(*v));
        }
        (name[0] == 'm' ? m.maxDepth : m.nSamples) = static_cast<uint>(*v);
      }
    }
  } else if (type == "hair" || type == "measured" || type == "subsurface") {
    m = defaultMaterial(kMaterialDiffuse);
    m.reflectance = vec3(kDefaultDiffuseReflectance);
    warnOnce("material " + type, where,
             "Material " + singleQuoted(type) +
                 " is rendered as a diffuse of reflectance 0.5 "
                 "(not simulated)");
    p.markAllUsed();
  } else {
    std::vector<std::string_view> names(std::begin(kMaterialTypeNames),
                                        std::end(kMaterialTypeNames));
    fail(where,
         "unknown material type " + singleQuoted(type) + scene_detail::didYouMean(type, names));
  }
  commonParams();
  return def;
}

// pbrt-v4's roughness parameters: u and v default to "roughness" (0), remapped by default.
void Builder::readRoughness(const Params& p, MaterialDef& def, const std::string& prefix) {
  Material& m = def.material;
  MaterialTextures& tex = def.textures;
  // Textures first: "roughness" gives u and v unless they are given themselves.
  const uint both = textureParam(p, prefix + "roughness", true);
  tex.uRoughness = textureParam(p, prefix + "uroughness", true);
  tex.vRoughness = textureParam(p, prefix + "vroughness", true);
  if (tex.uRoughness == kNoTexture && !p.find(prefix + "uroughness")) tex.uRoughness = both;
  if (tex.vRoughness == kNoTexture && !p.find(prefix + "vroughness")) tex.vRoughness = both;
  auto read = [&](const std::string& name, double fallback) {
    const Param* t = p.find(name);
    if (t != nullptr && t->type == ParamType::kTexture &&
        textureParam(p, name, true) != kNoTexture) {
      return fallback;  // the texture gives it at each hit
    }
    const std::optional<double> v = floatOrTexture(p, name);
    if (!v) return fallback;
    p.checkBounded(*p.find(name), *v, 0.0, false, 3.4e38, false, "a non-negative number");
    return *v;
  };
  const double roughness = read(prefix + "roughness", 0.0);
  const double u = read(prefix + "uroughness", roughness);
  const double v = read(prefix + "vroughness", roughness);
  const bool remap = p.boolean("remaproughness").value_or(true);
  setRoughness(m, static_cast<float>(u), static_cast<float>(v), remap);
  if (remap) tex.flags |= kRemapRoughness;
}

std::optional<double> Builder::floatOrTexture(const Params& p, std::string_view name) {
  const Param* q = p.find(name, {ParamType::kFloat, ParamType::kTexture});
  if (q == nullptr) return std::nullopt;
  p.expectCount(*q, 1);
  if (q->type == ParamType::kFloat) return q->numbers[0];
  const auto it = floatTextures_.find(q->strings[0]);
  if (it == floatTextures_.end()) {
    fail(q->location,
         "unknown float texture " + singleQuoted(q->strings[0]) + " for " + singleQuoted(q->name));
  }
  if (auto mean = textureMean(it->second, /*isFloat=*/true, q->location, 0)) return (*mean).x;
  return std::nullopt;
}

uint Builder::textureParam(const Params& p, std::string_view name, bool isFloat) {
  const Param* q = p.find(name);
  if (q == nullptr || q->type != ParamType::kTexture) return kNoTexture;
  p.expectCount(*q, 1);
  auto& table = isFloat ? floatTextures_ : spectrumTextures_;
  const auto it = table.find(q->strings[0]);
  if (it == table.end()) {
    fail(q->location, "unknown " + std::string(isFloat ? "float" : "spectrum") + " texture " +
                          singleQuoted(q->strings[0]) + " for " + singleQuoted(q->name));
  }
  return buildTexture(it->second, isFloat, q->location, 0).value_or(kNoTexture);
}

namespace {

// The last parameter of texture t named `name` of type `type`, marked used; or null.
Param* textureParamOf(Texture& t, std::string_view name, ParamType type) {
  for (auto v = t.params.rbegin(); v != t.params.rend(); ++v) {
    if (v->name == name && v->type == type) {
      v->used = true;
      return &*v;
    }
  }
  return nullptr;
}

}  // namespace

uint Builder::textureOperand(Texture& t, const char* name, bool isFloat, vec3 fallback, int depth) {
  for (auto v = t.params.rbegin(); v != t.params.rend(); ++v) {
    if (v->name != name || v->type != ParamType::kTexture || v->strings.empty()) continue;
    v->used = true;
    auto& table = isFloat ? floatTextures_ : spectrumTextures_;
    const auto it = table.find(v->strings[0]);
    if (it == table.end()) {
      fail(v->location, "unknown " + std::string(isFloat ? "float" : "spectrum") + " texture " +
                            singleQuoted(v->strings[0]));
    }
    if (auto built = buildTexture(it->second, isFloat, v->location, depth + 1)) return *built;
    // A class not simulated: its mean (textureMean warns).
    return textures_.constant(
        textureMean(it->second, isFloat, v->location, depth + 1).value_or(fallback));
  }
  return textures_.constant(textureParamMean(t, name, isFloat, fallback, depth).value_or(fallback));
}

std::optional<uint> Builder::buildTexture(Texture& t, bool isFloat, const Location& use,
                                          int depth) {
  const auto key = std::make_pair(static_cast<const Texture*>(&t), isFloat);
  if (const auto it = builtTextures_.find(key); it != builtTextures_.end()) return it->second;
  if (depth > 16) fail(use, "textures nested more than 16 deep (a cycle?)");
  const std::string& c = t.className;
  // The (u, v) mapping of imagemap and checkerboard: pbrt-v4's "uv" only.
  const auto mapping = [&]() -> std::optional<vec4> {
    if (const Param* m = textureParamOf(t, "mapping", ParamType::kString)) {
      if (!m->strings.empty() && m->strings[0] != "uv") {
        warnOnce("mapping " + m->strings[0], m->location,
                 "texture mapping " + singleQuoted(m->strings[0]) +
                     " is not simulated: textures that use it take their mean value");
        return std::nullopt;
      }
    }
    vec4 uv(1.0f, 1.0f, 0.0f, 0.0f);
    const char* names[] = {"uscale", "vscale", "udelta", "vdelta"};
    for (int i = 0; i < 4; ++i) {
      if (const Param* v = textureParamOf(t, names[i], ParamType::kFloat)) {
        if (!v->numbers.empty()) uv[i] = static_cast<float>(v->numbers[0]);
      }
    }
    return uv;
  };
  std::optional<uint> built;
  try {
    if (c == "constant") {
      built = textureOperand(t, "value", isFloat, vec3(1.0f), depth);
    } else if (c == "scale") {
      const uint tex = textureOperand(t, "tex", isFloat, vec3(1.0f), depth);
      built = textures_.scale(tex, textureOperand(t, "scale", true, vec3(1.0f), depth));
    } else if (c == "mix") {
      const uint a = textureOperand(t, "tex1", isFloat, vec3(0.0f), depth);
      const uint b = textureOperand(t, "tex2", isFloat, vec3(1.0f), depth);
      built = textures_.mix(a, b, textureOperand(t, "amount", true, vec3(0.5f), depth));
    } else if (c == "checkerboard") {
      const Param* dimension = textureParamOf(t, "dimension", ParamType::kInteger);
      const bool twoD =
          dimension == nullptr || dimension->numbers.empty() || dimension->numbers[0] == 2.0;
      if (twoD) {
        if (const std::optional<vec4> uv = mapping()) {
          const uint a = textureOperand(t, "tex1", isFloat, vec3(1.0f), depth);
          const uint b = textureOperand(t, "tex2", isFloat, vec3(0.0f), depth);
          built = textures_.checkerboard(*uv, a, b);
        }
      }
    } else if (c == "imagemap") {
      const Param* file = textureParamOf(t, "filename", ParamType::kString);
      if (file == nullptr || file->strings.empty() || file->strings[0].empty()) {
        fail(t.location, "Texture \"imagemap\" without a \"filename\"");
      }
      if (const std::optional<vec4> uv = mapping()) {
        ImageTextureDesc desc;
        desc.filename = resolvePath(file->strings[0], file->location, mainFile_);
        desc.mapping = *uv;
        if (const Param* e = textureParamOf(t, "encoding", ParamType::kString)) {
          double gamma = 0.0;
          if (e->strings.empty() || !parseColorEncoding(e->strings[0], gamma)) {
            fail(e->location, "Texture \"imagemap\": unknown \"encoding\" " +
                                  singleQuoted(e->strings.empty() ? "" : e->strings[0]) +
                                  " (expected \"sRGB\", \"linear\" or \"gamma <g>\")");
          }
          desc.encoding = e->strings[0];
        }
        if (const Param* w = textureParamOf(t, "wrap", ParamType::kString)) {
          if (w->strings.empty() || !parseWrapMode(w->strings[0], desc.wrap)) {
            fail(w->location, "Texture \"imagemap\": unknown \"wrap\" " +
                                  singleQuoted(w->strings.empty() ? "" : w->strings[0]) +
                                  " (expected \"repeat\", \"clamp\" or \"black\")");
          }
        }
        if (const Param* f = textureParamOf(t, "filter", ParamType::kString)) {
          const std::string name = f->strings.empty() ? "" : f->strings[0];
          if (name == "point") {
            desc.filter = kTexturePoint;
          } else if (name == "bilinear" || name == "trilinear" || name == "ewa" || name == "EWA") {
            desc.filter = kTextureBilinear;  // MIP maps are not kept: docs/pbrt-format.md
          } else {
            fail(f->location, "Texture \"imagemap\": unknown \"filter\" " + singleQuoted(name) +
                                  " (expected \"point\", \"bilinear\", \"trilinear\" or "
                                  "\"ewa\")");
          }
        }
        textureParamOf(t, "maxanisotropy", ParamType::kFloat);
        if (const Param* v = textureParamOf(t, "scale", ParamType::kFloat)) {
          if (!v->numbers.empty()) desc.scale = static_cast<float>(v->numbers[0]);
        }
        if (const Param* v = textureParamOf(t, "invert", ParamType::kBool)) {
          if (!v->bools.empty()) desc.invert = v->bools[0];
        }
        try {
          built = textures_.image(desc, isFloat);
        } catch (const InputError& e) {
          fail(file->location, std::string("Texture \"imagemap\": ") + e.what());
        }
      }
    }
  } catch (const InputError& e) {
    const std::string what = e.what();
    // Already located (file:line:column); else the builder's (nesting) about this texture.
    if (what.rfind(t.location.fileLine(), 0) == 0 || what.find(".pbrt:") != std::string::npos) {
      throw;
    }
    fail(t.location, "Texture: " + what);
  }
  if (built) builtTextures_.emplace(key, *built);
  return built;
}

// What each texture class averages to over the (u, v) square: a constant its value, an image
// its mean texel (decoded as pbrt-v4 decodes it, then scaled and inverted as it says), a
// checkerboard the mean of its two textures (each covers half), scale the product, mix and
// bilerp the mix of the means (exact for a constant amount). Anything else keeps the
// parameter's default. One warning per class says what stood in.
std::optional<vec3> Builder::textureMean(const Texture& t, bool isFloat, const Location& use,
                                         int depth) {
  const std::string& c = t.className;
  std::optional<vec3> mean;
  if (c == "constant") {
    return textureParamMean(t, "value", isFloat, vec3(1.0f), depth);
  } else if (c == "scale") {
    const auto a = textureParamMean(t, "tex", isFloat, vec3(1.0f), depth);
    const auto b = textureParamMean(t, "scale", true, vec3(1.0f), depth);
    if (a && b) mean = *a * (*b).x;
  } else if (c == "mix") {
    const auto a = textureParamMean(t, "tex1", isFloat, vec3(0.0f), depth);
    const auto b = textureParamMean(t, "tex2", isFloat, vec3(1.0f), depth);
    const auto amount = textureParamMean(t, "amount", true, vec3(0.5f), depth);
    if (a && b && amount) mean = *a + ((*b) - (*a)) * (*amount).x;
  } else if (c == "checkerboard") {
    const auto a = textureParamMean(t, "tex1", isFloat, vec3(1.0f), depth);
    const auto b = textureParamMean(t, "tex2", isFloat, vec3(0.0f), depth);
    if (a && b) mean = 0.5f * (*a + *b);
  } else if (c == "bilerp") {
    vec3 sum(0.0f);
    bool all = true;
    for (const char* corner : {"v00", "v01", "v10", "v11"}) {
      const vec3 fallback(corner[1] == corner[2] ? 0.0f : 1.0f);  // pbrt-v4: 0, 1, 1, 0
      const auto v = textureParamMean(t, corner, isFloat, fallback, depth);
      if (v)
        sum += *v;
      else
        all = false;
    }
    if (all) mean = 0.25f * sum;
  } else if (c == "imagemap") {
    std::string file;
    Location at = t.location;
    for (auto v = t.params.rbegin(); v != t.params.rend(); ++v) {
      if (v->name == "filename" && v->type == ParamType::kString && !v->strings.empty()) {
        file = v->strings[0];
        at = v->location;
        v->used = true;
        break;
      }
    }
    if (file.empty()) fail(t.location, "Texture \"imagemap\" without a \"filename\"");
    const fs::path path = resolvePath(file, at, mainFile_);
    Image image;
    bool readable = true;
    try {
      imageFormatOf(path);
    } catch (const InputError&) {
      readable = false;  // JPEG, TGA, ...: not read yet
    }
    if (readable) {
      try {
        image = readImage(path);
      } catch (const InputError& e) {
        fail(at, std::string("Texture \"imagemap\": ") + e.what());
      }
      // PNG is decoded from sRGB (pbrt-v4's default for 8-bit images); "linear" or "gamma g"
      // take the stored numbers instead. Float images are linear whatever it says.
      std::string encoding = "sRGB";
      for (auto v = t.params.rbegin(); v != t.params.rend(); ++v) {
        if (v->name == "encoding" && v->type == ParamType::kString && !v->strings.empty()) {
          encoding = v->strings[0];
          v->used = true;
          break;
        }
      }
      const bool png = imageFormatOf(path) == ImageFormat::kPng;
      double gamma = 0.0;  // 0: the decoded values as they are
      if (png && encoding == "linear") gamma = 1.0;
      if (png && encoding.rfind("gamma ", 0) == 0) gamma = std::atof(encoding.c_str() + 6);
      glm::dvec3 sum(0.0);
      for (const vec3& px : image.pixels) {
        glm::dvec3 v(px);
        if (gamma > 0.0) {
          for (int k = 0; k < 3; ++k) v[k] = std::pow(double(linearToSrgb(px[k])), gamma);
        }
        sum += v;
      }
      vec3 m = image.pixels.empty() ? vec3(0.0f) : vec3(sum / double(image.pixels.size()));
      if (isFloat) m = vec3((m.x + m.y + m.z) / 3.0f);
      const auto scale = textureParamMean(t, "scale", true, vec3(1.0f), depth);
      if (scale) m *= (*scale).x;
      bool invert = false;
      for (auto v = t.params.rbegin(); v != t.params.rend(); ++v) {
        if (v->name == "invert" && v->type == ParamType::kBool && !v->bools.empty()) {
          invert = v->bools[0];
          v->used = true;
          break;
        }
      }
      if (invert) m = max(vec3(0.0f), vec3(1.0f) - m);
      mean = m;
    }
  }
  warnOnce("texture " + c, use,
           "textures of class " + singleQuoted(c) + " are not simulated yet: " +
               (mean ? std::string("parameters that use one take its mean value") +
                           (c == "imagemap" ? " (an image's mean texel)" : "")
                     : std::string("parameters that use one keep their default value")));
  return mean;
}

// A parameter of texture t as its mean: a number or colour as it is, a texture by textureMean;
// `fallback` (pbrt-v4's default) when t does not give it.
std::optional<vec3> Builder::textureParamMean(const Texture& t, const char* name, bool isFloat,
                                              vec3 fallback, int depth) {
  for (auto v = t.params.rbegin(); v != t.params.rend(); ++v) {
    if (v->name != name) continue;
    v->used = true;
    if (v->type == ParamType::kTexture && !v->strings.empty()) {
      if (depth > 16) fail(v->location, "textures nested more than 16 deep (a cycle?)");
      auto& table = isFloat ? floatTextures_ : spectrumTextures_;
      auto it = table.find(v->strings[0]);
      if (it == table.end()) {
        fail(v->location, "unknown " + std::string(isFloat ? "float" : "spectrum") + " texture " +
                              singleQuoted(v->strings[0]));
      }
      return textureMean(it->second, isFloat, v->location, depth + 1);
    }
    if (v->type == ParamType::kFloat && v->numbers.size() == 1) {
      return vec3(static_cast<float>(v->numbers[0]));
    }
    if (!isFloat && (v->type == ParamType::kRgb || v->type == ParamType::kSpectrum ||
                     v->type == ParamType::kBlackbody)) {
      Statement texture;
      texture.directive = "Texture";
      texture.location = t.location;
      texture.params = t.params;
      return spectrumValue(Params(*this, texture, nullptr, "Texture"), *v, Use::kUnbounded);
    }
    return fallback;
  }
  return fallback;
}

std::optional<vec3> Builder::spectrum(const Params& p, std::string_view name, Use use,
                                      bool allowFloat) {
  const Param* q = allowFloat
                       ? p.find(name, {ParamType::kFloat, ParamType::kRgb, ParamType::kSpectrum,
                                       ParamType::kBlackbody, ParamType::kTexture})
                       : p.find(name, {ParamType::kRgb, ParamType::kSpectrum, ParamType::kBlackbody,
                                       ParamType::kTexture});
  if (q == nullptr) return std::nullopt;
  if (q->type == ParamType::kTexture) {
    p.expectCount(*q, 1);
    const auto it = spectrumTextures_.find(q->strings[0]);
    if (it == spectrumTextures_.end()) {
      fail(q->location, "unknown spectrum texture " + singleQuoted(q->strings[0]) + " for " +
                            singleQuoted(q->name));
    }
    std::optional<vec3> mean = textureMean(it->second, /*isFloat=*/false, q->location, 0);
    if (mean && use == Use::kAlbedo) mean = clamp(*mean, vec3(0.0f), vec3(1.0f));
    return mean;
  }
  return spectrumValue(p, *q, use);
}

// One spectrum parameter as linear RGB. RGB values are taken as they are; sampled spectra,
// blackbodies and pbrt-v4's named spectra become the RGB that pbrt-v4's spectral render of
// them shows (host/scene/pbrt/spectra.h; docs/pbrt-format.md, Spectra). What RGB cannot
// hold (a colour outside sRGB, dispersion) is warned once per kind.
vec3 Builder::spectrumValue(const Params& p, const Param& q, Use use, int depth) {
  const std::string what = singleQuoted(q.name) + " of " + p.context();
  // A spectrum's RGB as this use needs it: a reflectance inside [0, 1] and a light without
  // negative components (a colour outside sRGB's gamut, or a reflectance above 1, is clamped
  // into it, warned); an index as it is (unboundedToRgb clamps at 0).
  auto fit = [&](glm::dvec3 rgb) {
    constexpr double kSlack = 1e-6;  // rounding of an in-gamut colour is not worth a warning
    const double high = use == Use::kAlbedo ? 1.0 : std::numeric_limits<double>::max();
    bool outside = false;
    vec3 clamped;
    for (int c = 0; c < 3; ++c) {
      outside = outside || rgb[c] < -kSlack || rgb[c] > high + kSlack;
      clamped[c] = static_cast<float>(std::clamp(rgb[c], 0.0, high));
    }
    if (outside && use == Use::kAlbedo) {
      warnOnce("spectrum gamut albedo", q.location,
               "a reflectance spectrum (here " + what +
                   ") has a colour under D65 outside sRGB's reflectances (a component below "
                   "0 or above 1): clamped into [0, 1]");
    } else if (outside) {
      warnOnce("spectrum gamut illuminant", q.location,
               "an emission spectrum (here " + what +
                   ") has a colour outside sRGB's gamut (a negative component): clamped to 0");
    }
    return clamped;
  };
  // A spectrum on pbrt-v4's 360-830 nm grid as this use needs it.
  auto convert = [&](const spectra::Dense& s, const std::string& kind) {
    std::optional<glm::dvec3> rgb;
    if (use == Use::kUnbounded) {
      rgb = spectra::unboundedToRgb(s);
    } else if (use == Use::kAlbedo) {
      rgb = spectra::reflectanceToRgb(s);
    } else if (!(spectra::toXyz(s).y > 0.0)) {
      fail(q.location, kind + " " + what +
                           " emits nothing from 360 to 830 nm (pbrt-v4 normalizes a light by "
                           "its luminance, here 0)");
    } else {
      rgb = spectra::emissionToRgb(s);
    }
    for (int c = 0; c < 3; ++c) {
      if (!rgb || !(std::abs((*rgb)[c]) <= 3.4e38)) {
        fail(q.location, kind + " " + what + ": its RGB does not fit a 32-bit float");
      }
    }
    return use == Use::kUnbounded ? vec3(*rgb) : fit(*rgb);
  };
  switch (q.type) {
    case ParamType::kFloat:
      p.expectCount(q, 1);
      return vec3(static_cast<float>(q.numbers[0]));
    case ParamType::kRgb: {
      p.expectCount(q, 1, 3);
      vec3 rgb;
      for (int c = 0; c < 3; ++c) {
        const double v = q.numbers[c];
        if (v < 0.0) fail(q.location, "rgb " + what + " has a negative component");
        if (use == Use::kAlbedo && v > 1.0) {
          fail(q.location, "rgb " + what + " has a component above 1 (it is an albedo)");
        }
        if (v > 3.4e38) fail(q.location, "rgb " + what + " does not fit a 32-bit float");
        rgb[c] = static_cast<float>(v);
      }
      return rgb;
    }
    case ParamType::kBlackbody:
      if (q.numbers.size() == 2) {
        fail(q.location, "blackbody " + what +
                             " has two values: pbrt-v3's (temperature, scale) is pbrt-v4's "
                             "temperature alone, with \"scale\" on the light");
      }
      p.expectCount(q, 1);
      if (!(q.numbers[0] > 0.0)) fail(q.location, "blackbody temperature must be positive");
      // Planck's law scaled to 1 at its peak (pbrt-v4's BlackbodySpectrum); as a light,
      // luminance 1 of its colour.
      return convert(spectra::blackbody(q.numbers[0]), "blackbody");
    case ParamType::kSpectrum:
      break;
    default:
      PT_CHECK(false, "spectrumValue on a non-spectrum type");
  }
  std::vector<double> pairs = q.numbers;
  if (!q.strings.empty()) {
    const std::string& name = q.strings[0];
    if (name.rfind("metal-", 0) == 0 &&
        (name.size() > 4 && (name.compare(name.size() - 4, 4, "-eta") == 0 ||
                             name.compare(name.size() - 2, 2, "-k") == 0))) {
      const bool eta = name.compare(name.size() - 4, 4, "-eta") == 0;
      const std::string metal = name.substr(6, name.size() - 6 - (eta ? 4 : 2));
      // The per-channel eta and k that reproduce the spectral Fresnel reflectance (spectra.cpp
      // says how closely): an RGB index, used as it is whatever the parameter.
      if (const spectra::NamedMetal* m = spectra::namedMetal(metal)) return eta ? m->eta : m->k;
    }
    if (const std::optional<glm::vec3> glass = spectra::namedGlassEta(name)) {
      const float index = ((*glass)[0] + (*glass)[1] + (*glass)[2]) / 3.0f;
      warnOnce("spectrum glass", q.location,
               "named glass spectra (here " + singleQuoted(name) +
                   ") are taken as one index, the mean of their dispersion curve's RGB (" +
                   scene_detail::formatNumber(std::round(index * 1e5) / 1e5) +
                   "; dispersion is not simulated)");
      return vec3(index);
    }
    if (const std::optional<glm::dvec3> light = spectra::namedIlluminantRgb(name)) {
      if (use == Use::kIlluminant) return fit(*light);
      warnOnce("spectrum illuminant use", q.location,
               "a named illuminant used as a reflectance or an index (here " + singleQuoted(name) +
                   " for " + what + ") is taken as its colour as a light of luminance 1");
      return fit(*light);
    }
    // Any other name is a file of wavelength-value pairs, as pbrt-v4 reads them.
    const fs::path path = resolvePath(name, q.location, mainFile_);
    std::string text, why;
    if (depth > 0 || !scene_detail::readTextFile(path, &text, &why)) {
      fail(q.location, "unknown named spectrum " + singleQuoted(name) + " for " + what +
                           ", and no such spectrum file (looked for " + quotedPath(path.string()) +
                           ": " + why + ")");
    }
    pairs.clear();
    std::size_t i = 0;
    while (i < text.size()) {
      if (text[i] == '#') {
        while (i < text.size() && text[i] != '\n') ++i;
        continue;
      }
      if (std::isspace(static_cast<unsigned char>(text[i])) || text[i] == ',') {
        ++i;
        continue;
      }
      const char* begin = text.c_str() + i;
      char* end = nullptr;
      const double v = std::strtod(begin, &end);
      if (end == begin || !std::isfinite(v)) {
        fail(q.location, "spectrum file " + quotedPath(path.string()) + " has a non-number");
      }
      pairs.push_back(v);
      i += static_cast<std::size_t>(end - begin);
    }
    if (pairs.size() < 2 || pairs.size() % 2 != 0) {
      fail(q.location,
           "spectrum file " + quotedPath(path.string()) + " does not hold wavelength-value pairs");
    }
  }
  for (std::size_t i = 1; i < pairs.size() / 2; ++i) {
    if (!(pairs[2 * i] > pairs[2 * i - 2])) {
      fail(q.location, "spectrum " + what + ": the wavelengths must increase (" +
                           scene_detail::formatNumber(pairs[2 * i]) + " follows " +
                           scene_detail::formatNumber(pairs[2 * i - 2]) + ")");
    }
  }
  // Zero outside the first and last wavelength, as pbrt-v4's PiecewiseLinearSpectrum.
  return convert(spectra::piecewiseLinear(pairs), "spectrum");
}

uint Builder::slotFor(const MaterialRef& ref, uint alpha) {
  std::string key = ref.named ? "n" + ref.name : "i" + std::to_string(ref.inlineIndex);
  if (alpha != kNoTexture) key += " alpha " + std::to_string(alpha);
  const auto it = slotIndex_.find(key);
  if (it != slotIndex_.end()) return it->second;
  const uint index = static_cast<uint>(slots_.size());
  slots_.push_back(Slot{ref, std::nullopt, "", false, alpha});
  slotIndex_.emplace(key, index);
  return index;
}

const MaterialDef& Builder::resolve(const MaterialRef& ref) {
  if (!ref.named) return followMix(inlineMaterials_[ref.inlineIndex]);
  const auto it = namedMaterials_.find(ref.name);
  if (it == namedMaterials_.end()) {
    std::vector<std::string_view> names;
    for (const auto& [name, def] : namedMaterials_) names.push_back(name);
    fail(ref.location, "NamedMaterial " + singleQuoted(ref.name) + ": no material of that name" +
                           scene_detail::didYouMean(ref.name, names));
  }
  return followMix(it->second);
}

// A mix material becomes the one of its two that is the more likely.
const MaterialDef& Builder::followMix(const MaterialDef& def) {
  const MaterialDef* d = &def;
  for (int depth = 0; d->kind == MaterialDef::Kind::kMix; ++depth) {
    if (depth >= kMaxMixDepth) {
      fail(def.location,
           "mix materials nested more than " + std::to_string(kMaxMixDepth) + " deep (a cycle?)");
    }
    const std::string& name = d->mix[d->amount > 0.5 ? 1 : 0];
    const auto it = namedMaterials_.find(name);
    if (it == namedMaterials_.end()) {
      fail(d->mixLocation, "mix: no named material " + singleQuoted(name));
    }
    if (it->second.kind == MaterialDef::Kind::kInterface) {
      fail(d->mixLocation, "mix: " + singleQuoted(name) + " is an \"interface\" material");
    }
    d = &it->second;
  }
  return *d;
}

bool Builder::isKnownInterface(const MaterialRef& ref) const {
  if (!ref.named) return inlineMaterials_[ref.inlineIndex].kind == MaterialDef::Kind::kInterface;
  const auto it = namedMaterials_.find(ref.name);
  return it != namedMaterials_.end() && it->second.kind == MaterialDef::Kind::kInterface;
}

// ---- lights and textures ------------------------------------------------------------------

void Builder::areaLightSource(Statement& s) {
  const std::string& type = s.strings[0];
  if (type != "diffuse") {
    fail(s.stringLocations[0],
         "unknown area light type " + singleQuoted(type) + " (pbrt-v4 has only \"diffuse\")");
  }
  Params p(*this, s, &gs_.lightAttributes, "AreaLightSource \"diffuse\"");
  AreaLight light;
  light.location = s.location;
  if (auto L = spectrum(p, "L", Use::kIlluminant)) light.radiance = *L;
  if (auto v = p.number("scale")) light.scale = *v;
  if (auto v = p.number("power")) light.power = *v;
  light.twoSided = p.boolean("twosided").value_or(false);
  if (auto f = p.string("filename")) {
    warnOnce("area light image", s.location,
             "AreaLightSource \"diffuse\": \"filename\" ignored (image lights are later work): "
             "it emits \"L\"");
  }
  if (!(light.scale >= 0.0) || !std::isfinite(light.scale)) {
    fail(p.find("scale")->location, "AreaLightSource \"diffuse\": scale must not be negative");
  }
  p.reportUnused();
  gs_.areaLight = light;
}

// pbrt-v4's point, spot, distant and infinite lights (lights.cpp's Create functions): the
// same parameters and defaults, "scale", "power" and "illuminance" as it applies them. Light
// spectra come as RGB normalized as pbrt-v4 normalizes them (an RGB light keeps its RGB), so
// its division of the scale by SpectrumToPhotometric is already done. Positions and
// directions go through the CTM, and through the camera's mirror (see setupCamera).
void Builder::lightSource(Statement& s) {
  const std::string& type = s.strings[0];
  const std::string context = "LightSource " + singleQuoted(type);
  Params p(*this, s, &gs_.lightAttributes, context);
  if (type != "point" && type != "spot" && type != "distant" && type != "infinite") {
    p.markAllUsed();
    if (type != "goniometric" && type != "projection") {
      fail(s.stringLocations[0], "unknown light type " + singleQuoted(type) +
                                     " (pbrt-v4 has \"point\", \"spot\", \"goniometric\", "
                                     "\"projection\", \"distant\" and \"infinite\")");
    }
    warnOnce("LightSource " + type, s.location,
             context + " ignored: " + type +
                 " lights (an image over the directions) are not "
                 "simulated");
    return;
  }
  constexpr double kPi = 3.14159265358979323846;
  double scale = p.number("scale").value_or(1.0);
  if (!(scale >= 0.0) || !std::isfinite(scale)) {
    fail(p.find("scale")->location, context + ": \"scale\" must not be negative");
  }
  // A positive "power" or "illuminance" sets the scale that gives it (pbrt-v4 ignores <= 0).
  const auto target = [&](const char* name) -> std::optional<double> {
    const auto v = p.number(name);
    if (v && !std::isfinite(*v)) fail(p.find(name)->location, context + ": bad " + name);
    return v && *v > 0.0 ? v : std::nullopt;
  };
  const auto point3 = [&](const char* name, glm::dvec3 fallback) {
    const Param* q = p.find(name, {ParamType::kPoint3});
    if (q == nullptr) return fallback;
    p.expectCount(*q, 1, 3);
    return glm::dvec3(q->numbers[0], q->numbers[1], q->numbers[2]);
  };
  const glm::dmat4& m = gs_.ctm.m;
  const auto worldPoint = [&](glm::dvec3 v) {
    glm::dvec3 w = transformPoint(m, v);
    if (mirrored_) w.x = -w.x;
    return w;
  };
  // A unit direction in world space; fails where the transform or the points leave none.
  const auto worldDirection = [&](glm::dvec3 v, const char* what) {
    glm::dvec3 w = glm::dmat3(m) * v;
    if (mirrored_) w.x = -w.x;
    const double length = glm::length(w);
    if (!(length > 0.0) || !std::isfinite(length)) {
      fail(s.location, context + ": " + what +
                           " has no direction (\"from\" equals \"to\", or "
                           "the transform is singular)");
    }
    return w / length;
  };

  Light light{};
  vec3 emitted(1.0f);  // the colour space's illuminant: white
  double k = 1.0;      // pbrt-v4's k_e where power or illuminance is given
  std::optional<double> wanted;
  if (type == "point" || type == "spot") {
    if (auto I = spectrum(p, "I", Use::kIlluminant)) emitted = *I;
    const glm::dvec3 from = point3("from", glm::dvec3(0.0));
    light.position = vec3(worldPoint(from));
    wanted = target("power");
    if (type == "point") {
      light.type = kLightPoint;
      k = 4.0 * kPi;
    } else {
      light.type = kLightSpot;
      const double cone = p.number("coneangle").value_or(30.0);
      const double delta = p.number("conedeltaangle").value_or(5.0);
      if (!std::isfinite(cone) || !std::isfinite(delta)) {
        fail(s.location, context + ": the cone angles must be finite");
      }
      const double cosEnd = std::cos(cone * kPi / 180.0);
      const double cosStart = std::cos((cone - delta) * kPi / 180.0);
      light.cosFalloffEnd = static_cast<float>(cosEnd);
      light.cosFalloffStart = static_cast<float>(cosStart);
      light.direction = vec3(worldDirection(point3("to", glm::dvec3(0, 0, 1)) - from, "the spot"));
      k = 2.0 * kPi * ((1.0 - cosStart) + (cosStart - cosEnd) / 2.0);
    }
  } else if (type == "distant") {
    light.type = kLightDistant;
    if (auto L = spectrum(p, "L", Use::kIlluminant)) emitted = *L;
    const glm::dvec3 from = point3("from", glm::dvec3(0.0));
    const glm::dvec3 to = point3("to", glm::dvec3(0, 0, 1));
    light.direction = vec3(worldDirection(from - to, "the distant light"));
    wanted = target("illuminance");  // pbrt-v4: k_e = 1 (illuminance at normal incidence)
  } else {
    light.type = kLightInfinite;
    if (auto L = spectrum(p, "L", Use::kIlluminant)) emitted = *L;
    if (const Param* portal = p.find("portal")) {
      warnOnce("portal", portal->location,
               context +
                   ": \"portal\" ignored (it only guides "
                   "sampling in pbrt-v4)");
    }
    wanted = target("illuminance");
    k = kPi;
    if (auto file = p.string("filename")) {
      if (p.find("L")) {
        fail(p.find("L")->location, context + ": \"L\" and \"filename\" exclude each other");
      }
      imageInfiniteLight(p, *file, scale, wanted, context);
      p.reportUnused();
      return;
    }
  }
  if (wanted) scale *= *wanted / k;
  const glm::dvec3 radiance = glm::dvec3(emitted) * scale;
  for (int c = 0; c < 3; ++c) {
    if (!(static_cast<float>(radiance[c]) < std::numeric_limits<float>::infinity())) {
      fail(s.location, context + ": the emission (times its scale) does not fit a 32-bit float");
    }
  }
  light.radiance = vec3(radiance);
  p.reportUnused();
  scene_.lights.push_back(light);
}

// pbrt-v4's ImageInfiniteLight: an equal-area octahedral square image (its frame the CTM's
// rotation, +z in the image's centre), its radiance the nearest texel times `scale`, or scaled
// so that the upper hemisphere's illuminance (`wanted`) comes out as pbrt-v4 computes it.
void Builder::imageInfiniteLight(Params& p, const std::string& file, double scale,
                                 std::optional<double> wanted, const std::string& context) {
  const Param* f = p.find("filename");
  if (scene_.environment) {
    fail(f->location, context + ": a second image infinite light (one per scene is supported)");
  }
  const fs::path path = resolvePath(file, f->location, mainFile_);
  EnvironmentImage env;
  env.file = path.string();
  try {
    env.image = readImage(path);
  } catch (const InputError& e) {
    fail(f->location, context + ": " + e.what());
  }
  const Image& image = env.image;
  if (image.width != image.height) {
    fail(f->location, context + ": " + singleQuoted(file) + " is " + std::to_string(image.width) +
                          "x" + std::to_string(image.height) +
                          ", not square: pbrt-v4 takes only equal-area octahedral (square) "
                          "environment images");
  }
  for (const vec3& c : image.pixels) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) {
      fail(f->location, context + ": " + singleQuoted(file) +
                            " has infinite or not-a-number pixels, no use as a light");
    }
  }
  if (wanted) {
    // pbrt-v4's illuminance of the map over its upper hemisphere (z > 0 in the light's frame),
    // its texels' luminance times cos theta, times 2 pi / (texel count) as it writes it (a
    // texel's solid angle is 4 pi / count: pbrt-v4's own factor is kept, so that the same
    // parameter gives the same image).
    double illuminance = 0.0;
    const int n = image.width;
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const vec3 w = equalAreaSquareToSphere(
            vec2((float(x) + 0.5f) / float(n), (float(y) + 0.5f) / float(n)));
        if (w.z <= 0.0f) continue;
        const vec3 c = image.at(x, y);
        illuminance +=
            (0.2126 * double(c.x) + 0.7152 * double(c.y) + 0.0722 * double(c.z)) * double(w.z);
      }
    }
    illuminance *= 2.0 * 3.14159265358979323846 / (double(n) * double(n));
    if (illuminance > 0.0) scale *= *wanted / illuminance;
  }
  for (vec3& c : env.image.pixels) {
    const glm::dvec3 v = glm::max(glm::dvec3(c), glm::dvec3(0.0)) * scale;
    if (!(float(std::max(v.x, std::max(v.y, v.z))) < std::numeric_limits<float>::infinity())) {
      fail(f->location, context +
                            ": the image's radiance (times its scale) does not fit a 32-bit "
                            "float");
    }
    c = vec3(v);
  }
  // The light's frame: the CTM's rotation, through the camera's mirror. pbrt-v4 assumes a
  // rigid transform here; a uniform scale is harmless (the axes are normalized), anything else
  // has no direction-to-direction meaning and is refused.
  const glm::dmat3 m(gs_.ctm.m);
  glm::dvec3 axes[3];
  for (int i = 0; i < 3; ++i) {
    axes[i] = m[i];
    if (mirrored_) axes[i].x = -axes[i].x;
    const double length = glm::length(axes[i]);
    if (!(length > 0.0) || !std::isfinite(length)) {
      fail(f->location, context + ": the light's transform is singular");
    }
    axes[i] /= length;
  }
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(glm::dot(axes[i], axes[(i + 1) % 3])) > 1e-4) {
      fail(f->location, context +
                            ": the light's transform is not a rotation (times a uniform "
                            "scale)");
    }
  }
  for (int i = 0; i < 3; ++i) env.toWorld[size_t(i)] = vec3(axes[i]);
  env.mapping = kEnvironmentOctahedral;
  scene_.environment = std::move(env);
}

void Builder::texture(Statement& s) {
  const std::string& name = s.strings[0];
  const std::string& type = s.strings[1];
  if (type != "float" && type != "spectrum") {
    fail(s.stringLocations[1], "Texture " + singleQuoted(name) + ": unknown texture type " +
                                   singleQuoted(type) + " (expected \"float\" or \"spectrum\")");
  }
  auto& textures = type == "float" ? floatTextures_ : spectrumTextures_;
  Texture t{s.strings[2], s.params, s.location};
  for (const Param& a : gs_.textureAttributes) t.params.insert(t.params.begin(), a);
  for (Param& q : s.params) q.used = true;  // read, or warned about, where a material uses it
  const auto [it, inserted] = textures.emplace(name, std::move(t));
  if (!inserted) {
    fail(s.location, "Texture " + singleQuoted(name) + " redefined (first at " +
                         it->second.location.fileLine() + ")");
  }
}

// ---- shapes -------------------------------------------------------------------------------

void Builder::shape(Statement& s) {
  const std::string& type = s.strings[0];
  const std::string context = "Shape \"" + type + "\"";
  Params p(*this, s, &gs_.shapeAttributes, context);
  Mesh mesh;
  const bool built = buildShape(type, p, s, mesh);
  // pbrt-v4's "alpha": the shape is cut away where it is 0 (a texture or a number).
  uint alpha = kNoTexture;
  if (const Param* a = p.find("alpha", {ParamType::kFloat, ParamType::kTexture})) {
    if (a->type == ParamType::kTexture) {
      alpha = textureParam(p, "alpha", true);
      if (alpha == kNoTexture) {
        warnOnce("alpha", a->location,
                 "\"alpha\" of a texture class that is not simulated is ignored: the shape is "
                 "opaque");
      }
    } else {
      p.expectCount(*a, 1);
      p.checkBounded(*a, a->numbers[0], 0.0, false, 1.0, false, "a number in [0, 1]");
      if (a->numbers[0] != 1.0) alpha = textures_.constant(vec3(float(a->numbers[0])));
    }
  }
  p.reportUnused();
  if (!built || mesh.triangles.empty()) {
    ++skippedShapes_;
    return;
  }
  if (isKnownInterface(gs_.material)) {
    warnOnce("interface", s.location,
             "shapes with the \"interface\" material are left out (they bound media, which are "
             "not simulated)");
    return;
  }
  if (gs_.reverseOrientation) reverseMesh(mesh);
  Mesh world = transformMesh(mesh, gs_.ctm.m);
  if (!activeInstance_.empty()) {
    if (gs_.areaLight) {
      warnOnce("instance area light", s.location,
               "area lights in object instances are ignored, as pbrt-v4 ignores them");
    }
    instances_[activeInstance_].shapes.push_back(
        InstanceShape{std::move(world), slotFor(gs_.material, alpha), s.location, context});
    return;
  }
  uint slot;
  if (gs_.areaLight) {
    const AreaLight& light = *gs_.areaLight;
    double scale = light.scale;
    if (light.power > 0.0) {
      // pbrt-v4: the scale that makes the shape emit `power`, area * pi per unit radiance
      // and side.
      double area = 0.0;
      for (const Tri& t : world.triangles) {
        area += 0.5 * glm::length(glm::cross(t[1] - t[0], t[2] - t[0]));
      }
      if (area > 0.0)
        scale *= light.power / ((light.twoSided ? 2.0 : 1.0) * area * 3.14159265358979323846);
    }
    const glm::dvec3 emission = glm::dvec3(light.radiance) * scale;
    for (int c = 0; c < 3; ++c) {
      if (!(static_cast<float>(emission[c]) < std::numeric_limits<float>::infinity())) {
        fail(light.location, "the area light's emission (L * scale) does not fit a 32-bit float");
      }
    }
    slot = static_cast<uint>(slots_.size());
    slots_.push_back(Slot{gs_.material, vec3(emission),
                          "AreaLightSource at " + light.location.fileLine(), light.twoSided,
                          alpha});
    // A sphere that stays a sphere (a rotation and a uniform scale, no mirror) and emits
    // outwards on one side: light sampling takes the cone it subtends, as pbrt-v4's does.
    const glm::dmat3 m(gs_.ctm.m);
    const double size = glm::length(m[0]);
    bool similar = glm::determinant(m) > 0.0 && size > 0.0;
    for (int a = 0; a < 3 && similar; ++a) {
      similar = std::fabs(glm::length(m[a]) - size) <= 1e-6 * size &&
                std::fabs(glm::dot(m[a], m[(a + 1) % 3])) <= 1e-6 * size * size;
    }
    if (type == "sphere" && similar && !light.twoSided && !gs_.reverseOrientation) {
      Light sphere{};
      sphere.type = kLightSphere;
      glm::dvec3 centre = transformPoint(gs_.ctm.m, glm::dvec3(0.0));
      if (mirrored_) centre.x = -centre.x;
      sphere.position = vec3(centre);
      sphere.radius = static_cast<float>(p.number("radius").value_or(1.0) * size);
      sphere.radiance = vec3(emission);
      sphereLights_.emplace_back(sphere, slot);
    }
  } else {
    slot = slotFor(gs_.material, alpha);
  }
  emit(world, slot, s.location, context);
}

// The shape's triangles in object space; false when it is skipped (warned).
bool Builder::buildShape(const std::string& type, const Params& p, const Statement& s, Mesh& mesh) {
  const std::string& context = p.context();
  if (type == "trianglemesh" || type == "loopsubdiv" || type == "bilinearmesh") {
    if (type != "trianglemesh") {
      warnOnce("shape " + type, s.location,
               context + " skipped: " +
                   (type == "loopsubdiv" ? "subdivision surfaces" : "bilinear patches") +
                   " are not supported yet");
      p.markAllUsed();
      return false;
    }
    const Param* P = p.find("P", {ParamType::kPoint3});
    if (P == nullptr) fail(s.location, context + " needs \"point3 P\"");
    const std::size_t points = P->numbers.size() / 3;
    std::vector<double> indices;
    if (const Param* I = p.find("indices", {ParamType::kInteger})) {
      indices = I->numbers;
      if (indices.size() % 3 != 0) {
        fail(I->location, "\"indices\" of " + context + " takes a multiple of 3 integers, got " +
                              std::to_string(indices.size()));
      }
      for (double v : indices) {
        if (v < 0 || v >= static_cast<double>(points)) {
          fail(I->location, "vertex index " + std::to_string(static_cast<long long>(v)) + " of " +
                                context + " out of range (the mesh has " + std::to_string(points) +
                                " points; indices start at 0)");
        }
      }
    } else if (points == 3) {
      indices = {0, 1, 2};  // pbrt-v4: three points need no indices
    } else {
      fail(s.location, context +
                           " needs \"integer indices\" (only a mesh of exactly 3 points "
                           "may leave them out)");
    }
    const Param* N = p.find("N", {ParamType::kNormal});
    if (N != nullptr && N->numbers.size() != P->numbers.size()) {
      fail(N->location, "\"N\" of " + context + " has " + std::to_string(N->numbers.size() / 3) +
                            " normals for " + std::to_string(points) + " points");
    }
    // Texture coordinates are kept; tangents are read (and checked) but not used.
    const Param* uv = p.find("uv", {ParamType::kPoint2, ParamType::kFloat});
    if (uv != nullptr) {
      if (uv->numbers.size() != 2 * points) {
        fail(uv->location, "\"uv\" of " + context + " has " +
                               std::to_string(uv->numbers.size() / 2) + " pairs for " +
                               std::to_string(points) + " points");
      }
      for (double v : uv->numbers) {
        if (!(std::fabs(v) <= double(std::numeric_limits<float>::max()))) {
          fail(uv->location, "\"uv\" of " + context +
                                 " has a value that is not finite or "
                                 "does not fit a 32-bit float");
        }
      }
    }
    p.find("S");
    p.find("faceIndices");
    const auto point = [&](const std::vector<double>& v, double i) {
      const std::size_t k = static_cast<std::size_t>(i) * 3;
      return glm::dvec3(v[k], v[k + 1], v[k + 2]);
    };
    mesh.triangles.reserve(indices.size() / 3);
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
      mesh.triangles.push_back(Tri{point(P->numbers, indices[t]), point(P->numbers, indices[t + 1]),
                                   point(P->numbers, indices[t + 2])});
      if (N != nullptr) {
        mesh.normals.push_back(Tri{point(N->numbers, indices[t]), point(N->numbers, indices[t + 1]),
                                   point(N->numbers, indices[t + 2])});
      }
      if (uv != nullptr) {
        const auto at = [&](double i) {
          const std::size_t k = static_cast<std::size_t>(i) * 2;
          return glm::vec2(float(uv->numbers[k]), float(uv->numbers[k + 1]));
        };
        mesh.uvs.push_back(UVs{at(indices[t]), at(indices[t + 1]), at(indices[t + 2])});
      }
    }
    return true;
  }
  if (type == "plymesh") {
    const Param* f = p.find("filename", {ParamType::kString});
    if (f == nullptr) fail(s.location, context + " needs \"string filename\"");
    p.expectCount(*f, 1);
    const std::string& name = f->strings[0];
    if (name.empty()) fail(f->location, "\"filename\" of " + context + " is empty");
    const fs::path path = resolvePath(name, f->location, mainFile_);
    std::string bytes, why;
    if (!scene_detail::readTextFile(path, &bytes, &why)) {
      const std::string looked =
          path.string() == name ? std::string() : "looked for " + quotedPath(path.string()) + ": ";
      fail(f->location, "cannot open " + quotedPath(name) + " (" + looked + why + ")");
    }
    scene_detail::PlyMesh ply = scene_detail::loadPlyMesh(
        bytes, path.string(), " (referenced by " + f->location.fileLine() + ")");
    mesh.triangles = std::move(ply.triangles);
    mesh.normals = std::move(ply.normals);
    mesh.uvs = std::move(ply.uvs);
    if (ply.nonFiniteNormals > 0) {
      warnOnce("non-finite normals", f->location,
               context + ": " + std::to_string(ply.nonFiniteNormals) + " vertex normals of " +
                   quotedPath(name) +
                   " are not finite (NaN or infinite): their triangles take the geometric "
                   "normal at those vertices");
    }
    for (const char* displacement : {"displacement", "edgelength"}) {
      if (p.find(displacement)) {
        warnOnce("plymesh displacement", s.location,
                 context + ": displacement ignored (the mesh is rendered as it is)");
      }
    }
    return true;
  }
  if (type == "sphere") {
    const double radius =
        p.bounded("radius", 0.0, true, 3.4e38, false, "a positive radius").value_or(1.0);
    const double zmin = p.number("zmin").value_or(-radius);
    const double zmax = p.number("zmax").value_or(radius);
    const double phimax = p.number("phimax").value_or(360.0);
    if (zmin > -radius || zmax < radius || phimax < 360.0) {
      warnOnce("partial sphere", s.location,
               "partial spheres (zmin, zmax, phimax) are not supported: skipped");
      return false;
    }
    warnOnce("sphere", s.location,
             "spheres are tessellated into " +
                 std::to_string(2 * kSphereSegments * (kSphereRings - 1)) +
                 " triangles with vertex normals (chord error 3e-4 of the radius) until they "
                 "are exact primitives");
    const auto direction = [](int ring, int segment) {
      if (ring == 0) return glm::dvec3(0, 0, 1);
      if (ring == kSphereRings) return glm::dvec3(0, 0, -1);
      const auto [cosTheta, sinTheta] = cosSinDegrees(180.0 * ring / kSphereRings);
      const auto [cosPhi, sinPhi] =
          cosSinDegrees(360.0 * (segment % kSphereSegments) / kSphereSegments);
      return glm::dvec3(sinTheta * cosPhi, sinTheta * sinPhi, cosTheta);
    };
    // pbrt-v4's (u, v) on a sphere: u = phi / 2 pi, v = 1 - theta / pi (theta from +z).
    const auto uvAt = [](int ring, int segment) {
      return glm::vec2(float(double(segment) / kSphereSegments),
                       float(1.0 - double(ring) / kSphereRings));
    };
    for (int i = 0; i < kSphereRings; ++i) {
      for (int j = 0; j < kSphereSegments; ++j) {
        const glm::dvec3 a = direction(i, j), b = direction(i, j + 1);
        const glm::dvec3 c = direction(i + 1, j), d = direction(i + 1, j + 1);
        const glm::vec2 ua = uvAt(i, j), ub = uvAt(i, j + 1), uc = uvAt(i + 1, j),
                        ud = uvAt(i + 1, j + 1);
        // (a, c, b) and (b, c, d): the winding's normal points outwards, pbrt's front.
        if (i != 0) {
          mesh.triangles.push_back(Tri{a * radius, c * radius, b * radius});
          mesh.normals.push_back(Tri{a, c, b});
          mesh.uvs.push_back(UVs{ua, uc, ub});
        }
        if (i != kSphereRings - 1) {
          mesh.triangles.push_back(Tri{b * radius, c * radius, d * radius});
          mesh.normals.push_back(Tri{b, c, d});
          mesh.uvs.push_back(UVs{ub, uc, ud});
        }
      }
    }
    return true;
  }
  if (type == "disk") {
    const double height = p.number("height").value_or(0.0);
    const double radius =
        p.bounded("radius", 0.0, true, 3.4e38, false, "a positive radius").value_or(1.0);
    const double inner = p.number("innerradius").value_or(0.0);
    const double phimax =
        p.bounded("phimax", 0.0, true, 360.0, false, "an angle in degrees in (0, 360]")
            .value_or(360.0);
    if (!(inner >= 0.0 && inner < radius)) {
      fail(p.find("innerradius")->location,
           "\"innerradius\" of " + context + " must be at least 0 and less than the radius");
    }
    warnOnce("disk", s.location,
             "disks are tessellated into " + std::to_string(kDiskSegments) +
                 " segments (chord error 3e-4 of the radius) until they are exact primitives");
    const int segments = std::max(1, static_cast<int>(std::ceil(kDiskSegments * phimax / 360.0)));
    const auto at = [&](double r, int j) {
      if (j == segments && phimax == 360.0) j = 0;  // closes the circle exactly
      const auto [c, sn] = cosSinDegrees(phimax * j / segments);
      return glm::dvec3(r * c, r * sn, height);
    };
    const glm::dvec3 center(0.0, 0.0, height);
    // pbrt-v4's (u, v) on a disk: u = phi / phimax, v = (radius - r) / (radius - inner); the
    // centre takes its segment's middle u.
    const auto uvAt = [&](double r, double j) {
      return glm::vec2(float(j / segments), float((radius - r) / (radius - inner)));
    };
    // Counter-clockwise about +z: the winding's normal is +z, pbrt's front of a disk.
    for (int j = 0; j < segments; ++j) {
      if (inner == 0.0) {
        mesh.triangles.push_back(Tri{center, at(radius, j), at(radius, j + 1)});
        mesh.uvs.push_back(UVs{uvAt(0.0, j + 0.5), uvAt(radius, j), uvAt(radius, j + 1)});
      } else {
        mesh.triangles.push_back(Tri{at(inner, j), at(radius, j), at(radius, j + 1)});
        mesh.triangles.push_back(Tri{at(inner, j), at(radius, j + 1), at(inner, j + 1)});
        mesh.uvs.push_back(UVs{uvAt(inner, j), uvAt(radius, j), uvAt(radius, j + 1)});
        mesh.uvs.push_back(UVs{uvAt(inner, j), uvAt(radius, j + 1), uvAt(inner, j + 1)});
      }
    }
    return true;
  }
  if (type == "curve" || type == "cylinder") {
    warnOnce("shape " + type, s.location,
             context + " skipped: " + (type == "curve" ? "curves (hair)" : "cylinders") +
                 " are not supported yet");
    p.markAllUsed();
    return false;
  }
  fail(s.stringLocations[0],
       "unknown shape type " + singleQuoted(type) +
           scene_detail::didYouMean(type, {"bilinearmesh", "curve", "cylinder", "disk",
                                           "loopsubdiv", "plymesh", "sphere", "trianglemesh"}));
}

void Builder::objectBegin(const Statement& s) {
  if (!activeInstance_.empty()) {
    fail(s.location, "ObjectBegin inside the definition of object " +
                         singleQuoted(activeInstance_) + " (pbrt-v4 does not nest them)");
  }
  stack_.push_back(Pushed{gs_, 'o', s.location, s.directive});
  Instance& instance = instances_[s.strings[0]];
  if (instance.defined) {
    fail(s.location, "object " + singleQuoted(s.strings[0]) + " redefined (first at " +
                         instance.location.fileLine() + ")");
  }
  instance.defined = true;
  instance.location = s.location;
  activeInstance_ = s.strings[0];
}

void Builder::objectEnd(const Statement& s) {
  if (activeInstance_.empty()) fail(s.location, "ObjectEnd without an ObjectBegin");
  if (stack_.back().kind != 'o') {
    fail(s.location, "ObjectEnd closes the " + stack_.back().directive + " at " +
                         stack_.back().location.fileLine());
  }
  gs_ = std::move(stack_.back().state);
  stack_.pop_back();
  activeInstance_.clear();
}

// Appends an oriented world-space mesh to the scene: mirrored with the camera if need be,
// rounded to float, zero-area triangles dropped as the JSON reader drops them.
void Builder::emit(const Mesh& mesh, uint slot, const Location& where, const std::string& context) {
  std::size_t dropped = 0;
  Scene& scene = scene_;
  // Room for the shape, growing geometrically: reserving the exact size for every shape
  // would copy the whole scene once per shape (855 PLY meshes took 9.6 s, mostly page faults).
  reserveGeometric(scene.triangles, scene.triangles.size() + mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    Tri t = mesh.triangles[i];
    Tri n = mesh.normals.empty() ? Tri{} : mesh.normals[i];
    UVs uv = mesh.uvs.empty() ? UVs{} : mesh.uvs[i];
    if (mirrored_) {
      // x -> -x reverses the winding, and the swap restores the front.
      for (glm::dvec3& v : t) v.x = -v.x;
      for (glm::dvec3& v : n) v.x = -v.x;
      std::swap(t[1], t[2]);
      std::swap(n[1], n[2]);
      std::swap(uv[1], uv[2]);
    }
    Triangle out{};
    glm::vec3* corners[3] = {&out.v0, &out.v1, &out.v2};
    for (int k = 0; k < 3; ++k) {
      *corners[k] = glm::vec3(t[k]);
      if (!std::isfinite(corners[k]->x) || !std::isfinite(corners[k]->y) ||
          !std::isfinite(corners[k]->z)) {
        fail(where, context + ": the transform moves vertices beyond the range of 32-bit floats");
      }
    }
    // Zero-area triangles dropped, normals made unit, as the JSON reader does.
    out.material = slot;
    const Appended appended = appendTriangle(scene, out, mesh.normals.empty() ? nullptr : &n,
                                             mesh.uvs.empty() ? nullptr : &uv);
    if (appended == Appended::kZeroArea) ++dropped;
    if (appended == Appended::kTooMany) {
      fail(where, "too many triangles in the scene (at most 4294967295)");
    }
  }
  if (dropped > 0) {
    // One warning for the whole scene (finish): Bitterli's staircase drops some in 30 shapes.
    if (droppedShapes_ == 0) firstDrop_ = where.fileLine() + ": " + context;
    droppedTriangles_ += dropped;
    ++droppedShapes_;
  }
}

Scene Builder::finish(const Location& end) {
  if (!inWorld_) fail(end, "the file ends before WorldBegin (a scene needs a world block)");
  const auto reportDropped = [&] {
    if (droppedShapes_ == 0) return;
    const auto plural = [](std::size_t n, const char* word) {
      return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
    };
    scene_.warnings.push_back(
        firstDrop_ + ": dropped " + plural(droppedTriangles_, "zero-area triangle") + " in " +
        plural(droppedShapes_, "shape") + (droppedShapes_ > 1 ? " (this is the first)" : ""));
  };
  if (!stack_.empty()) {
    const Pushed& open = stack_.back();
    fail(open.location, open.directive + " without a matching " +
                            (open.kind == 'o'                     ? std::string("ObjectEnd")
                             : open.directive == "TransformBegin" ? std::string("TransformEnd")
                                                                  : std::string("AttributeEnd")));
  }
  // Object instances, flattened: each use copies the definition's triangles under its CTM.
  for (const InstanceUse& use : instanceUses_) {
    const auto it = instances_.find(use.name);
    if (it == instances_.end() || !it->second.defined) {
      std::vector<std::string_view> names;
      for (const auto& [name, instance] : instances_) names.push_back(name);
      fail(use.location, "ObjectInstance: no object named " + singleQuoted(use.name) +
                             scene_detail::didYouMean(use.name, names));
    }
    for (const InstanceShape& shape : it->second.shapes) {
      emit(transformMesh(shape.mesh, use.m), shape.slot, use.location,
           "ObjectInstance " + singleQuoted(use.name));
    }
  }
  reportDropped();
  // Materials: each slot resolved; interface materials named before their definition drop
  // their triangles now, and only the materials some triangle uses are kept.
  std::vector<Material> materials(slots_.size());
  std::vector<std::string> names(slots_.size());
  std::vector<bool> keep(slots_.size(), true);
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const MaterialDef& def = resolve(slots_[i].ref);
    if (def.kind == MaterialDef::Kind::kInterface) {
      keep[i] = false;
      continue;
    }
    materials[i] = def.material;
    names[i] = def.label;
    if (slots_[i].emission) {
      materials[i].emission = *slots_[i].emission;
      materials[i].twoSided = slots_[i].twoSided ? 1u : 0u;
      names[i] += " + " + slots_[i].lightLabel;
    }
  }
  std::vector<bool> used(slots_.size(), false);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < scene_.triangles.size(); ++i) {
    Triangle t = scene_.triangles[i];
    if (!keep[t.material]) continue;
    used[t.material] = true;
    t.primitive = static_cast<uint>(kept);
    scene_.triangles[kept] = t;
    if (!scene_.normals.empty()) scene_.normals[kept] = scene_.normals[i];
    if (!scene_.uvs.empty()) scene_.uvs[kept] = scene_.uvs[i];
    ++kept;
  }
  scene_.triangles.resize(kept);
  if (!scene_.normals.empty()) scene_.normals.resize(kept);
  if (!scene_.uvs.empty()) scene_.uvs.resize(kept);
  std::vector<uint> remap(slots_.size(), 0);
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (!used[i]) continue;
    remap[i] = static_cast<uint>(scene_.materials.size());
    scene_.materials.push_back(materials[i]);
    scene_.materialNames.push_back(names[i]);
    MaterialTextures textures = resolve(slots_[i].ref).textures;
    textures.alpha = slots_[i].alpha;
    setMaterialTextures(scene_, scene_.materials.size() - 1, textures);
  }
  for (Triangle& t : scene_.triangles) t.material = remap[t.material];
  for (auto& [sphere, slot] : sphereLights_) {
    if (!used[slot]) continue;  // all its triangles dropped
    sphere.material = remap[slot];
    scene_.lights.push_back(sphere);
  }
  if (scene_.triangles.empty()) {
    fail(end, "the scene has no triangles to render" +
                  (skippedShapes_ > 0
                       ? " (" + std::to_string(skippedShapes_) + " shapes were skipped or empty)"
                       : std::string()));
  }
  return std::move(scene_);
}

Scene build(const std::function<void(const StatementHandler&)>& parse, const fs::path& path,
            std::size_t lines, const SceneLoadOptions& options) {
  Builder builder(path, options.strict);
  parse([&](Statement& s) { builder.handle(s); });
  return builder.finish(Location{path.string(), static_cast<int>(lines), 1});
}

std::size_t lineCount(const std::string& text) {
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

}  // namespace

Scene loadPbrtSceneText(std::string text, const fs::path& path, const SceneLoadOptions& options) {
  const std::size_t lines = lineCount(text);
  return build([&](const StatementHandler& h) { parseText(std::move(text), path, h); }, path, lines,
               options);
}

Scene loadPbrtScene(const fs::path& path, const SceneLoadOptions& options) {
  std::string text, why;
  if (!scene_detail::readTextFile(path, &text, &why)) {
    scene_detail::throwInputError(path.string(), "", "cannot open scene file (" + why + ")");
  }
  return loadPbrtSceneText(std::move(text), path, options);
}

}  // namespace pt
