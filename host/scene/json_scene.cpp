// The JSON scene reader: reads the scene description (docs/scene-format.md) into a Scene with
// a flat triangle list, validating everything and naming the field of any error.
#include "scene/json_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>

#include "common/check.h"
#include "common/named_values.h"
#include "scene/camera_filter.h"
#include "scene/gltf/gltf_wrapper.h"
#include "scene/json_media.h"
#include "scene/json_reader.h"
#include "scene/json_sections.h"
#include "scene/json_textures.h"
#include "scene/json_transform.h"
#include "scene/media.h"
#include "scene/mtl_materials.h"
#include "scene/obj_mesh.h"
#include "scene/ply_mesh.h"
#include "scene/reader_helpers.h"
#include "scene/textures.h"

namespace pt {

namespace {

using scene_detail::JsonMedia;
using scene_detail::JsonNode;
using scene_detail::JsonTextures;
using scene_detail::quotedPath;
using scene_detail::readRotation;
using scene_detail::readTransform;
using scene_detail::singleQuoted;
using scene_detail::Transform;
using Tri = std::array<glm::dvec3, 3>;

constexpr std::int64_t kMaxResolution = 16384;  // keeps width * height well inside int
constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();

// The value of an enumerated string field, from the option's name table (named_values.h).
template <typename T, std::size_t N>
T readChoice(const JsonNode& node, const NameTable<T, N>& table, const char* what) {
  const std::string s = node.string();
  if (const std::optional<T> value = valueNamed(table, s)) return *value;
  std::vector<std::string_view> names;
  for (const NamedValue<T>& entry : table) names.push_back(entry.name);
  const std::string hint = scene_detail::didYouMean(s, names);
  node.fail("unknown " + std::string(what) + " " + singleQuoted(s) +
            (hint.empty() ? " (expected " + quotedNames(table) + ")" : hint));
}

// ---- camera and integrator --------------------------------------------------------------

constexpr NameTable<uint, 4> kFilterTypes{{
    {"box", kFilterBox, "constant"},
    {"triangle", kFilterTriangle, "a tent"},
    {"gaussian", kFilterGaussian, "a truncated Gaussian"},
    {"mitchell", kFilterMitchell, "Mitchell and Netravali's cubic"},
}};

// A float field that must satisfy `ok` (after rounding to float too: 1e-50 rounds to 0).
template <typename Ok>
float readFloat(const JsonNode& n, Ok ok, const std::string& expected) {
  const double v = n.number();
  const float rounded = static_cast<float>(v);
  if (!(ok(v) && ok(double(rounded)) && std::isfinite(rounded))) {
    n.fail("expected " + expected + ", got " + n.describe());
  }
  return rounded;
}

// Four numbers [x0, x1, y0, y1].
std::array<double, 4> readRectangle(const JsonNode& n) {
  n.expectArray();
  if (n.size() != 4) n.fail("expected [x0, x1, y0, y1], got " + n.describe());
  std::array<double, 4> r{};
  for (std::size_t i = 0; i < 4; ++i) {
    r[i] = n[i].number();
    if (!std::isfinite(static_cast<float>(r[i]))) {
      n[i].fail("expected a number that fits a 32-bit float, got " + n[i].describe());
    }
  }
  return r;
}

// "filter": {"type": ..., "radius": r or [rx, ry], "sigma": s, "B": b, "C": c}, pbrt-v4's
// filters with its defaults.
PixelFilterDesc readFilter(const JsonNode& node) {
  node.expectObject();
  const uint type = readChoice(node.require("type"), kFilterTypes, "filter type");
  std::vector<std::string_view> keys{"type", "radius"};
  if (type == kFilterGaussian) keys.push_back("sigma");
  if (type == kFilterMitchell) keys.insert(keys.end(), {"B", "C"});
  node.checkKeys(keys);
  PixelFilterDesc filter = defaultFilter(type);
  const auto positive = [](double v) { return v > 0.0 && v <= 4096.0; };
  const std::string radius = "a radius in (0, 4096] pixels";
  if (auto n = node.find("radius")) {
    if (n->json().is_array()) {
      if (n->size() != 2) {
        n->fail("expected a radius or [x radius, y radius], got " + n->describe());
      }
      filter.radiusX = readFloat((*n)[0], positive, radius);
      filter.radiusY = readFloat((*n)[1], positive, radius);
    } else {
      filter.radiusX = filter.radiusY = readFloat(*n, positive, radius);
    }
  }
  if (auto n = node.find("sigma")) {
    filter.sigma = readFloat(
        *n, [](double v) { return v > 0.0; }, "a positive number");
  }
  const auto bounded = [](double v) { return v >= -100.0 && v <= 100.0; };
  if (auto n = node.find("B")) filter.b = readFloat(*n, bounded, "a number in [-100, 100]");
  if (auto n = node.find("C")) filter.c = readFloat(*n, bounded, "a number in [-100, 100]");
  // What only the combination can violate (gaussian's sigma against its radius).
  Camera check{};
  try {
    setFilterConstants(check, filter, "");
  } catch (const InputError& e) {
    node.fail(e.what());
  }
  return filter;
}

// The keys given replace those of `desc` (a glTF wrapper's camera over the file's).
CameraDesc readCamera(const JsonNode& node, CameraDesc desc = CameraDesc()) {
  // "medium" (the medium the camera is in) is read with the media (loadJsonScene).
  node.checkKeys({"position", "target", "up", "vfov", "width", "height", "filter", "lensRadius",
                  "focalDistance", "screenWindow", "cropWindow", "pixelBounds", "medium"});
  glm::dvec3 position(desc.position), target(desc.target), up(desc.up);
  if (auto n = node.find("position")) position = n->vec3();
  if (auto n = node.find("target")) target = n->vec3();
  if (auto n = node.find("up")) up = n->vec3();
  if (auto n = node.find("vfov")) {
    const double vfov = n->number();
    // Checked after rounding to float too: 179.999999999 rounds to 180 and 1e-50 to 0.
    const float rounded = static_cast<float>(vfov);
    if (!(vfov > 0.0 && vfov < 180.0 && rounded > 0.0f && rounded < 180.0f)) {
      n->fail("expected a field of view in degrees strictly between 0 and 180, got " +
              n->describe());
    }
    desc.vfovDegrees = rounded;
  }
  if (auto n = node.find("width")) desc.width = static_cast<int>(n->integer(1, kMaxResolution));
  if (auto n = node.find("height")) desc.height = static_cast<int>(n->integer(1, kMaxResolution));
  if (auto n = node.find("filter")) desc.filter = readFilter(*n);
  if (auto n = node.find("lensRadius")) {
    desc.lensRadius = readFloat(
        *n, [](double v) { return v >= 0.0; }, "a lens radius >= 0 (0: a pinhole)");
  }
  if (auto n = node.find("focalDistance")) {
    desc.focalDistance = readFloat(
        *n, [](double v) { return v > 0.0; }, "a positive distance");
  }
  if (auto n = node.find("screenWindow")) {
    const std::array<double, 4> w = readRectangle(*n);
    std::array<float, 4> f{};
    for (std::size_t i = 0; i < 4; ++i) f[i] = static_cast<float>(w[i]);
    if (!(f[0] != f[1] && f[2] != f[3])) {
      n->fail("expected a window of some width and height [x0, x1, y0, y1], got " + n->describe());
    }
    desc.screenWindow = f;
  }
  if (node.find("cropWindow") && node.find("pixelBounds")) {
    node.fail("give cropWindow or pixelBounds, not both");
  }
  if (auto n = node.find("cropWindow")) {
    const std::array<double, 4> c = readRectangle(*n);
    if (!(c[0] >= 0.0 && c[0] < c[1] && c[1] <= 1.0 && c[2] >= 0.0 && c[2] < c[3] && c[3] <= 1.0)) {
      n->fail(
          "expected fractions of the film [x0, x1, y0, y1] with 0 <= x0 < x1 <= 1 and "
          "0 <= y0 < y1 <= 1");
    }
    desc.cropWindow = std::array<float, 4>{static_cast<float>(c[0]), static_cast<float>(c[1]),
                                           static_cast<float>(c[2]), static_cast<float>(c[3])};
  }
  if (auto n = node.find("pixelBounds")) {
    n->expectArray();
    if (n->size() != 4) n->fail("expected [x0, x1, y0, y1], got " + n->describe());
    std::array<int, 4> b{};
    for (std::size_t i = 0; i < 4; ++i) b[i] = static_cast<int>((*n)[i].integer(0, kMaxResolution));
    if (!(b[0] < b[1] && b[1] <= desc.width && b[2] < b[3] && b[3] <= desc.height)) {
      n->fail("expected pixels [x0, x1) x [y0, y1) of the " + std::to_string(desc.width) + "x" +
              std::to_string(desc.height) + " film, x0 < x1 and y0 < y1");
    }
    desc.pixelBounds = b;
  }
  if (auto n = node.find("cropWindow")) {
    const std::array<int, 4> crop = cropPixels(desc, desc.width, desc.height);
    if (!(crop[1] > crop[0] && crop[3] > crop[2])) {
      n->fail("selects no pixel of the " + std::to_string(desc.width) + "x" +
              std::to_string(desc.height) + " film");
    }
  }

  // The basis must be well defined. Checked in double on the float values makeCamera sees.
  desc.position = glm::vec3(position);
  desc.target = glm::vec3(target);
  desc.up = glm::vec3(up);
  const std::string prefix = node.path() + ".";
  const glm::dvec3 forward = glm::dvec3(desc.target) - glm::dvec3(desc.position);
  if (glm::length(forward) == 0.0) {
    scene_detail::throwInputError(node.file(), prefix + "target",
                                  "equals camera.position, so there is no view direction");
  }
  const glm::dvec3 upD(desc.up);
  if (glm::length(upD) == 0.0) {
    scene_detail::throwInputError(node.file(), prefix + "up", "must not be the zero vector");
  }
  const double sine = glm::length(glm::cross(glm::normalize(forward), glm::normalize(upD)));
  if (!(sine > 1e-6)) {
    scene_detail::throwInputError(node.file(), prefix + "up",
                                  "is parallel to the view direction (target - position)");
  }
  return desc;
}

IntegratorSettings readIntegrator(const JsonNode& node) {
  IntegratorSettings s;
  // "integrator": "bdpt" names the algorithm alone.
  if (node.json().is_string()) {
    s.integrator = readChoice(node, kIntegratorNames, "integrator");
    if (s.integrator == kIntegratorSppm) s.maxDepth = kSppmDefaultMaxDepth;
    return s;
  }
  node.checkKeys({"type", "spp", "maxDepth", "seed", "russianRoulette", "rrStartDepth", "strategy",
                  "sampler", "lightSampler", "radius", "photonsperiteration"});
  if (auto n = node.find("type")) s.integrator = readChoice(*n, kIntegratorNames, "type");
  if (auto n = node.find("spp")) s.spp = static_cast<int>(n->integer(1, kIntMax));
  if (s.integrator == kIntegratorSppm) s.maxDepth = kSppmDefaultMaxDepth;
  if (auto n = node.find("maxDepth")) s.maxDepth = static_cast<int>(n->integer(0, kIntMax));
  // Photon mapping's parameters, by pbrt-v4's names: for it alone.
  for (const char* key : {"radius", "photonsperiteration"}) {
    if (auto n = node.find(key); n && s.integrator != kIntegratorSppm) {
      n->fail("is a parameter of the sppm integrator (\"type\": \"sppm\")");
    }
  }
  if (auto n = node.find("radius")) {
    const double r = n->floatNumber();
    if (!(r > 0.0)) n->fail("the initial search radius must be positive, got " + n->describe());
    s.sppm.radius = static_cast<float>(r);
  }
  if (auto n = node.find("photonsperiteration")) {
    s.sppm.photonsPerIteration = n->integer(-1, kSppmMaxPhotonsPerIteration);
    if (s.sppm.photonsPerIteration == 0) {
      n->fail("must be positive, or -1 for one photon per pixel of the image");
    }
  }
  if (auto n = node.find("seed")) s.seed = static_cast<uint>(n->integer(0, 0xFFFFFFFFll));
  if (auto n = node.find("russianRoulette")) s.russianRoulette = n->boolean();
  if (auto n = node.find("rrStartDepth")) {
    s.rrStartDepth = static_cast<int>(n->integer(1, kIntMax));
  }
  if (auto n = node.find("strategy")) s.strategy = readChoice(*n, kStrategyNames, "strategy");
  if (auto n = node.find("sampler")) s.sampler = readChoice(*n, kSamplerNames, "sampler");
  if (auto n = node.find("lightSampler")) {
    s.lightSampler = readChoice(*n, kLightSamplerNames, "lightSampler");
  }
  return s;
}

// ---- materials --------------------------------------------------------------------------

constexpr NameTable<uint, 8> kMaterialTypes{{
    {"diffuse", kMaterialDiffuse, "Lambertian"},
    {"mirror", kMaterialMirror, "ideal specular reflection"},
    {"conductor", kMaterialConductor, "metal"},
    {"dielectric", kMaterialDielectric, "glass"},
    {"thindielectric", kMaterialThinDielectric, "a thin pane"},
    {"diffusetransmission", kMaterialDiffuseTransmission, "Lambertian, both sides"},
    {"coateddiffuse", kMaterialCoatedDiffuse, "varnish over a Lambertian base"},
    {"interface", kMaterialInterface, "no surface: only bounds media"},
}};

// The keys a material of `type` takes: name, type and emission for all, then pbrt-v4's names
// of the type's parameters (docs/scene-format.md).
std::vector<std::string_view> materialKeys(uint type) {
  std::vector<std::string_view> keys = {"name", "type"};
  if (type == kMaterialInterface) return keys;  // nothing to see, nothing to emit
  const std::initializer_list<std::string_view> roughness = {"roughness", "uroughness",
                                                             "vroughness", "remaproughness"};
  switch (type) {
    case kMaterialDiffuse:
    case kMaterialMirror:
      keys.push_back("reflectance");
      break;
    case kMaterialConductor:
      keys.insert(keys.end(), {"eta", "k", "reflectance"});
      keys.insert(keys.end(), roughness);
      break;
    case kMaterialDielectric:
      keys.push_back("eta");
      keys.insert(keys.end(), roughness);
      break;
    case kMaterialThinDielectric:
      keys.push_back("eta");
      break;
    case kMaterialDiffuseTransmission:
      keys.insert(keys.end(), {"reflectance", "transmittance", "scale"});
      break;
    case kMaterialCoatedDiffuse:
      keys.push_back("reflectance");
      keys.insert(keys.end(), roughness);
      keys.insert(keys.end(), {"thickness", "eta", "albedo", "g", "maxdepth", "nsamples"});
      break;
    default:
      PT_CHECK(false, "material type without a key list");
  }
  keys.push_back("emission");
  keys.push_back("twoSided");
  keys.push_back("alpha");
  keys.push_back("displacement");
  return keys;
}

// Fails on a key the material's type does not take. A key that another type takes gets
// "not a parameter of 'type'" and the type's list (the user has the right name for the wrong
// type); any other key is unknown, with a suggestion among the type's keys.
void checkMaterialKeys(const JsonNode& m, uint type) {
  const std::vector<std::string_view> keys = materialKeys(type);
  for (const auto& [key, value] : m.json().items()) {
    if (std::find(keys.begin(), keys.end(), key) != keys.end()) continue;
    bool otherType = false;
    for (const NamedValue<uint>& t : kMaterialTypes) {
      const std::vector<std::string_view> other = materialKeys(t.value);
      otherType = otherType || std::find(other.begin(), other.end(), key) != other.end();
    }
    if (!otherType) continue;  // checkKeys below reports it
    std::string list;
    for (std::size_t i = 2; i < keys.size(); ++i) {  // past "name" and "type"
      if (i > 2) list += i + 1 == keys.size() ? " and " : ", ";
      list += "'" + std::string(keys[i]) + "'";
    }
    const std::string name = singleQuoted(nameOf(kMaterialTypes, type));
    m.find(key)->fail("not a parameter of " + name + " (a " + name + " material takes " + list +
                      ")");
  }
  m.checkKeys(keys);
}

// A number that fits a float, checked against its bounds after rounding to float (1e-50
// rounds to 0, 0.99999999999 to 1). `bounds` names them for the message.
float readBounded(const JsonNode& n, double lo, bool loOpen, double hi, bool hiOpen,
                  const char* bounds) {
  const double v = n.floatNumber();
  const double rounded = static_cast<float>(v);
  const bool aboveLo = loOpen ? rounded > lo : rounded >= lo;
  const bool belowHi = hiOpen ? rounded < hi : rounded <= hi;
  if (!(aboveLo && belowHi)) n.fail(std::string("expected ") + bounds + ", got " + n.describe());
  return static_cast<float>(v);
}

constexpr double kInf = std::numeric_limits<double>::infinity();

float readPositive(const JsonNode& n) {
  return readBounded(n, 0.0, true, kInf, false, "a positive number");
}
float readNonNegative(const JsonNode& n) {
  return readBounded(n, 0.0, false, kInf, false, "a non-negative number");
}

// A colour whose components are albedos (reflectances, transmittances) in [0, 1].
glm::vec3 readAlbedo(const JsonNode& n) {
  const glm::dvec3 r = n.vec3();
  for (std::size_t c = 0; c < 3; ++c) {
    if (!(r[c] >= 0.0 && r[c] <= 1.0)) {
      n[c].fail("expected a number in [0, 1], got " + n[c].describe());
    }
  }
  return glm::vec3(r);
}

// A conductor's eta or k: one number for all three channels, or one per channel (pbrt-v4
// takes a spectrum; this RGB renderer a value per channel).
glm::vec3 readPerChannel(const JsonNode& n, float (*read)(const JsonNode&)) {
  if (n.json().is_number()) return glm::vec3(read(n));
  if (!n.json().is_array() || n.size() != 3) {
    n.fail("expected a number or an array of 3 numbers, got " + n.describe());
  }
  return glm::vec3(read(n[0]), read(n[1]), read(n[2]));
}

// "roughness", "uroughness", "vroughness" and "remaproughness" as pbrt-v4 reads them: each
// of u and v defaults to "roughness" (0), and with remaproughness (the default) the values
// are mapped to Trowbridge-Reitz alphas by RoughnessToAlpha, alpha = sqrt(roughness).
void readRoughness(const JsonNode& m, Material& material) {
  float roughness = 0.0f;
  if (auto n = m.find("roughness")) roughness = readNonNegative(*n);
  float u = roughness, v = roughness;
  if (auto n = m.find("uroughness")) u = readNonNegative(*n);
  if (auto n = m.find("vroughness")) v = readNonNegative(*n);
  bool remap = true;
  if (auto n = m.find("remaproughness")) remap = n->boolean();
  setRoughness(material, u, v, remap);
}

// The parameters of `material.type` beyond emission, over the type's defaults.
void readMaterialParameters(const JsonNode& m, Material& material) {
  switch (material.type) {
    case kMaterialDiffuse:
    case kMaterialMirror:
      if (auto n = m.find("reflectance")) material.reflectance = readAlbedo(*n);
      break;
    case kMaterialConductor: {
      const std::optional<JsonNode> reflectance = m.find("reflectance");
      const std::optional<JsonNode> eta = m.find("eta");
      const std::optional<JsonNode> k = m.find("k");
      if (reflectance && (eta || k)) {
        reflectance->fail(std::string("a conductor takes either 'reflectance' or 'eta' and 'k', "
                                      "not both (as in pbrt-v4); this one also has ") +
                          (eta ? "'eta'" : "'k'"));
      }
      // One of eta and k alone keeps the other's default (copper), as in pbrt-v4.
      if (reflectance) setConductorReflectance(material, readAlbedo(*reflectance));
      if (eta) material.eta = readPerChannel(*eta, readPositive);
      if (k) material.k = readPerChannel(*k, readNonNegative);
      readRoughness(m, material);
      break;
    }
    case kMaterialDielectric:
    case kMaterialThinDielectric:
      // A single index: pbrt-v4's dielectrics refract all wavelengths alike unless eta is a
      // spectrum, and this renderer has no wavelengths to disperse.
      if (auto n = m.find("eta")) material.eta = glm::vec3(readPositive(*n), 0.0f, 0.0f);
      if (material.type == kMaterialDielectric) readRoughness(m, material);
      break;
    case kMaterialDiffuseTransmission: {
      if (auto n = m.find("reflectance")) material.reflectance = readAlbedo(*n);
      if (auto n = m.find("transmittance")) material.transmittance = readAlbedo(*n);
      if (auto n = m.find("scale")) {
        scaleDiffuseTransmission(material, readNonNegative(*n));
      }
      break;
    }
    case kMaterialCoatedDiffuse:
      if (auto n = m.find("reflectance")) material.reflectance = readAlbedo(*n);
      readRoughness(m, material);
      if (auto n = m.find("thickness")) material.thickness = readPositive(*n);
      if (auto n = m.find("eta")) material.eta = glm::vec3(readPositive(*n), 0.0f, 0.0f);
      if (auto n = m.find("albedo")) material.transmittance = readAlbedo(*n);
      if (auto n = m.find("g")) {
        material.g = readBounded(*n, -1.0, true, 1.0, true, "a number strictly between -1 and 1");
      }
      if (auto n = m.find("maxdepth")) {
        material.maxDepth = static_cast<uint>(n->integer(1, kMaxCoatedWalk));
      }
      if (auto n = m.find("nsamples")) {
        material.nSamples = static_cast<uint>(n->integer(1, kMaxCoatedWalk));
      }
      break;
    case kMaterialInterface:
      break;
    default:
      PT_CHECK(false, "material type without a reader");
  }
}

// The parameters of material `m` (of type `type`) that name a texture (a string in place of a
// value; docs/scene-format.md), and its "alpha" and "displacement". Returns the textures and a
// copy of the material's JSON without the textured keys, for the value readers.
MaterialTextures readMaterialTextures(const JsonNode& m, uint type, JsonTextures& textures,
                                      nlohmann::json& values) {
  MaterialTextures t = noMaterialTextures();
  values = m.json();
  const auto take = [&](const char* key, bool isFloat, uint& slot) {
    const std::optional<JsonNode> n = m.find(key);
    if (!n || !n->json().is_string()) return false;
    slot = textures.use(*n, isFloat);
    values.erase(key);
    return true;
  };
  const bool rough =
      type == kMaterialConductor || type == kMaterialDielectric || type == kMaterialCoatedDiffuse;
  if (type != kMaterialDielectric && type != kMaterialThinDielectric) {
    take("reflectance", false, t.reflectance);
  }
  if (type == kMaterialDiffuseTransmission) take("transmittance", false, t.transmittance);
  if (type == kMaterialCoatedDiffuse) {
    take("albedo", false, t.transmittance);
    take("thickness", true, t.thickness);
    take("g", true, t.g);
  }
  if (type == kMaterialConductor) {
    take("eta", false, t.eta);
    take("k", false, t.k);
    if (t.reflectance != kNoTexture && (m.find("eta") || m.find("k"))) {
      m.find("reflectance")
          ->fail(
              "a conductor takes either 'reflectance' or 'eta' and 'k', not both (as in "
              "pbrt-v4)");
    }
  }
  if (rough) {
    uint both = kNoTexture;
    if (take("roughness", true, both)) t.uRoughness = t.vRoughness = both;
    take("uroughness", true, t.uRoughness);
    take("vroughness", true, t.vRoughness);
    bool remap = true;
    if (auto n = m.find("remaproughness")) remap = n->boolean();
    if (remap) t.flags |= kRemapRoughness;
  }
  if (type == kMaterialDiffuseTransmission) {
    if (auto n = m.find("scale"); n && n->json().is_number()) {
      t.scale = static_cast<float>(n->floatNumber());
    }
  }
  // Alpha and displacement: a texture's name or a number (a constant).
  const auto floatOrTexture = [&](const char* key, uint& slot) {
    const std::optional<JsonNode> n = m.find(key);
    if (!n) return;
    if (n->json().is_string()) {
      slot = textures.use(*n, true);
      return;
    }
    const float v = static_cast<float>(n->floatNumber());
    if (std::string_view(key) == "alpha") {
      if (!(v >= 0.0f && v <= 1.0f)) n->fail("expected a number in [0, 1], got " + n->describe());
      if (v == 1.0f) return;  // opaque: nothing to test
    }
    slot = textures.constant(vec3(v));
  };
  floatOrTexture("alpha", t.alpha);
  floatOrTexture("displacement", t.displacement);
  return t;
}

void readMaterials(const JsonNode& node, Scene& scene, JsonTextures& textures) {
  if (node.size() == 0) node.fail("expected at least one material");
  std::unordered_map<std::string, std::size_t> firstIndex;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const JsonNode m = node[i];
    // The type first: it decides which keys are allowed.
    uint type = kMaterialDiffuse;
    if (auto n = m.find("type")) type = readChoice(*n, kMaterialTypes, "material type");
    checkMaterialKeys(m, type);
    const JsonNode nameNode = m.require("name");
    const std::string name = nameNode.string();
    if (name.empty()) nameNode.fail("must not be empty");
    if (auto [it, inserted] = firstIndex.emplace(name, i); !inserted) {
      nameNode.fail("duplicate material name " + singleQuoted(name) + " (also used by materials[" +
                    std::to_string(it->second) + "])");
    }

    Material material = defaultMaterial(type);
    nlohmann::json values;
    const MaterialTextures materialTextures = readMaterialTextures(m, type, textures, values);
    readMaterialParameters(JsonNode(values, m.path(), m.file()), material);
    if (auto n = m.find("emission")) {
      const glm::dvec3 e = n->vec3();
      for (std::size_t c = 0; c < 3; ++c) {
        if (!(e[c] >= 0.0)) {
          (*n)[c].fail("expected a non-negative number, got " + (*n)[c].describe());
        }
      }
      material.emission = glm::vec3(e);
    }
    if (auto n = m.find("twoSided")) material.twoSided = n->boolean() ? 1u : 0u;
    scene.materials.push_back(material);
    scene.materialNames.push_back(name);
    setMaterialTextures(scene, scene.materials.size() - 1, materialTextures);
  }
}

// ---- shapes -----------------------------------------------------------------------------

// Reads a "vertices" array of points; `exactly` > 0 demands that many.
std::vector<glm::dvec3> readPoints(const JsonNode& node, std::size_t exactly) {
  const std::size_t n = node.size();
  if (exactly > 0 && n != exactly) {
    node.fail("expected an array of " + std::to_string(exactly) + " points, got " +
              node.describe());
  }
  if (n == 0) node.fail("expected at least one point");
  std::vector<glm::dvec3> points;
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) points.push_back(node[i].vec3());
  return points;
}

