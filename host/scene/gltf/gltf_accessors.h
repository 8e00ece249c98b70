// glTF accessors read into plain arrays: every component type, byte strides, accessors without a
// buffer view (zeros), sparse substitutions, normalized integers as the specification maps them
// to [0, 1] or [-1, 1]. Each problem is an InputError naming the accessor's JSON path, or the
// path of the field that refers to it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/gltf/tinygltf.h"

#include "scene/gltf/gltf_context.h"

namespace pt::gltf {

// An accessor's elements, `components` values each (1 for SCALAR ... 4 for VEC4), flattened.
struct AccessorValues {
  std::size_t count = 0;
  int components = 0;
  std::vector<double> values;  // count * components
  double at(std::size_t element, int component) const {
    return values[element * std::size_t(components) + std::size_t(component)];
  }
};

// What a use of an accessor asks of it.
struct AccessorUse {
  std::string where;  // the referring field, "meshes[0].primitives[1].attributes.NORMAL"
  int type;           // TINYGLTF_TYPE_SCALAR, _VEC2, _VEC3 or _VEC4
  // Indices: unsigned integer component types only, values kept as integers (never
  // normalized). Otherwise every component type is read, integers normalized where the
  // accessor says so.
  bool indices = false;
};

// Reads accessor `index` as `use` asks; values are finite (non-finite ones are errors).
AccessorValues readAccessor(const tinygltf::Model& model, int index, const AccessorUse& use,
                            const Context& context);

}  // namespace pt::gltf
