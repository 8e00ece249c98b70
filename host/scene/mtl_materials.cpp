// MTL materials; see mtl_materials.h. tinyobjloader parses the file; this maps its values.
#include "scene/mtl_materials.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <string_view>

#include <tiny_obj_loader.h>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace pt::scene_detail {
namespace {

vec3 toVec3(const tinyobj::real_t (&c)[3]) {
  return vec3(float(c[0]), float(c[1]), float(c[2]));
}

// Shortest decimal that reads back as the same float: "0.1", not "0.100000001".
std::string shortest(float v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
  return ec == std::errc() ? std::string(buffer, end) : "?";
}

std::string describe(vec3 c) {
  return "(" + shortest(c.x) + ", " + shortest(c.y) + ", " + shortest(c.z) + ")";
}

// The names of the materials whose first definition has an Ni line: tinyobjloader reads a
// missing Ni as 1, which for glass would mean no refraction at all. Lines and names are split
// as tinyobjloader splits them (lines end at \n, \r or \r\n; the name is the rest of the
// newmtl line after one blank), so that the names match its.
std::set<std::string> namesWithNi(const std::string& text) {
  std::set<std::string> defined, withNi;
  const std::string* current = nullptr;  // the block being read, if it is a first definition
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    line.erase(line.find_last_not_of(" \t") + 1);
    line.resize(std::strlen(line.c_str()));  // tinyobjloader reads the line as a C string
    const std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos) continue;
    const std::string_view token = std::string_view(line).substr(start);
    const auto blank = [&](std::size_t i) {
      return token.size() > i && (token[i] == ' ' || token[i] == '\t');
    };
    if (token.rfind("newmtl", 0) == 0 && blank(6)) {
      const auto [it, first] = defined.emplace(token.substr(7));
      current = first ? &*it : nullptr;
    } else if (token.rfind("Ni", 0) == 0 && blank(2) && current) {
      withNi.insert(*current);
    }
  }
  return withNi;
}

}  // namespace

float phongExponentToAlpha(float ns) {
  return static_cast<float>(std::sqrt(2.0 / (static_cast<double>(ns) + 2.0)));
}

std::vector<MtlMaterial> loadMtlMaterials(const std::string& text, const std::string& file) {
  std::map<std::string, int> byName;
  std::vector<tinyobj::material_t> parsed;
  std::string warn, err;
  std::istringstream stream(text);
  tinyobj::LoadMtl(&byName, &parsed, &stream, &warn, &err);
  const std::set<std::string> withNi = namesWithNi(text);

  std::vector<MtlMaterial> result;
  std::set<std::string> seen;
  for (const tinyobj::material_t& m : parsed) {
    // tinyobjloader flushes an unnamed default material at the end; later duplicates of a
    // name lose, as in its own name map.
    if (m.name.empty() || !seen.insert(m.name).second) continue;
    const std::string where = "material " + singleQuoted(m.name);
    auto fail = [&](const char* field, const std::string& problem) {
      throwInputError(file, where + ": " + field, problem);
    };
    const vec3 kd = toVec3(m.diffuse), ks = toVec3(m.specular), ke = toVec3(m.emission);
    for (const auto& [field, c] : {std::pair{"Kd", kd}, std::pair{"Ks", ks}}) {
      for (int i = 0; i < 3; ++i) {
        if (!(c[i] >= 0.0f && c[i] <= 1.0f)) {
          fail(field, "expected colour components in [0, 1], got " + describe(c));
        }
      }
    }
    for (int i = 0; i < 3; ++i) {
      if (!(ke[i] >= 0.0f && std::isfinite(ke[i]))) {
        fail("Ke", "expected non-negative finite emission, got " + describe(ke));
      }
    }

    MtlMaterial out;
    out.name = m.name;
    const std::string prefix = file + ": " + where + ": ";
    const float kdMax = std::max({kd.x, kd.y, kd.z});
    const float ksMax = std::max({ks.x, ks.y, ks.z});
    const bool glass = m.illum == 4 || m.illum == 6 || m.illum == 7;
    const bool mirror = !glass && (m.illum == 3 || m.illum == 5 ||
                                   (m.shininess >= 1000.0f && ksMax > 0.0f && ksMax >= kdMax));
    const bool glossy = !glass && !mirror && ksMax > 0.0f;
    Material& material = out.material;
    std::string became;  // for the warnings: what the material is rendered as
    if (glass) {
      float eta = 1.5f;
      if (withNi.count(m.name)) {
        eta = m.ior;
        if (!(eta > 0.0f && std::isfinite(eta))) {
          fail("Ni", "expected a positive finite index of refraction for a glass (illum " +
                         std::to_string(m.illum) + "), got " + shortest(eta));
        }
      }
      material = defaultMaterial(kMaterialDielectric);
      material.eta.x = eta;
      became = "glass";
    } else if (mirror) {
      material = defaultMaterial(kMaterialMirror);
      material.reflectance = ksMax > 0.0f ? ks : vec3(1.0f);
      became = "mirror";
      if (kdMax > 0.0f) {
        out.warnings.push_back(prefix + "diffuse part Kd " + describe(kd) +
                               " is not simulated beside the mirror; rendered as a mirror of "
                               "reflectance " +
                               describe(material.reflectance));
      }
    } else if (glossy) {
      // Infinity is allowed: it gives alpha 0, a smooth surface.
      if (!(m.shininess >= 0.0f)) {
        fail("Ns", "expected a non-negative specular exponent, got " + shortest(m.shininess));
      }
      const float alpha = phongExponentToAlpha(m.shininess);
      if (kdMax > 0.0f) {
        // Plastic, paint, varnish: a diffuse base under a clear coat whose Fresnel reflection
        // is the highlight (Ks's colour and strength are not kept).
        material = defaultMaterial(kMaterialCoatedDiffuse);
        material.reflectance = kd;
        became = "coated diffuse surface";
      } else {
        material = defaultMaterial(kMaterialConductor);
        setConductorReflectance(material, ks);
        became = "rough conductor";
      }
      material.alphaX = alpha;
      material.alphaY = alpha;
    } else {
      material = defaultMaterial(kMaterialDiffuse);
      material.reflectance = kd;
      became = "diffuse surface";
    }
    material.emission = ke;
    if (!glass && (m.illum == 9 || m.dissolve < 1.0f)) {
      out.warnings.push_back(prefix + "transparency (illum " + std::to_string(m.illum) + ", d " +
                             shortest(m.dissolve) +
                             ") is not simulated without illum 4, 6 or 7; rendered as an opaque " +
                             became);
    }
    if (!m.diffuse_texname.empty() || !m.specular_texname.empty() || !m.bump_texname.empty() ||
        !m.alpha_texname.empty() || !m.emissive_texname.empty()) {
      out.warnings.push_back(prefix +
                             "texture maps are not simulated; the constant colours are used");
    }
    result.push_back(std::move(out));
  }
  return result;
}

}  // namespace pt::scene_detail