std::vector<Tri> readTriangleShape(const JsonNode& shape) {
  const std::vector<glm::dvec3> vertices = readPoints(shape.require("vertices"), 0);
  const JsonNode indices = shape.require("indices");
  if (indices.size() == 0) indices.fail("expected at least one triangle");
  std::vector<Tri> triangles;
  triangles.reserve(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const JsonNode triple = indices[i];
    if (!triple.json().is_array() || triple.size() != 3) {
      triple.fail("expected an array of 3 vertex indices, got " + triple.describe());
    }
    Tri tri;
    for (std::size_t k = 0; k < 3; ++k) {
      const JsonNode index = triple[k];
      const std::int64_t v = index.integer(0, std::numeric_limits<std::int64_t>::max());
      if (static_cast<std::uint64_t>(v) >= vertices.size()) {
        index.fail("vertex index " + std::to_string(v) + " out of range (the shape has " +
                   std::to_string(vertices.size()) + " vertices; indices start at 0)");
      }
      tri[k] = vertices[static_cast<std::size_t>(v)];
    }
    triangles.push_back(tri);
  }
  return triangles;
}

// A mesh file named by a shape's "file" key, relative to the scene file.
struct MeshFile {
  std::filesystem::path path;  // as resolved
  std::string bytes;
  std::string context;  // " (referenced by <scene>: shapes[i].file)", for the mesh's messages
};

