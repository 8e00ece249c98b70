// MTL materials; see mtl_materials.h. tinyobjloader parses the file; this maps its values.
#include "scene/mtl_materials.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include <tiny_obj_loader.h>

#include "common/check.h"
#include "scene/json_reader.h"
#include "scene/reader_helpers.h"
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

// The lines of a material's first definition: each line's keyword and the rest of the line
// after it and its blanks, in file order.
struct MtlBlock {
  std::vector<std::pair<std::string, std::string>> lines;
  bool has(std::string_view keyword) const {
    for (const auto& [k, rest] : lines) {
      if (k == keyword) return true;
    }
    return false;
  }
  // The last line of one of these keywords (tinyobjloader keeps the last), or null.
  const std::pair<std::string, std::string>* last(
      std::initializer_list<std::string_view> keywords) const {
    for (auto it = lines.rbegin(); it != lines.rend(); ++it) {
      for (std::string_view k : keywords) {
        if (it->first == k) return &*it;
      }
    }
    return nullptr;
  }
};

// The lines of each material's first definition: tinyobjloader reads a missing Ni as 1, which
// for glass would mean no refraction at all, a missing Kd beside a map_Kd as 0.6 or 0 (by
// whether an earlier material of the file had a Kd line), and a map's options its own way
// (`-s u v file` takes the file name for w and loses the map; `-cc` is taken as the file
// name). Lines and names are split as tinyobjloader splits them (lines end at \n, \r or \r\n;
// a keyword is followed by a blank; the name is the rest of the newmtl line after one blank),
// so that the names match its.
std::map<std::string, MtlBlock> blocksByName(const std::string& text) {
  std::map<std::string, MtlBlock> blocks;
  MtlBlock* current = nullptr;  // the block being read, if a first definition
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
    const std::size_t blank = token.find_first_of(" \t");
    if (blank == std::string_view::npos) continue;
    const std::string_view keyword = token.substr(0, blank);
    if (keyword == "newmtl") {
      const auto [it, first] = blocks.emplace(std::string(token.substr(7)), MtlBlock{});
      current = first ? &it->second : nullptr;
    } else if (current) {
      std::string_view rest = token.substr(blank);
      rest.remove_prefix(std::min(rest.size(), rest.find_first_not_of(" \t")));
      current->lines.emplace_back(std::string(keyword), std::string(rest));
    }
  }
  return blocks;
}

// A map statement's options and file name (the rest of the line after the options, blanks
// and all), as the MTL format has them: -s and -o take one to three numbers, -mm one or two,
// -clamp, -blendu, -blendv and -cc on or off (on where neither follows). A number or word is
// an option's argument only when something follows it, so that the file name is never taken.
struct MapLine {
  std::string file;
  float scale[2] = {1.0f, 1.0f};
  float offset[2] = {0.0f, 0.0f};
  bool clamp = false;
  float bm = 1.0f;
  std::string colorspace;
  std::vector<std::string> ignored;  // options given that change what the map means
};

