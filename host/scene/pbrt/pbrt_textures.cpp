// pbrt-v4's Texture directive and its textures where materials and shapes use them: built as
// texture programs (scene/textures.h) where simulated, else their mean value.
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "common/check.h"
#include "image/image.h"
#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_builder.h"

namespace pt::pbrt {

namespace fs = std::filesystem;

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
          if (!parseTextureFilter(name, desc.filter)) {
            fail(f->location, "Texture \"imagemap\": unknown \"filter\" " + singleQuoted(name) +
                                  " (expected \"point\", \"bilinear\", \"trilinear\" or "
                                  "\"ewa\")");
          }
        }
        if (const Param* v = textureParamOf(t, "maxanisotropy", ParamType::kFloat)) {
          if (!v->numbers.empty()) {
            desc.maxAnisotropy = static_cast<float>(v->numbers[0]);
            if (!(desc.maxAnisotropy > 0.0f) || !std::isfinite(desc.maxAnisotropy)) {
              fail(v->location,
                   "Texture \"imagemap\": \"maxanisotropy\" must be a positive number");
            }
          }
        }
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

}  // namespace pt::pbrt