MeshFile readMeshFile(const JsonNode& shape, const std::filesystem::path& scenePath) {
  const JsonNode fileNode = shape.require("file");
  const std::string name = fileNode.string();
  if (name.empty()) fileNode.fail("expected a file name, got an empty string");
  const std::filesystem::path given(name);
  const std::filesystem::path resolved =
      given.is_absolute() ? given : scenePath.parent_path() / given;
  MeshFile mesh;
  mesh.path = resolved;
  std::string why;
  if (!scene_detail::readTextFile(resolved, &mesh.bytes, &why)) {
    const std::string looked =
        resolved == given ? std::string{} : "looked for " + quotedPath(resolved.string()) + ": ";
    fileNode.fail("cannot open " + quotedPath(name) + " (" + looked + why + ")");
  }
  mesh.context = " (referenced by " + shape.file() + ": " + fileNode.path() + ")";
  return mesh;
}

// The triangles of one shape and their materials (scene material indices).
struct ShapeTriangles {
  std::vector<Tri> triangles;
  std::vector<uint> materials;  // per triangle; empty: all take the shape's "material"
  // Per triangle, the vertex normals as the mesh file gives them (not unit, untransformed;
  // zero where a face has none), or empty when the mesh has no normals.
  std::vector<Tri> normals;
  // Per triangle, the texture coordinates of its vertices, or empty where the shape has none.
  std::vector<std::array<glm::vec2, 3>> uvs;
};

