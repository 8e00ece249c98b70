// What every scene reader shares when it builds a Scene: material defaults and conversions,
// exact rotations, appending triangles. Messages and file access are scene/json_reader.h's.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "common/huge_pages.h"
#include "common/shared.h"
#include "scene/scene.h"

namespace pt {

// A material of type `type` (kMaterial*) with the defaults of docs/scene-format.md (pbrt-v4's,
// for the types taken from pbrt-v4) and no emission. The JSON reader and the MTL mapping both
// start from it, so that a default is written in one place.
Material defaultMaterial(uint type);

// Makes `material` pbrt-v4's conductor of the given reflectance colour (its
// ConductorMaterial::GetBxDF): eta = 1 and k = 2 sqrt(r) / sqrt(1 - r) per channel, with r
// clamped to [0, 0.9999] so that white stays finite.
void setConductorReflectance(Material& material, vec3 reflectance);

// pbrt-v4's "roughness", "uroughness" and "vroughness" as a material stores them: Trowbridge-
// Reitz alphas, mapped by RoughnessToAlpha (alpha = sqrt(roughness)) when `remap` (pbrt-v4's
// "remaproughness", true by default). The JSON and pbrt readers both call it.
void setRoughness(Material& material, float uRoughness, float vRoughness, bool remap);

// diffusetransmission's "scale" as pbrt-v4 applies it: both colours scaled and the products
// clamped to [0, 1].
void scaleDiffuseTransmission(Material& material, float scale);

// The most random-walk steps or walks a coated material may ask for per evaluation: far more
// than pbrt-v4's defaults (10 and 1) need, and small enough that one evaluation stays short.
inline constexpr std::int64_t kMaxCoatedWalk = 1000;

// cos and sin of an angle in degrees, exact for multiples of 90 degrees so that axis-aligned
// geometry stays exactly axis-aligned (cos(radians(90)) is 6e-17, not 0). Both scene readers
// rotate with it.
std::pair<double, double> cosSinDegrees(double degrees);

// How appendTriangle ended.
enum class Appended { kAdded, kZeroArea, kTooMany };

// Appends triangle `t` (its vertices and material set; emitter and primitive are filled here)
// to scene.triangles, as both scene readers do: not if it has zero area (the edges at v0
// parallel to within double rounding, i.e. the sine of the angle between them at most 1e-12:
// scale-invariant, computed in double on the float vertices the renderer will see, so thin
// but real slivers are kept; coincident vertices too), nor beyond kNoEmitter - 1 triangles.
// `normals`: the vertex normals in world space (any length), or null where the mesh has none;
// each is made unit, the geometric normal standing in for one that is zero or not finite.
// Once some triangle has normals, every triangle has an entry in scene.normals (its geometric
// normal at all three vertices where its mesh has none).
// `uvs`: the vertices' texture coordinates, or null where the mesh has none (scene.uvs then
// gets pbrt-v4's defaults for it once some triangle has coordinates).
Appended appendTriangle(Scene& scene, Triangle t, const std::array<glm::dvec3, 3>* normals,
                        const std::array<glm::vec2, 3>* uvs = nullptr);

// Makes room for `size` elements, at least doubling the capacity when it grows, so that
// appending shape after shape costs amortized linear time (std::vector::reserve would allocate
// exactly `size`, and the next shape would copy everything again). The new room is given huge
// pages (common/huge_pages.h) before the elements are copied into it.
template <typename T>
void reserveGeometric(std::vector<T>& v, std::size_t size) {
  if (size <= v.capacity()) return;
  std::vector<T> grown;
  grown.reserve(std::max(size, 2 * v.capacity()));
  adviseHugePages(grown.data(), grown.capacity() * sizeof(T));
  grown.insert(grown.end(), std::make_move_iterator(v.begin()), std::make_move_iterator(v.end()));
  v.swap(grown);
}

}  // namespace pt
