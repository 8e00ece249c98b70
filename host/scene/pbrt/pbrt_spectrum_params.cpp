// Spectrum parameters as RGB: "rgb", "blackbody", "spectrum" (named or listed) and textures
// resolved to constants (the spectra's maths is scene/pbrt/spectra.h's).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/check.h"
#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_builder.h"
#include "scene/pbrt/spectra.h"

namespace pt::pbrt {

namespace fs = std::filesystem;

using scene_detail::quotedPath;

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

}  // namespace pt::pbrt