// Scene materials made from MTL files, shared by every shape that uses the same file.
struct MtlLibrary {
  // (MTL file path, material name) -> scene material index
  std::map<std::pair<std::string, std::string>, uint> sceneIndex;
  // MTL file path -> its materials, read once
  std::map<std::string, std::vector<scene_detail::MtlMaterial>> files;
  // The textures of MTL maps, made when a material with maps is first used (each image read
  // once per encoding).
  std::optional<TextureBuilder> textures;
};

// An OBJ shape with "materials": "mtl": every usemtl names a material of the OBJ's mtllib
// files, which becomes a scene material; faces before any usemtl take the shape's "material"
// (an error without one). A missing MTL file or an unknown name is an error at its OBJ line.
ShapeTriangles readObjWithMtl(const JsonNode& shape, const MeshFile& file,
                              const std::optional<uint>& fallback, MtlLibrary& library,
                              Scene& scene) {
  scene_detail::ObjMesh obj =
      scene_detail::loadObjMesh(file.bytes, file.path.string(), file.context);
  const std::string objName = file.path.string();
  auto failAt = [&](std::size_t line, const std::string& problem) {
    scene_detail::throwInputError(objName, "line " + std::to_string(line), problem + file.context);
  };
  // Every mtllib file, in order; a name's first definition wins, as within one file.
  std::vector<std::pair<std::string, const scene_detail::MtlMaterial*>> available;
  for (const scene_detail::ObjMesh::Statement& lib : obj.mtllib) {
    const std::filesystem::path mtlPath = file.path.parent_path() / lib.name;
    const std::string key = mtlPath.string();
    if (!library.files.count(key)) {
      std::string text, why;
      if (!scene_detail::readTextFile(mtlPath, &text, &why)) {
        failAt(lib.line, "cannot open material library " + quotedPath(lib.name) + " (looked for " +
                             quotedPath(key) + ": " + why + ")");
      }
      std::vector<scene_detail::MtlMaterial> materials = scene_detail::loadMtlMaterials(text, key);
      for (const scene_detail::MtlMaterial& m : materials) {
        for (const std::string& w : m.warnings) scene.warnings.push_back(w);
      }
      library.files.emplace(key, std::move(materials));
    }
    for (const scene_detail::MtlMaterial& m : library.files.at(key))
      available.emplace_back(key, &m);
  }
  // Scene material of every usemtl name.
  std::vector<uint> sceneMaterial(obj.usemtl.size());
  for (std::size_t i = 0; i < obj.usemtl.size(); ++i) {
    const std::string& name = obj.usemtl[i].name;
    const auto match = std::find_if(available.begin(), available.end(),
                                    [&](const auto& a) { return a.second->name == name; });
    if (match == available.end()) {
      std::vector<std::string_view> names;
      for (const auto& a : available) names.push_back(a.second->name);
      failAt(obj.usemtl[i].line,
             "usemtl " + singleQuoted(name) + ": no such material in " +
                 (obj.mtllib.empty() ? std::string("any mtllib (the file has no mtllib line)")
                                     : "its mtllib files") +
                 scene_detail::didYouMean(name, names));
    }
    const auto key = std::make_pair(match->first, name);
    auto [it, inserted] = library.sceneIndex.emplace(key, uint(scene.materials.size()));
    if (inserted) {
      scene.materials.push_back(match->second->material);
      scene.materialNames.push_back(std::filesystem::path(match->first).filename().string() + ":" +
                                    name);
      // Its maps' textures; the shape's texture coordinates are kept once some material has
      // textures (readShapes decides after this).
      if (!match->second->maps.empty()) {
        if (!library.textures) library.textures.emplace(scene);
        setMaterialTextures(
            scene, it->second,
            scene_detail::buildMtlTextures(*match->second, match->first, *library.textures, scene));
      }
    }
    sceneMaterial[i] = it->second;
  }
  ShapeTriangles out;
  out.triangles = std::move(obj.triangles);
  out.normals = std::move(obj.normals);
  out.uvs = std::move(obj.uvs);
  out.materials.reserve(obj.material.size());
  for (std::size_t t = 0; t < obj.material.size(); ++t) {
    if (obj.material[t] < 0) {
      if (!fallback) {
        shape.fail("needs a 'material' for the faces of " + quotedPath(objName) +
                   " that come before any usemtl");
      }
      out.materials.push_back(*fallback);
    } else {
      out.materials.push_back(sceneMaterial[std::size_t(obj.material[t])]);
    }
  }
  return out;
}

