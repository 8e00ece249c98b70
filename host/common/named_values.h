// Name <-> value tables for the enumerated options (direct-light strategy, sampler,
// intersection test, Russian roulette, BVH builder). One table per option serves the scene
// parser, the command line's validation and help text, and the statistics line, so a name
// is spelled in exactly one place.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/shared.h"

namespace pt {

template <typename T>
struct NamedValue {
  std::string_view name;
  T value;
  std::string_view meaning;  // a few words for help texts
};

template <typename T, std::size_t N>
using NameTable = std::array<NamedValue<T>, N>;

// The value called `name`, if any.
template <typename T, std::size_t N>
std::optional<T> valueNamed(const NameTable<T, N>& table, std::string_view name) {
  for (const NamedValue<T>& entry : table) {
    if (entry.name == name) return entry.value;
  }
  return std::nullopt;
}

// The name of `value`; every value an option can take is in its table.
template <typename T, std::size_t N>
std::string_view nameOf(const NameTable<T, N>& table, T value) {
  for (const NamedValue<T>& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}

// The names in table order, e.g. for CLI11's IsMember.
template <typename T, std::size_t N>
std::vector<std::string> namesOf(const NameTable<T, N>& table) {
  std::vector<std::string> names;
  for (const NamedValue<T>& entry : table) names.emplace_back(entry.name);
  return names;
}

// "'a', 'b' or 'c'", for error messages.
template <typename T, std::size_t N>
std::string quotedNames(const NameTable<T, N>& table) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) s += i + 1 == N ? " or " : ", ";
    s += "'" + std::string(table[i].name) + "'";
  }
  return s;
}

// "a (meaning), b (meaning)", for help texts.
template <typename T, std::size_t N>
std::string describeNames(const NameTable<T, N>& table) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) s += ", ";
    s += std::string(table[i].name) + " (" + std::string(table[i].meaning) + ")";
  }
  return s;
}

// ---- The tables (the BVH builder's is in bvh/bvh.h) --------------------------------------

inline constexpr NameTable<uint, 3> kStrategyNames{{
    {"mis", kStrategyMis, "light and BSDF sampling, power heuristic"},
    {"nee", kStrategyNee, "light sampling only"},
    {"bsdf", kStrategyBsdf, "BSDF sampling only, no shadow rays"},
}};

// The light transport algorithms (pbrt-v4's Integrator types of the same names).
inline constexpr uint kIntegratorPath = 0;  // path tracing: light and BSDF sampling, MIS
inline constexpr uint kIntegratorBdpt = 1;  // bidirectional path tracing (docs/bdpt.md)
inline constexpr uint kIntegratorSppm = 2;  // stochastic progressive photon mapping (both
                                            // backends, docs/sppm.md): consistent, not unbiased

inline constexpr NameTable<uint, 3> kIntegratorNames{{
    {"path", kIntegratorPath, "path tracing with light and BSDF sampling"},
    {"bdpt", kIntegratorBdpt, "bidirectional path tracing (CPU)"},
    {"sppm", kIntegratorSppm, "stochastic progressive photon mapping (consistent, biased)"},
}};

inline constexpr NameTable<uint, 3> kLightSamplerNames{{
    {"bvh", kLightSamplerBvh, "pbrt-v4's light BVH: by importance at the shading point"},
    {"power", kLightSamplerPower, "by power"},
    {"uniform", kLightSamplerUniform, "every light alike"},
}};

inline constexpr NameTable<uint, 2> kSamplerNames{{
    {"independent", kSamplerIndependent, "a hash per sample"},
    {"sobol", kSamplerSobol, "Owen-scrambled Sobol points"},
}};

// The value is RenderParams::fastIntersection.
inline constexpr NameTable<bool, 2> kIntersectionNames{{
    {"watertight", false, "Woop et al. 2013"},
    {"fast", true, "Moller-Trumbore, leaks between triangles"},
}};

inline constexpr NameTable<bool, 2> kRouletteNames{{
    {"on", true, "Russian roulette ends paths of low throughput"},
    {"off", false, "paths run to the maximum depth"},
}};

}  // namespace pt
