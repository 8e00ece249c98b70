// pbrt-v4's parser target (its BasicSceneBuilder): the statements applied in order to the
// graphics state, each family's directives defined in its own file (pbrt_*.cpp), giving a Scene.
// Everything read but not simulated is a warning, once per kind; everything malformed an
// InputError naming file:line:column.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/shared.h"
#include "scene/camera_filter.h"
#include "scene/pbrt/pbrt_graphics_state.h"
#include "scene/pbrt/pbrt_materials.h"
#include "scene/pbrt/pbrt_media.h"
#include "scene/pbrt/pbrt_params.h"
#include "scene/pbrt/pbrt_parser.h"
#include "scene/pbrt/pbrt_shapes.h"
#include "scene/reader_helpers.h"
#include "scene/scene.h"
#include "scene/textures.h"

namespace pt::pbrt {

// pbrt-v4's defaults where they differ from the JSON reader's (its scene.cpp, film.cpp,
// integrators.cpp, materials.cpp).
constexpr int kDefaultWidth = 1280;
constexpr int kDefaultHeight = 720;
constexpr int kDefaultMaxDepth = 5;
constexpr double kDefaultFov = 90.0;
constexpr float kDefaultDiffuseReflectance = 0.5f;

// The file's statements applied in order to pbrt-v4's graphics state.
class Builder {
 public:
  Builder(std::filesystem::path mainFile, bool strict)
      : mainFile_(std::move(mainFile)), strict_(strict) {
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
  void attributes(Statement& s);
  void objectBegin(const Statement& s);
  void objectEnd(const Statement& s);
  void objectInstance(const Statement& s);
  void makeNamedMedium(Statement& s);
  void mediumInterface(const Statement& s);
  // The media of every MediumInterface a shape or the camera took, by index (unknown names
  // are errors); the named media's transforms set in the scene.
  std::vector<MediumInterface> resolveMedia();

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
  void emit(const Mesh& mesh, uint slot, std::size_t mediumInterface, const Location& where,
            const std::string& context);

  std::filesystem::path mainFile_;
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

  std::map<std::string, NamedMedium> namedMedia_;
  std::vector<MediumNames> mediumInterfaces_{MediumNames{}};  // GraphicsState::mediumInterface
  std::vector<std::size_t> triangleInterfaces_;  // per triangle of scene_, its interface's index
  std::size_t cameraInterface_ = 0;  // the interface current at Camera: its outside medium

  std::map<std::string, Instance> instances_;
  std::string activeInstance_;  // empty: not inside ObjectBegin
  std::vector<InstanceUse> instanceUses_;
  std::size_t skippedShapes_ = 0;
};

}  // namespace pt::pbrt