// A vertex normal in world space: transformed by the inverse transpose of the shape's linear
// map (rotation times scale: the rotation times the inverse scale); appendTriangle makes it
// unit.
glm::dvec3 worldNormal(glm::dvec3 n, const std::optional<Transform>& transform) {
  if (!transform) return n;
  const Transform& t = *transform;
  n /= t.scale;
  return n * t.cosAngle + glm::cross(t.axis, n) * t.sinAngle +
         t.axis * (glm::dot(t.axis, n) * (1.0 - t.cosAngle));
}

// Appends the triangles of one shape to the scene, transformed and rounded to float,
// dropping those of zero area. Vertex normals, where the mesh has them, go to scene.normals;
// once any shape has some, every triangle has an entry there (its geometric normal where its
// mesh has none).
void emitTriangles(const JsonNode& shape, const ShapeTriangles& shapeTriangles,
                   const std::optional<Transform>& transform, uint material,
                   MediumInterface mediumInterface, Scene& scene) {
  const std::vector<Tri>& triangles = shapeTriangles.triangles;
  std::size_t dropped = 0;
  // Room for the shape, growing geometrically: reserving the exact size for every shape
  // would copy the whole scene once per shape (855 PLY meshes took 9.6 s, mostly page faults).
  reserveGeometric(scene.triangles, scene.triangles.size() + triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const Tri& tri = triangles[i];
    Triangle out{};
    glm::vec3* corners[3] = {&out.v0, &out.v1, &out.v2};
    for (std::size_t k = 0; k < 3; ++k) {
      const glm::dvec3 p = transform ? transform->apply(tri[k]) : tri[k];
      *corners[k] = glm::vec3(p);
      if (!std::isfinite(corners[k]->x) || !std::isfinite(corners[k]->y) ||
          !std::isfinite(corners[k]->z)) {
        shape.fail("transform moves vertices beyond the range of 32-bit floats");
      }
    }
    out.material = shapeTriangles.materials.empty() ? material : shapeTriangles.materials[i];
    std::array<glm::dvec3, 3> normals;
    if (!shapeTriangles.normals.empty()) {
      for (std::size_t k = 0; k < 3; ++k) {
        normals[k] = worldNormal(shapeTriangles.normals[i][k], transform);
      }
    }
    const Appended appended =
        appendTriangle(scene, out, shapeTriangles.normals.empty() ? nullptr : &normals,
                       shapeTriangles.uvs.empty() ? nullptr : &shapeTriangles.uvs[i]);
    if (appended == Appended::kZeroArea) ++dropped;
    if (appended == Appended::kTooMany) {
      shape.fail("too many triangles in the scene (at most 4294967295)");
    }
    if (appended == Appended::kAdded) scene.mediumInterfaces.push_back(mediumInterface);
  }
  if (dropped > 0) {
    scene.warnings.push_back(shape.file() + ": " + shape.path() + ": dropped " +
                             std::to_string(dropped) + " zero-area triangle" +
                             (dropped == 1 ? "" : "s") + " (of " +
                             std::to_string(triangles.size()) + ")");
  }
}