MapLine parseMapLine(const std::string& rest) {
  MapLine out;
  std::size_t pos = 0;
  // The next blank-separated word from pos, and where the one after it starts; empty at the
  // end or where it is the last word (the file name).
  const auto peek = [&](std::size_t from, std::size_t* after) -> std::string {
    const std::size_t start = rest.find_first_not_of(" \t", from);
    if (start == std::string::npos) return {};
    const std::size_t end = std::min(rest.size(), rest.find_first_of(" \t", start));
    const std::size_t next = rest.find_first_not_of(" \t", end);
    if (next == std::string::npos) return {};  // the last word: the file name
    *after = next;
    return rest.substr(start, end - start);
  };
  const auto number = [&](float* value) {
    std::size_t after = 0;
    const std::string word = peek(pos, &after);
    if (word.empty()) return false;
    char* end = nullptr;
    const double v = std::strtod(word.c_str(), &end);
    if (end != word.c_str() + word.size()) return false;
    // Beyond float's range: infinite (a plain conversion would be undefined), for the checks.
    *value = std::fabs(v) <= double(std::numeric_limits<float>::max())
                 ? static_cast<float>(v)
                 : (std::isnan(v) ? std::numeric_limits<float>::quiet_NaN()
                                  : std::copysign(std::numeric_limits<float>::infinity(),
                                                  float(v > 0 ? 1 : -1)));
    pos = after;
    return true;
  };
  const auto onOff = [&](bool* value) {
    std::size_t after = 0;
    const std::string word = peek(pos, &after);
    if (word == "on" || word == "off") {
      *value = word == "on";
      pos = after;
    } else {
      *value = true;
    }
  };
  const auto word = [&](std::string* value) {
    std::size_t after = 0;
    *value = peek(pos, &after);
    if (!value->empty()) pos = after;
  };
  while (true) {
    std::size_t after = 0;
    const std::string option = peek(pos, &after);
    if (option.empty() || option[0] != '-') break;
    const auto ignore = [&](const std::string& name) {
      if (std::find(out.ignored.begin(), out.ignored.end(), name) == out.ignored.end()) {
        out.ignored.push_back(name);
      }
    };
    const std::size_t optionStart = pos;
    pos = after;
    float unused[3];
    bool flag = false;
    std::string text;
    if (option == "-s" || option == "-o") {
      float* v = option == "-s" ? out.scale : out.offset;
      if (number(&v[0]) && number(&v[1])) number(&unused[0]);
    } else if (option == "-t") {
      if (number(&unused[0]) && number(&unused[1])) number(&unused[2]);
      ignore(option);
    } else if (option == "-bm") {
      number(&out.bm);
    } else if (option == "-mm") {
      if (number(&unused[0])) number(&unused[1]);
      ignore(option);
    } else if (option == "-boost" || option == "-texres") {
      number(&unused[0]);
      ignore(option);
    } else if (option == "-clamp") {
      onOff(&out.clamp);
    } else if (option == "-blendu" || option == "-blendv" || option == "-cc") {
      onOff(&flag);
      // -blendu on, -blendv on and -cc off are the defaults: nothing ignored.
      if (flag == (option == "-cc")) ignore(option);
    } else if (option == "-imfchan" || option == "-type") {
      word(&text);
      ignore(option);
    } else if (option == "-colorspace") {
      word(&out.colorspace);
    } else {
      pos = optionStart;  // not an option: the file name starts here
      break;
    }
  }
  const std::size_t start = rest.find_first_not_of(" \t", pos);
  if (start != std::string::npos) out.file = rest.substr(start);
  return out;
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
  const std::map<std::string, MtlBlock> blocks = blocksByName(text);
  const std::filesystem::path directory = std::filesystem::path(file).parent_path();

  std::vector<MtlMaterial> result;
  std::set<std::string> seen;
  for (const tinyobj::material_t& m : parsed) {
    // tinyobjloader flushes an unnamed default material at the end; later duplicates of a
    // name lose, as in its own name map.
    if (m.name.empty() || !seen.insert(m.name).second) continue;
    const std::string where = "material " + singleQuoted(m.name);
    auto fail = [&](const std::string& field, const std::string& problem) {
      throwInputError(file, where + ": " + field, problem);
    };
    const auto found = blocks.find(m.name);
    const MtlBlock* block = found == blocks.end() ? nullptr : &found->second;
    const auto has = [&](const char* keyword) { return block && block->has(keyword); };
    using Line = std::pair<std::string, std::string>;  // keyword, the rest
    const auto line = [&](std::initializer_list<std::string_view> keywords) -> const Line* {
      return block ? block->last(keywords) : nullptr;
    };
    const Line* const kdLine = line({"map_Kd"});
    const Line* const alphaLine = line({"map_d"});
    vec3 kd = toVec3(m.diffuse);
    const vec3 ks = toVec3(m.specular), ke = toVec3(m.emission);
    const bool hasKd = has("Kd");
    // tinyobjloader's default Kd beside a map_Kd, whatever came before in the file.
    if (kdLine && !hasKd) kd = vec3(0.6f);
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
    // What map_Kd and map_Ks texture: the factor of the image, or none.
    std::optional<vec3> kdMap, ksMap;
    if (glass) {
      float eta = 1.5f;
      if (has("Ni")) {
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
      ksMap = material.reflectance;
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
        kdMap = kd;
        became = "coated diffuse surface";
      } else {
        material = defaultMaterial(kMaterialConductor);
        setConductorReflectance(material, ks);
        ksMap = ks;
        became = "rough conductor";
      }
      material.alphaX = alpha;
      material.alphaY = alpha;
    } else {
      material = defaultMaterial(kMaterialDiffuse);
      material.reflectance = kd;
      kdMap = kd;
      became = "diffuse surface";
    }
    material.emission = ke;
    const bool alphaMap = alphaLine != nullptr;
    if (!glass && (m.illum == 9 || (m.dissolve < 1.0f && !alphaMap))) {
      out.warnings.push_back(prefix + "transparency (illum " + std::to_string(m.illum) + ", d " +
                             shortest(m.dissolve) +
                             ") is not simulated without illum 4, 6 or 7; rendered as an opaque " +
                             became);
    }

    // The maps, in the order of MaterialTextures.
    const auto addMap = [&](const Line* mapLine, MtlMap::Target target, std::optional<vec3> factor,
                            const std::string& notUsed) {
      if (!mapLine) return;
      const std::string& statement = mapLine->first;
      const MapLine parsed = parseMapLine(mapLine->second);
      const std::string field = statement + " " + quotedPath(parsed.file);
      if (!factor) {
        out.warnings.push_back(prefix + field + " is not simulated for a " + became + " (" +
                               notUsed + "); ignored");
        return;
      }
      if (parsed.file.empty()) fail(statement, "no image file name after the options");
      if (!parsed.ignored.empty()) {
        std::string list;
        for (const std::string& o : parsed.ignored) list += (list.empty() ? "" : ", ") + o;
        out.warnings.push_back(
            prefix + field + ": option" + (parsed.ignored.size() > 1 ? "s " : " ") + list +
            (parsed.ignored.size() > 1 ? " are" : " is") + " not simulated; ignored");
      }
      MtlMap map;
      map.target = target;
      map.statement = statement;
      map.file = parsed.file;
      map.isFloat = target != MtlMap::Target::kReflectance;
      map.factor = *factor;
      ImageTextureDesc& desc = map.desc;
      desc.filename = directory / parsed.file;
      // Colours are stored in sRGB (pbrt-v4's default); alpha and bump maps as numbers.
      desc.encoding = map.isFloat ? "linear" : "sRGB";
      if (!parsed.colorspace.empty()) {
        double gamma = 0.0;
        if (!parseColorEncoding(parsed.colorspace, gamma)) {
          fail(field,
               "-colorspace: expected 'sRGB' or 'linear', got " + singleQuoted(parsed.colorspace));
        }
        desc.encoding = parsed.colorspace;
      }
      for (const auto& [option, v] :
           {std::pair{"-s", parsed.scale}, std::pair{"-o", parsed.offset}}) {
        if (!std::isfinite(v[0]) || !std::isfinite(v[1])) {
          fail(field, std::string(option) + ": expected finite numbers, got " + shortest(v[0]) +
                          " " + shortest(v[1]));
        }
      }
      desc.mapping = vec4(parsed.scale[0], parsed.scale[1], parsed.offset[0], parsed.offset[1]);
      desc.wrap = parsed.clamp ? kWrapClamp : kWrapRepeat;
      if (target == MtlMap::Target::kDisplacement) {
        if (!std::isfinite(parsed.bm)) {
          fail(field, "-bm: expected a finite number, got " + shortest(parsed.bm));
        }
        desc.scale = parsed.bm;
      }
      out.maps.push_back(std::move(map));
    };
    // map_Kd and map_Ks multiply the colour they texture, as the MTL convention has it; where
    // the material has no Kd line, the image alone.
    if (kdMap && !hasKd) kdMap = vec3(1.0f);
    const std::string noColour = glass ? "a glass is clear" : "it has no parameter for ";
    addMap(kdLine, MtlMap::Target::kReflectance, kdMap, glass ? noColour : noColour + "Kd");
    addMap(line({"map_Ks"}), MtlMap::Target::kReflectance, ksMap,
           glass                                     ? noColour
           : material.type == kMaterialCoatedDiffuse ? "its coat has no colour"
                                                     : noColour + "Ks");
    std::optional<vec3> alphaFactor = vec3(1.0f);
    if (alphaLine && !glass && m.dissolve < 1.0f) {
      if (!(m.dissolve >= 0.0f)) {
        fail("d", "expected a number in [0, 1] to multiply map_d, got " + shortest(m.dissolve));
      }
      alphaFactor = vec3(m.dissolve);
    }
    addMap(alphaLine, MtlMap::Target::kAlpha, alphaFactor, "");
    addMap(line({"map_Bump", "map_bump", "bump"}), MtlMap::Target::kDisplacement, vec3(1.0f), "");
    // Each other map tinyobjloader knows: one warning each.
    for (const std::initializer_list<std::string_view> keywords :
         {std::initializer_list<std::string_view>{"map_Ka"},
          {"map_Ns"},
          {"disp", "map_disp", "map_Disp"},
          {"refl"},
          {"map_Pr"},
          {"map_Pm"},
          {"map_Ps"},
          {"map_Ke"},
          {"norm"}}) {
      if (const Line* other = line(keywords)) {
        out.warnings.push_back(prefix + other->first + " " +
                               quotedPath(parseMapLine(other->second).file) +
                               " is not simulated; the constant values are used");
      }
    }
    result.push_back(std::move(out));
  }
  return result;
}

MaterialTextures buildMtlTextures(const MtlMaterial& m, const std::string& file,
                                  TextureBuilder& builder, Scene& scene) {
  MaterialTextures textures = noMaterialTextures();
  for (const MtlMap& map : m.maps) {
    uint texture = kNoTexture;
    try {
      texture = builder.image(map.desc, map.isFloat);
    } catch (const InputError& e) {
      throwInputError(
          file,
          "material " + singleQuoted(m.name) + ": " + map.statement + " " + quotedPath(map.file),
          e.what());
    }
    // An image node's value multiplies its lookup per channel (texture.h's imageLookup: the
    // pbrt-v4 "scale", here a colour): Kd, Ks or d times the image, bm included.
    scene.textureNodes[texture].value *= map.factor;
    switch (map.target) {
      case MtlMap::Target::kReflectance:
        textures.reflectance = texture;
        break;
      case MtlMap::Target::kAlpha:
        textures.alpha = texture;
        break;
      case MtlMap::Target::kDisplacement:
        textures.displacement = texture;
        break;
    }
  }
  return textures;
}

}  // namespace pt::scene_detail
