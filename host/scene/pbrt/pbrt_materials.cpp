// pbrt-v4's Material and MakeNamedMaterial (its materials.cpp Create functions), and the
// scene's material slots resolved at the end. Texture and spectrum values are read elsewhere.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/check.h"
#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_builder.h"
#include "scene/pbrt/spectra.h"
#include "scene/reader_helpers.h"

namespace pt::pbrt {

namespace {

constexpr int kMaxMixDepth = 16;  // mix materials naming mix materials, at most this deep

// A single index of refraction from an RGB one: the value itself when the channels agree
// (a "float eta"), so that it is not rounded by the mean.
float meanIndex(vec3 eta) {
  if (eta.x == eta.y && eta.y == eta.z) return eta.x;
  return (eta.x + eta.y + eta.z) / 3.0f;
}

}  // namespace

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

}  // namespace pt::pbrt