void readShapes(const JsonNode& node, const std::filesystem::path& scenePath,
                const JsonMedia& media, Scene& scene) {
  if (node.size() == 0) node.fail("expected at least one shape");
  std::unordered_map<std::string, uint> materialIndex;
  // Views into a copy of the JSON's material names: shapes with "materials": "mtl" append to
  // scene.materialNames, which would leave views into it dangling (found by fuzzing).
  const std::vector<std::string> jsonMaterialNames = scene.materialNames;
  std::vector<std::string_view> materialNames;
  for (std::size_t i = 0; i < jsonMaterialNames.size(); ++i) {
    materialIndex.emplace(jsonMaterialNames[i], static_cast<uint>(i));
    materialNames.push_back(jsonMaterialNames[i]);
  }

  std::size_t total = 0;
  std::size_t interfaceDropped = 0;
  MtlLibrary mtlLibrary;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const JsonNode shape = node[i];
    shape.expectObject();
    enum class Kind { kQuad, kTriangles, kObj, kPly };
    static constexpr NameTable<Kind, 4> kKinds{{
        {"quad", Kind::kQuad, "a parallelogram"},
        {"triangles", Kind::kTriangles, "a list of triangles"},
        {"obj", Kind::kObj, "a Wavefront OBJ mesh"},
        {"ply", Kind::kPly, "a Stanford PLY mesh"},
    }};
    const Kind kind = readChoice(shape.require("type"), kKinds, "shape type");
    switch (kind) {
      case Kind::kQuad:
        shape.checkKeys(
            {"type", "name", "material", "vertices", "transform", "interior", "exterior"});
        break;
      case Kind::kTriangles:
        shape.checkKeys({"type", "name", "material", "vertices", "indices", "transform", "interior",
                         "exterior"});
        break;
      case Kind::kObj:
        shape.checkKeys(
            {"type", "name", "material", "materials", "file", "transform", "interior", "exterior"});
        break;
      case Kind::kPly:
        shape.checkKeys({"type", "name", "material", "file", "transform", "interior", "exterior"});
        break;
    }
    if (auto n = shape.find("name")) n->string();  // documentation only, but must be a string

    // "materials": "mtl" (OBJ only) takes the materials from the OBJ's MTL files; then
    // "material" is optional, for faces before any usemtl.
    bool useMtl = false;
    if (auto n = shape.find("materials")) {
      if (n->string() != "mtl") {
        n->fail("expected 'mtl' (materials from the OBJ's mtllib files), got " + n->describe());
      }
      useMtl = true;
    }
    std::optional<uint> material;
    if (!useMtl || shape.find("material")) {
      const JsonNode materialNode = shape.require("material");
      const std::string materialName = materialNode.string();
      const auto found = materialIndex.find(materialName);
      if (found == materialIndex.end()) {
        materialNode.fail("unknown material " + singleQuoted(materialName) +
                          scene_detail::didYouMean(materialName, materialNames));
      }
      material = found->second;
    }

    std::optional<Transform> transform;
    if (auto n = shape.find("transform")) transform = readTransform(*n);
    // The media on the two sides: "interior" opposite the triangles' normals (pbrt-v4's inside),
    // "exterior" on their side.
    const MediumInterface mediumInterface{media.find(shape, "interior"),
                                          media.find(shape, "exterior")};

    ShapeTriangles triangles;
    switch (kind) {
      case Kind::kQuad: {
        const std::vector<glm::dvec3> v = readPoints(shape.require("vertices"), 4);
        // Fixed split along the v0-v2 diagonal; both halves keep the quad's winding.
        triangles.triangles = {Tri{v[0], v[1], v[2]}, Tri{v[0], v[2], v[3]}};
        // The corners' (u, v): (0, 0), (1, 0), (1, 1), (0, 1) in the order given, as pbrt-v4's
        // bilinear patch maps its four corners.
        const glm::vec2 c[4] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
        triangles.uvs = {{c[0], c[1], c[2]}, {c[0], c[2], c[3]}};
        break;
      }
      case Kind::kTriangles:
        triangles.triangles = readTriangleShape(shape);
        break;
      case Kind::kObj: {
        const MeshFile file = readMeshFile(shape, scenePath);
        if (useMtl) {
          triangles = readObjWithMtl(shape, file, material, mtlLibrary, scene);
        } else {
          scene_detail::ObjMesh obj =
              scene_detail::loadObjMesh(file.bytes, file.path.string(), file.context);
          triangles.triangles = std::move(obj.triangles);
          triangles.normals = std::move(obj.normals);
          triangles.uvs = std::move(obj.uvs);
        }
        break;
      }
      case Kind::kPly: {
        const MeshFile file = readMeshFile(shape, scenePath);
        scene_detail::PlyMesh ply =
            scene_detail::loadPlyMesh(file.bytes, file.path.string(), file.context);
        triangles.triangles = std::move(ply.triangles);
        triangles.normals = std::move(ply.normals);
        triangles.uvs = std::move(ply.uvs);
        if (ply.nonFiniteNormals > 0) {
          scene.warnings.push_back(file.path.string() + ": " +
                                   std::to_string(ply.nonFiniteNormals) +
                                   " vertex normals are not finite (NaN or infinite): their "
                                   "triangles take the geometric normal at those vertices");
        }
        break;
      }
    }
    total += triangles.triangles.size();
    // An "interface" shape that bounds no medium (the same on both sides) changes nothing.
    if (!useMtl && scene.materials[*material].type == kMaterialInterface &&
        mediumInterface.inside == mediumInterface.outside) {
      interfaceDropped += triangles.triangles.size();
      continue;
    }
    // Texture coordinates only where some material has a texture (materials come first).
    if (scene.materialTextures.empty()) triangles.uvs.clear();
    emitTriangles(shape, triangles, transform, material.value_or(0u), mediumInterface, scene);
  }
  if (scene.triangles.empty()) {
    node.fail("no triangles left: all " + std::to_string(total) +
              (interfaceDropped == 0 ? " have zero area"
                                     : " have zero area or belong to \"interface\" shapes that "
                                       "bound no medium"));
  }
}

}  // namespace

