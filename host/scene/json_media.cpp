// The JSON format's "media" (json_media.h): each medium's keys read under pbrt-v4's names,
// checked by the rules both readers share (scene/media.h), and stored in the Scene.
#include "scene/json_media.h"

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/check.h"
#include "scene/json_transform.h"
#include "scene/media.h"

namespace pt::scene_detail {

namespace {

constexpr std::int64_t kMaxVoxels = std::numeric_limits<int>::max();

// The keys a medium of `type` takes.
std::vector<std::string_view> mediumKeys(uint type) {
  if (type == kMediumNanoVdb) {
    return {"name",
            "type",
            "sigma_a",
            "sigma_s",
            "scale",
            "g",
            "Lescale",
            "filename",
            "gridname",
            "temperaturename",
            "temperatureoffset",
            "temperaturescale",
            "transform"};
  }
  if (type == kMediumCloud) {
    return {"name",      "type",      "sigma_a", "sigma_s", "g",        "density",
            "wispiness", "frequency", "p0",      "p1",      "transform"};
  }
  std::vector<std::string_view> keys = {"name",  "type", "sigma_a", "sigma_s",
                                        "scale", "g",    "Le",      "Lescale"};
  if (type == kMediumHomogeneous) {
    keys.push_back("preset");
  } else {
    keys.insert(keys.end(), {"nx", "ny", "nz", "p0", "p1", "transform"});
    if (type == kMediumUniformGrid) {
      keys.insert(keys.end(), {"density", "temperature", "temperatureoffset", "temperaturescale"});
    }
  }
  return keys;
}

// An array of numbers that fit a float.
std::vector<float> readFloats(const JsonNode& n) {
  n.expectArray();
  std::vector<float> out;
  out.reserve(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) out.push_back(static_cast<float>(n[i].floatNumber()));
  return out;
}

// An array of [r, g, b] colours, flattened.
std::vector<float> readColours(const JsonNode& n) {
  n.expectArray();
  std::vector<float> out;
  out.reserve(3 * n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    const glm::dvec3 c = n[i].vec3();
    for (int k = 0; k < 3; ++k) out.push_back(static_cast<float>(c[k]));
  }
  return out;
}

}  // namespace

void JsonMedia::read(const JsonNode& node) {
  node.expectArray();
  std::map<std::string, std::size_t> firstIndex;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const JsonNode m = node[i];
    m.expectObject();
    const JsonNode typeNode = m.require("type");
    const std::string type = typeNode.string();
    MediumParams p;
    if (type == "homogeneous") {
      p.type = kMediumHomogeneous;
    } else if (type == "uniformgrid") {
      p.type = kMediumUniformGrid;
    } else if (type == "rgbgrid") {
      p.type = kMediumRgbGrid;
    } else if (type == "nanovdb") {
      p.type = kMediumNanoVdb;
    } else if (type == "cloud") {
      p.type = kMediumCloud;
    } else {
      typeNode.fail("unknown medium type " + singleQuoted(type) +
                    " (expected \"homogeneous\", \"uniformgrid\", \"rgbgrid\", \"nanovdb\" "
                    "or \"cloud\")");
    }
    m.checkKeys(mediumKeys(p.type));
    const JsonNode nameNode = m.require("name");
    const std::string name = nameNode.string();
    if (name.empty()) nameNode.fail("must not be empty");
    if (auto [it, inserted] = firstIndex.emplace(name, i); !inserted) {
      nameNode.fail("duplicate medium name " + singleQuoted(name) + " (also used by media[" +
                    std::to_string(it->second) + "])");
    }

    // pbrt-v4's defaults (scene/media.h): sigma_a, sigma_s 1, scale 1, g 0, no emission.
    const bool rgb = p.type == kMediumRgbGrid;
    if (auto n = m.find("scale")) p.scale = n->floatNumber();
    if (auto n = m.find("g")) p.g = n->floatNumber();
    if (auto n = m.find("preset")) {
      const std::string preset = n->string();
      const MediumPreset* known = findMediumPreset(preset);
      if (known == nullptr) {
        n->fail("unknown preset " + singleQuoted(preset) + didYouMean(preset, mediumPresetNames()));
      }
      if (m.find("sigma_a") || m.find("sigma_s")) {
        n->fail("give a preset or sigma_a and sigma_s, not both");
      }
      p.sigmaA = known->sigmaA;
      p.sigmaS = known->sigmaPrimeS;
    }
    if (rgb) {
      if (auto n = m.find("sigma_a")) p.sigmaAGrid = readColours(*n);
      if (auto n = m.find("sigma_s")) p.sigmaSGrid = readColours(*n);
      if (auto n = m.find("Le")) p.LeGrid = readColours(*n);
    } else {
      if (auto n = m.find("sigma_a")) p.sigmaA = vec3(n->vec3());
      if (auto n = m.find("sigma_s")) p.sigmaS = vec3(n->vec3());
      if (auto n = m.find("Le")) p.Le = vec3(n->vec3());
    }
    if (p.type == kMediumNanoVdb || p.type == kMediumUniformGrid) {
      if (auto n = m.find("temperatureoffset")) p.temperatureOffset = n->floatNumber();
      if (auto n = m.find("temperaturescale")) p.temperatureScale = n->floatNumber();
    }
    if (p.type == kMediumNanoVdb) {
      const JsonNode fileNode = m.require("filename");
      const std::filesystem::path given(fileNode.string());
      if (given.empty()) fileNode.fail("expected a file name");
      const std::filesystem::path path =
          given.is_absolute() ? given : std::filesystem::path(m.file()).parent_path() / given;
      const std::string grid = m.find("gridname") ? m.find("gridname")->string() : "density";
      const std::string temperature =
          m.find("temperaturename") ? m.find("temperaturename")->string() : "temperature";
      try {
        p.nanovdb =
            std::make_shared<const NanoVdbMediumGrids>(readNanoVdbMedium(path, grid, temperature));
      } catch (const InputError& e) {
        fileNode.fail(e.what());
      }
    }
    if (p.type == kMediumCloud) {
      if (auto n = m.find("density")) p.cloudDensity = n->floatNumber();
      if (auto n = m.find("wispiness")) p.wispiness = n->floatNumber();
      if (auto n = m.find("frequency")) p.frequency = n->floatNumber();
      if (auto n = m.find("p0")) p.p0 = n->vec3();
      if (auto n = m.find("p1")) p.p1 = n->vec3();
    }
    if (auto n = m.find("Lescale")) {
      if (p.type == kMediumUniformGrid) {
        p.LeScaleGrid = readFloats(*n);  // one per voxel, as pbrt-v4's
      } else {
        p.LeScale = n->floatNumber();
      }
    }
    if (p.type == kMediumUniformGrid || p.type == kMediumRgbGrid) {
      if (auto n = m.find("nx")) p.nx = n->integer(1, kMaxVoxels);
      if (auto n = m.find("ny")) p.ny = n->integer(1, kMaxVoxels);
      if (auto n = m.find("nz")) p.nz = n->integer(1, kMaxVoxels);
      if (auto n = m.find("p0")) p.p0 = n->vec3();
      if (auto n = m.find("p1")) p.p1 = n->vec3();
      if (auto n = m.find("density")) p.density = readFloats(*n);
      if (auto n = m.find("temperature")) p.temperature = readFloats(*n);
    }
    if (const std::optional<MediumProblem> problem = checkMedium(p)) {
      const std::optional<JsonNode> n = m.find(problem->param);
      if (!n) m.fail(singleQuoted(problem->param) + ": " + problem->message);
      if (!problem->index) n->fail(problem->message);
      const std::size_t k = *problem->index;
      const bool colours = rgb && problem->param != "Lescale";
      (colours ? (*n)[k / 3][k % 3] : (*n)[k]).fail(problem->message);
    }
    const uint index = addMedium(scene_, name, p);
    if (auto n = m.find("transform")) {
      const glm::dmat4 mediumFromWorld = readTransform(*n).inverseMatrix();
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 3; ++r) {
          if (!(std::fabs(mediumFromWorld[c][r]) <= std::numeric_limits<float>::max())) {
            n->fail("its inverse does not fit 32-bit floats (a scale too close to 0)");
          }
        }
      }
      setMediumTransform(scene_.media[index], mediumFromWorld);
    }
    index_.emplace(name, index);
  }
}

uint JsonMedia::find(const JsonNode& parent, std::string_view key) const {
  const std::optional<JsonNode> n = parent.find(key);
  if (!n) return kNoMedium;
  const std::string name = n->string();
  if (name.empty()) n->fail("expected a medium's name (leave the key out for vacuum)");
  const auto it = index_.find(name);
  if (it == index_.end()) {
    std::vector<std::string_view> names;
    for (const auto& [known, index] : index_) names.push_back(known);
    n->fail("unknown medium " + singleQuoted(name) + didYouMean(name, names));
  }
  return it->second;
}

}  // namespace pt::scene_detail
