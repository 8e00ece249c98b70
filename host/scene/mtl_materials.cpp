// MTL materials; see mtl_materials.h. tinyobjloader parses the file; this maps its values.
#include "scene/mtl_materials.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include <tiny_obj_loader.h>

#include "scene/json_reader.h"

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

}  // namespace

std::vector<MtlMaterial> loadMtlMaterials(const std::string& text, const std::string& file) {
  std::map<std::string, int> byName;
  std::vector<tinyobj::material_t> parsed;
  std::string warn, err;
  std::istringstream stream(text);
  tinyobj::LoadMtl(&byName, &parsed, &stream, &warn, &err);

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
    const bool mirror =
        m.illum == 3 || m.illum == 5 || (m.shininess >= 1000.0f && ksMax > 0.0f && ksMax >= kdMax);
    Material& material = out.material;
    material.emission = ke;
    material.reserved = 0;
    if (mirror) {
      material.type = kMaterialMirror;
      material.reflectance = ksMax > 0.0f ? ks : vec3(1.0f);
      if (kdMax > 0.0f) {
        out.warnings.push_back(prefix + "diffuse part Kd " + describe(kd) +
                               " is not simulated beside the mirror; rendered as a mirror of "
                               "reflectance " +
                               describe(material.reflectance));
      }
    } else {
      material.type = kMaterialDiffuse;
      material.reflectance = kd;
      if (ksMax > 0.0f) {
        out.warnings.push_back(prefix + "glossy highlight Ks " + describe(ks) + ", Ns " +
                               shortest(m.shininess) +
                               " is not simulated; rendered as diffuse with Kd " + describe(kd));
      }
    }
    const bool refracts = m.illum == 4 || m.illum == 6 || m.illum == 7 || m.illum == 9;
    if (refracts || m.dissolve < 1.0f) {
      out.warnings.push_back(prefix + "transparency/refraction (illum " + std::to_string(m.illum) +
                             ", d " + shortest(m.dissolve) +
                             ") is not simulated; rendered as an opaque " +
                             (mirror ? "mirror" : "diffuse surface"));
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