// ---- lights -----------------------------------------------------------------------------

namespace {

// An "environment" light with a "filename": the image (relative to the scene file), its
// "mapping" ("latlong", the default, or "octahedral"), "scale" and "rotate" (docs/scene-format.md).
void readEnvironmentImage(const JsonNode& l, const std::filesystem::path& sceneFile, Scene& scene) {
  l.checkKeys({"type", "filename", "mapping", "scale", "rotate"});
  const JsonNode fileNode = l.require("filename");
  if (scene.environment) fileNode.fail("a second environment image (one per scene is supported)");
  EnvironmentImage env;
  const std::filesystem::path path = sceneFile.parent_path() / fileNode.string();
  env.file = path.string();
  try {
    env.image = readImage(path);
  } catch (const InputError& e) {
    fileNode.fail(e.what());
  }
  env.mapping = kEnvironmentLatLong;
  if (auto n = l.find("mapping")) {
    const std::string mapping = n->string();
    if (mapping == "octahedral") {
      env.mapping = kEnvironmentOctahedral;
    } else if (mapping != "latlong") {
      n->fail("unknown mapping " + singleQuoted(mapping) +
              " (expected \"latlong\" or \"octahedral\")");
    }
  }
  if (env.mapping == kEnvironmentOctahedral && env.image.width != env.image.height) {
    fileNode.fail(env.file + " is " + std::to_string(env.image.width) + "x" +
                  std::to_string(env.image.height) +
                  ", not square: an octahedral (equal-area) map is a square");
  }
  double scale = 1.0;
  if (auto n = l.find("scale")) {
    scale = n->number();
    if (!(scale >= 0.0)) n->fail("expected a non-negative number, got " + n->describe());
  }
  for (vec3& c : env.image.pixels) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) {
      fileNode.fail(env.file + " has infinite or not-a-number pixels, no use as a light");
    }
    const glm::dvec3 v = glm::max(glm::dvec3(c), glm::dvec3(0.0)) * scale;
    if (!(float(std::max(v.x, std::max(v.y, v.z))) < 3.4e38f)) {
      l.require("scale").fail("the image's radiance times the scale does not fit a 32-bit float");
    }
    c = vec3(v);
  }
  if (auto n = l.find("rotate")) {
    // The shapes' "rotate" (readTransform): right-handed about the axis, the image's frame into
    // the world.
    Transform t;
    readRotation(*n, t);
    for (int i = 0; i < 3; ++i) {
      glm::dvec3 e(0.0);
      e[i] = 1.0;
      env.toWorld[size_t(i)] = vec3(glm::normalize(t.apply(e)));
    }
  }
  scene.environment = std::move(env);
}

