// pbrt-v4's MakeNamedMedium (its media.cpp Create functions: homogeneous, uniformgrid,
// rgbgrid, cloud and nanovdb) and MediumInterface, resolved at the end of the file into
// Scene::media, the triangles' interfaces and the camera's medium.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/check.h"
#include "scene/json_reader.h"
#include "scene/media.h"
#include "scene/pbrt/pbrt_builder.h"

namespace pt::pbrt {

namespace {

constexpr std::string_view kMediumTypes[] = {"cloud", "homogeneous", "nanovdb", "rgbgrid",
                                             "uniformgrid"};

// A float parameter's values as 32-bit floats (too large ones become infinite, which
// checkMedium refuses), or none.
std::vector<float> floats(const Params& p, std::string_view name, ParamType type) {
  std::vector<float> out;
  if (const Param* q = p.find(name, {type})) {
    out.reserve(q->numbers.size());
    for (double v : q->numbers) out.push_back(static_cast<float>(v));
  }
  return out;
}

}  // namespace

void Builder::makeNamedMedium(Statement& s) {
  const std::string& name = s.strings[0];
  const std::string context = "MakeNamedMedium " + singleQuoted(name);
  Params p(*this, s, &gs_.mediumAttributes, context);
  if (const auto it = namedMedia_.find(name); it != namedMedia_.end()) {
    fail(s.location, "named medium " + singleQuoted(name) + " redefined (first at " +
                         it->second.location.fileLine() + ")");
  }
  const Param* t = p.find("type", {ParamType::kString});
  if (t == nullptr) fail(s.location, context + " needs a \"string type\" parameter");
  p.expectCount(*t, 1);
  const std::string& type = t->strings[0];
  NamedMedium entry;
  entry.location = s.location;
  entry.worldFromMedium = gs_.ctm;
  entry.beforeCamera = cameraLocation_.file.empty();

  MediumParams m;
  if (type == "homogeneous") {
    m.type = kMediumHomogeneous;
  } else if (type == "uniformgrid") {
    m.type = kMediumUniformGrid;
  } else if (type == "rgbgrid") {
    m.type = kMediumRgbGrid;
  } else if (type == "nanovdb") {
    m.type = kMediumNanoVdb;
  } else if (type == "cloud") {
    m.type = kMediumCloud;
  } else {
    fail(t->location, context + ": unknown medium type " + singleQuoted(type) +
                          (type == "heterogeneous"
                               ? " (pbrt-v3's name of pbrt-v4's \"uniformgrid\")"
                               : scene_detail::didYouMean(
                                     type, {std::begin(kMediumTypes), std::end(kMediumTypes)})));
  }
  {
    // pbrt-v4's parameters and defaults (media.cpp): sigma_a and sigma_s 1, scale 1, g 0, no
    // emission; grids nx = ny = nz = 1 over p0 (0 0 0) to p1 (1 1 1).
    if (m.type != kMediumCloud) {
      if (auto v = p.number("scale")) m.scale = *v;
    }
    if (auto v = p.number("g")) m.g = *v;
    const auto count = [&](const char* axis, std::int64_t& out) {
      const Param* q = p.find(axis, {ParamType::kInteger});
      if (q == nullptr) return;
      p.expectCount(*q, 1);
      const double v = q->numbers[0];
      if (!(v >= 1.0 && v <= double(std::numeric_limits<int>::max()))) {
        fail(q->location, singleQuoted(axis) + " of " + context +
                              ": expected a number of voxels of at least 1, got " +
                              scene_detail::formatNumber(v));
      }
      out = static_cast<std::int64_t>(v);
    };
    const auto point = [&](const char* key, glm::dvec3& out) {
      const Param* q = p.find(key, {ParamType::kPoint3});
      if (q == nullptr) return;
      p.expectCount(*q, 1, 3);
      out = glm::dvec3(q->numbers[0], q->numbers[1], q->numbers[2]);
    };
    // Le is an illuminant: RGB as it is, a spectrum as its colour at luminance 1 (pbrt-v4
    // divides by its luminance), and a spectrum that is zero everywhere no emission.
    const auto emission = [&] {
      const Param* q = p.find("Le");
      if (q != nullptr && q->type == ParamType::kSpectrum && q->strings.empty()) {
        bool zero = true;
        for (std::size_t i = 1; i < q->numbers.size(); i += 2) zero = zero && q->numbers[i] == 0.0;
        if (zero) return;
      }
      if (auto v = spectrum(p, "Le", Use::kIlluminant)) m.Le = *v;
    };
    if (m.type == kMediumHomogeneous) {
      bool preset = false;
      if (auto name = p.string("preset"); name && !name->empty()) {
        if (const MediumPreset* known = findMediumPreset(*name)) {
          // pbrt-v4 then reads neither sigma_a nor sigma_s (reportUnused warns of them).
          m.sigmaA = known->sigmaA;
          m.sigmaS = known->sigmaPrimeS;
          preset = true;
        } else {
          warnOnce("medium preset " + *name, p.find("preset")->location,
                   context + ": unknown preset " + singleQuoted(*name) +
                       scene_detail::didYouMean(*name, mediumPresetNames()) +
                       " (pbrt-v4 warns too): sigma_a and sigma_s are used");
        }
      }
      if (!preset) {
        if (auto v = spectrum(p, "sigma_a", Use::kUnbounded)) m.sigmaA = *v;
        if (auto v = spectrum(p, "sigma_s", Use::kUnbounded)) m.sigmaS = *v;
      }
      emission();
      if (auto v = p.number("Lescale")) m.LeScale = *v;
    } else if (m.type == kMediumNanoVdb || m.type == kMediumCloud) {
      if (auto v = spectrum(p, "sigma_a", Use::kUnbounded)) m.sigmaA = *v;
      if (auto v = spectrum(p, "sigma_s", Use::kUnbounded)) m.sigmaS = *v;
    }
    if (m.type == kMediumNanoVdb) {
      if (auto v = p.number("Lescale")) m.LeScale = *v;
      // pbrt-v4 reads "temperatureoffset", and "temperaturecutoff" where that is missing.
      if (auto v = p.number("temperaturecutoff")) m.temperatureOffset = *v;
      if (auto v = p.number("temperatureoffset")) m.temperatureOffset = *v;
      if (auto v = p.number("temperaturescale")) m.temperatureScale = *v;
      const Param* file = p.find("filename", {ParamType::kString});
      if (file == nullptr || file->strings.empty() || file->strings[0].empty()) {
        fail(s.location, context + ": a \"nanovdb\" medium needs a \"string filename\"");
      }
      p.expectCount(*file, 1);
      const std::string grid = p.string("gridname").value_or("density");
      const std::string temperature = p.string("temperaturename").value_or("temperature");
      const std::filesystem::path path = resolvePath(file->strings[0], file->location, mainFile_);
      try {
        m.nanovdb =
            std::make_shared<const NanoVdbMediumGrids>(readNanoVdbMedium(path, grid, temperature));
      } catch (const InputError& e) {
        fail(file->location, context + ": " + e.what());
      }
    } else if (m.type == kMediumCloud) {
      if (auto v = p.number("density")) m.cloudDensity = *v;
      if (auto v = p.number("wispiness")) m.wispiness = *v;
      if (auto v = p.number("frequency")) m.frequency = *v;
      point("p0", m.p0);
      point("p1", m.p1);
    } else if (m.type == kMediumUniformGrid || m.type == kMediumRgbGrid) {
      count("nx", m.nx);
      count("ny", m.ny);
      count("nz", m.nz);
      point("p0", m.p0);
      point("p1", m.p1);
      if (m.type == kMediumUniformGrid) {
        if (auto v = spectrum(p, "sigma_a", Use::kUnbounded)) m.sigmaA = *v;
        if (auto v = spectrum(p, "sigma_s", Use::kUnbounded)) m.sigmaS = *v;
        emission();
        m.density = floats(p, "density", ParamType::kFloat);
        m.LeScaleGrid = floats(p, "Lescale", ParamType::kFloat);
        m.temperature = floats(p, "temperature", ParamType::kFloat);
        if (!m.temperature.empty()) {
          // pbrt-v4 reads "temperatureoffset", and "temperaturecutoff" where that is missing.
          if (auto v = p.number("temperaturecutoff")) m.temperatureOffset = *v;
          if (auto v = p.number("temperatureoffset")) m.temperatureOffset = *v;
          if (auto v = p.number("temperaturescale")) m.temperatureScale = *v;
        }
      } else {
        m.sigmaAGrid = floats(p, "sigma_a", ParamType::kRgb);
        m.sigmaSGrid = floats(p, "sigma_s", ParamType::kRgb);
        m.LeGrid = floats(p, "Le", ParamType::kRgb);
        if (auto v = p.number("Lescale")) m.LeScale = *v;
        if (m.sigmaAGrid.empty() != m.sigmaSGrid.empty()) {
          warnOnce("rgbgrid constant", s.location,
                   context +
                       ": the missing one of \"sigma_a\" and \"sigma_s\" is a grid of ones "
                       "(pbrt-v4's is 1 everywhere, also in the half voxel at the bounds' "
                       "faces where a grid's interpolation falls off)");
        }
      }
    }
    if (const std::optional<MediumProblem> problem = checkMedium(m)) {
      const Param* q = p.find(problem->param);
      fail(q != nullptr ? q->location : s.location,
           singleQuoted(problem->param) + " of " + context +
               (problem->index ? ", its value [" + std::to_string(*problem->index) + "]" : "") +
               ": " + problem->message);
    }
  }
  p.reportUnused();
  if (name.empty()) {
    warnOnce("medium ''", s.location,
             context + " ignored: \"\" names the vacuum in MediumInterface, not a medium");
    return;
  }
  entry.index = addMedium(scene_, name, m);
  namedMedia_.emplace(name, entry);
}

void Builder::mediumInterface(const Statement& s) {
  // One name: the same medium on both sides (pbrt-v4's parser).
  const std::size_t second = s.strings.size() > 1 ? 1 : 0;
  MediumNames names{s.strings[0], s.strings[second], s.stringLocations[0],
                    s.stringLocations[second], false};
  if (names.inside.empty() && names.outside.empty()) {
    gs_.mediumInterface = 0;
    return;
  }
  gs_.mediumInterface = mediumInterfaces_.size();
  mediumInterfaces_.push_back(std::move(names));
}

std::vector<MediumInterface> Builder::resolveMedia() {
  const auto find = [&](const std::string& name, const Location& where) {
    if (name.empty()) return kNoMedium;
    const auto it = namedMedia_.find(name);
    if (it == namedMedia_.end()) {
      std::vector<std::string_view> names;
      for (const auto& [known, medium] : namedMedia_) names.push_back(known);
      fail(where, "MediumInterface: no medium named " + singleQuoted(name) +
                      scene_detail::didYouMean(name, names));
    }
    return it->second.index;
  };
  std::vector<MediumInterface> resolved(mediumInterfaces_.size(),
                                        MediumInterface{kNoMedium, kNoMedium});
  for (std::size_t i = 0; i < mediumInterfaces_.size(); ++i) {
    const MediumNames& n = mediumInterfaces_[i];
    if (!n.used) continue;
    resolved[i] =
        MediumInterface{find(n.inside, n.insideLocation), find(n.outside, n.outsideLocation)};
  }
  // The media's transforms into this scene's world, mirrored in x where the camera asked for
  // it (setupCamera): world to medium is the inverse of world-from-medium, after the mirror.
  const glm::dvec3 camera = transformPoint(cameraFromWorld_.inverse, glm::dvec3(0.0));
  glm::dmat4 mirror(1.0);
  if (mirrored_) mirror[0][0] = -1.0;
  for (const auto& [name, medium] : namedMedia_) {
    if (medium.index == kNoMedium) continue;
    Medium& m = scene_.media[medium.index];
    if (m.type == kMediumHomogeneous) continue;  // the same everywhere: no transform
    const glm::dmat4& w = medium.worldFromMedium.m;
    if (w[0][3] != 0.0 || w[1][3] != 0.0 || w[2][3] != 0.0 || w[3][3] != 1.0) {
      warnOnce("medium projective", medium.location,
               "MakeNamedMedium " + singleQuoted(name) +
                   ": the CTM's projective part is ignored (a medium's transform is affine)");
    }
    glm::dmat4 mediumFromWorld = medium.worldFromMedium.inverse;
    if (medium.beforeCamera) mediumFromWorld = mediumFromWorld * translateMatrix(-camera);
    mediumFromWorld = mediumFromWorld * mirror;
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 3; ++r) {
        if (!(std::fabs(mediumFromWorld[c][r]) <= std::numeric_limits<float>::max())) {
          fail(medium.location, "MakeNamedMedium " + singleQuoted(name) +
                                    ": the CTM is singular or too large (a grid medium needs an "
                                    "invertible transform)");
        }
      }
    }
    setMediumTransform(m, mediumFromWorld);
  }
  return resolved;
}

}  // namespace pt::pbrt