// An "environment" light: an image (readEnvironmentImage) or a constant radiance.
void readEnvironmentLight(const JsonNode& l, const std::filesystem::path& sceneFile, Scene& scene) {
  if (l.find("filename")) {
    readEnvironmentImage(l, sceneFile, scene);
    return;
  }
  l.checkKeys({"type", "radiance"});
  const JsonNode n = l.require("radiance");
  const glm::dvec3 c = n.vec3();
  for (std::size_t k = 0; k < 3; ++k) {
    if (!(c[k] >= 0.0) || !(static_cast<float>(c[k]) < 3.4e38f)) {
      n[k].fail("expected a non-negative number that fits a 32-bit float, got " + n[k].describe());
    }
  }
  Light light{};
  light.type = kLightInfinite;
  light.radiance = glm::vec3(c);
  scene.lights.push_back(light);
}

// "lights": pbrt-v4's point, spot, distant and infinite lights (docs/scene-format.md), in world
// space, with their radiometric quantities given directly.
void readLights(const JsonNode& node, const std::filesystem::path& sceneFile, Scene& scene) {
  node.expectArray();
  for (std::size_t i = 0; i < node.size(); ++i) {
    const JsonNode l = node[i];
    l.expectObject();
    const JsonNode typeNode = l.require("type");
    const std::string type = typeNode.string();
    // A non-negative colour that fits a float.
    const auto colour = [&](const char* key) {
      const JsonNode n = l.require(key);
      const glm::dvec3 c = n.vec3();
      for (std::size_t k = 0; k < 3; ++k) {
        if (!(c[k] >= 0.0) || !(static_cast<float>(c[k]) < 3.4e38f)) {
          n[k].fail("expected a non-negative number that fits a 32-bit float, got " +
                    n[k].describe());
        }
      }
      return glm::vec3(c);
    };
    const auto unit = [&](const JsonNode& n, glm::dvec3 v) {
      const double length = glm::length(v);
      if (!(length > 0.0)) n.fail("has no direction (zero length)");
      return glm::vec3(v / length);
    };
    Light light{};
    if (type == "point" || type == "spot") {
      l.checkKeys(type == "point"
                      ? std::vector<std::string_view>{"type", "position", "intensity"}
                      : std::vector<std::string_view>{"type", "position", "target", "intensity",
                                                      "coneAngle", "coneDeltaAngle"});
      light.type = type == "point" ? kLightPoint : kLightSpot;
      const glm::dvec3 position = l.require("position").vec3();
      light.position = glm::vec3(position);
      light.radiance = colour("intensity");
      if (light.type == kLightSpot) {
        const JsonNode target = l.require("target");
        light.direction = unit(target, target.vec3() - position);
        double cone = 30.0, delta = 5.0;  // pbrt-v4's defaults
        if (auto n = l.find("coneAngle")) {
          cone = n->number();
          if (!(cone > 0.0 && cone <= 180.0)) n->fail("expected degrees in (0, 180]");
        }
        if (auto n = l.find("coneDeltaAngle")) {
          delta = n->number();
          if (!(delta >= 0.0 && delta <= cone)) n->fail("expected degrees in [0, coneAngle]");
        }
        const double pi = 3.14159265358979323846;
        light.cosFalloffEnd = static_cast<float>(std::cos(cone * pi / 180.0));
        light.cosFalloffStart = static_cast<float>(std::cos((cone - delta) * pi / 180.0));
      }
    } else if (type == "distant") {
      l.checkKeys({"type", "direction", "radiance"});
      light.type = kLightDistant;
      const JsonNode direction = l.require("direction");
      light.direction = unit(direction, direction.vec3());
      light.radiance = colour("radiance");
    } else if (type == "environment") {
      readEnvironmentLight(l, sceneFile, scene);
      continue;
    } else {
      typeNode.fail("unknown light type " + singleQuoted(type) +
                    " (expected \"point\", \"spot\", \"distant\" or \"environment\")");
    }
    scene.lights.push_back(light);
  }
}

}  // namespace

namespace scene_detail {

CameraDesc readJsonCamera(const JsonNode& node, const CameraDesc& base) {
  return readCamera(node, base);
}
IntegratorSettings readJsonIntegrator(const JsonNode& node) {
  return readIntegrator(node);
}
void readJsonEnvironment(const JsonNode& node, const std::filesystem::path& sceneFile,
                         Scene& scene) {
  node.expectObject();
  readEnvironmentLight(node, sceneFile, scene);
}

}  // namespace scene_detail

Scene loadJsonScene(const std::filesystem::path& path, const SceneLoadOptions& options) {
  const std::string file = path.string();
  std::string text;
  std::string why;
  if (!scene_detail::readTextFile(path, &text, &why)) {
    scene_detail::throwInputError(file, "", "cannot open scene file (" + why + ")");
  }
  const nlohmann::json document = scene_detail::parseJson(text, file);
  const JsonNode root(document, "", file);
  // A glTF file with what glTF lacks (docs/gltf.md, "A JSON wrapper").
  if (document.is_object() && document.contains("gltf")) {
    return scene_detail::loadGltfWrapper(root, path, options);
  }
  if (!options.camera.empty() || !options.environment.empty()) {
    scene_detail::throwInputError(file, "",
                                  std::string(options.camera.empty() ? "--env" : "--camera") +
                                      " is for glTF files; this is not one");
  }
  root.checkKeys({"description", "camera", "integrator", "textures", "media", "materials", "shapes",
                  "lights"});

  Scene scene;
  if (auto n = root.find("description")) n->string();
  if (auto n = root.find("camera")) scene.camera = readCamera(*n);
  if (auto n = root.find("integrator")) scene.integrator = readIntegrator(*n);
  scene_detail::JsonTextures textures(scene, path.parent_path());
  if (auto n = root.find("textures")) textures.read(*n);
  JsonMedia media(scene);
  if (auto n = root.find("media")) media.read(*n);
  if (auto n = root.find("camera")) scene.cameraMedium = media.find(*n, "medium");
  readMaterials(root.require("materials"), scene, textures);
  readShapes(root.require("shapes"), path, media, scene);
  if (auto n = root.find("lights")) readLights(*n, path, scene);
  padMaterialTextures(scene);
  keepUsedMedia(scene);  // none used: every media field empty
  return scene;
}

}  // namespace pt
