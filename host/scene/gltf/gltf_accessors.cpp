// readAccessor (gltf_accessors.h): bounds of buffers, views and accessors checked before a byte
// is read, then the components decoded little-endian as the specification stores them.
#include "scene/gltf/gltf_accessors.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace pt::gltf {

namespace {

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;  // not a glTF 2.0 accessor component type (INT and DOUBLE are not)
  }
}

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    default:
      return 0;
  }
}

const char* typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "an unknown type";
  }
}

// One component at `p`, little-endian; normalized integers as the specification maps them
// (unsigned: c / max; signed: max(c / max, -1)).
double decode(const unsigned char* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto c = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(c / 127.0, -1.0) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const auto c = static_cast<std::int16_t>(std::uint16_t(p[0] | (p[1] << 8)));
      return normalized ? std::max(c / 32767.0, -1.0) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const std::uint16_t c = std::uint16_t(p[0] | (p[1] << 8));
      return normalized ? c / 65535.0 : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      const std::uint32_t c = std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) |
                              (std::uint32_t(p[2]) << 16) | (std::uint32_t(p[3]) << 24);
      return normalized ? c / 4294967295.0 : c;
    }
    default: {  // float
      const std::uint32_t bits = std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) |
                                 (std::uint32_t(p[2]) << 16) | (std::uint32_t(p[3]) << 24);
      float f;
      std::memcpy(&f, &bits, 4);
      return f;
    }
  }
}

// A strided run of `count` elements of `elementSize` bytes in buffer view `viewIndex`, from
// `byteOffset` in the view: its first byte in the buffer and its stride, every byte inside
// the view and the view inside its buffer. `where` names the field holding the view index.
struct Run {
  const unsigned char* first;
  std::size_t stride;
};
Run locate(const tinygltf::Model& model, int viewIndex, std::size_t byteOffset, std::size_t count,
           std::size_t elementSize, bool strideAllowed, const std::string& where,
           const Context& context) {
  if (viewIndex < 0 || std::size_t(viewIndex) >= model.bufferViews.size()) {
    context.fail(where, "buffer view " + std::to_string(viewIndex) +
                            " out of range (the file has " +
                            std::to_string(model.bufferViews.size()) + ")");
  }
  const std::string viewPath = indexed("bufferViews", std::size_t(viewIndex));
  const tinygltf::BufferView& view = model.bufferViews[std::size_t(viewIndex)];
  if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size()) {
    context.fail(viewPath + ".buffer", "buffer " + std::to_string(view.buffer) +
                                           " out of range (the file has " +
                                           std::to_string(model.buffers.size()) + ")");
  }
  const std::size_t bufferSize = model.buffers[std::size_t(view.buffer)].data.size();
  if (view.byteOffset > bufferSize || view.byteLength > bufferSize - view.byteOffset) {
    context.fail(viewPath + ".byteLength",
                 "bytes " + std::to_string(view.byteOffset) + " + " +
                     std::to_string(view.byteLength) + " run past the end of buffer " +
                     std::to_string(view.buffer) + " (" + std::to_string(bufferSize) + " bytes)");
  }
  std::size_t stride = elementSize;
  if (view.byteStride != 0) {
    if (!strideAllowed) {
      context.fail(viewPath + ".byteStride", "indices and sparse data must be tightly packed");
    }
    if (view.byteStride < 4 || view.byteStride > 252 || view.byteStride % 4 != 0) {
      context.fail(viewPath + ".byteStride",
                   std::to_string(view.byteStride) + " is not a multiple of 4 from 4 to 252");
    }
    if (view.byteStride < elementSize) {
      context.fail(viewPath + ".byteStride", std::to_string(view.byteStride) +
                                                 " is less than the element size " +
                                                 std::to_string(elementSize));
    }
    stride = view.byteStride;
  }
  // The last element ends at byteOffset + stride (count - 1) + elementSize.
  const std::size_t limit = view.byteLength;
  const bool fits =
      count == 0 || (byteOffset <= limit && (count - 1) <= (limit - byteOffset) / stride &&
                     elementSize <= limit - byteOffset - (count - 1) * stride);
  if (!fits) {
    context.fail(where, std::to_string(count) + " elements of " + std::to_string(elementSize) +
                            " bytes from byte " + std::to_string(byteOffset) +
                            " run past the end of buffer view " + std::to_string(viewIndex) + " (" +
                            std::to_string(limit) + " bytes)");
  }
  return Run{model.buffers[std::size_t(view.buffer)].data.data() + view.byteOffset + byteOffset,
             stride};
}

}  // namespace

AccessorValues readAccessor(const tinygltf::Model& model, int index, const AccessorUse& use,
                            const Context& context) {
  if (index < 0 || std::size_t(index) >= model.accessors.size()) {
    context.fail(use.where, "accessor " + std::to_string(index) + " out of range (the file has " +
                                std::to_string(model.accessors.size()) + ")");
  }
  const std::string path = indexed("accessors", std::size_t(index));
  const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
  const int size = componentSize(a.componentType);
  if (size == 0) {
    context.fail(path + ".componentType",
                 std::to_string(a.componentType) + " is not a glTF 2.0 component type");
  }
  if (a.type != use.type) {
    context.fail(use.where, "accessor " + std::to_string(index) + " is " + typeName(a.type) +
                                ", expected " + typeName(use.type));
  }
  const bool integral = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                        a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                        a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  if (use.indices && (!integral || a.normalized)) {
    context.fail(use.where, "accessor " + std::to_string(index) +
                                " must hold unsigned integers that are not normalized");
  }
  if (a.normalized && a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
    context.fail(path + ".normalized", "floats cannot be normalized");
  }
  const int components = componentCount(a.type);
  const std::size_t elementSize = std::size_t(size) * std::size_t(components);
  AccessorValues out;
  out.count = a.count;
  out.components = components;
  // The largest a buffer can hold (glTF's lengths are at most 2^32 - 1 bytes) bounds the
  // count before anything is allocated for it.
  if (a.count > 0xFFFFFFFFull) context.fail(path + ".count", "too large");
  if (a.bufferView >= 0) {
    const Run run = locate(model, a.bufferView, a.byteOffset, a.count, elementSize, !use.indices,
                           path + ".bufferView", context);
    out.values.resize(a.count * std::size_t(components));
    for (std::size_t i = 0; i < a.count; ++i) {
      const unsigned char* e = run.first + i * run.stride;
      for (int c = 0; c < components; ++c) {
        out.values[i * std::size_t(components) + std::size_t(c)] =
            decode(e + c * size, a.componentType, a.normalized);
      }
    }
  } else {
    if (!a.sparse.isSparse) {
      context.fail(path,
                   "has neither a bufferView nor sparse values (data compressed by an "
                   "extension this reader does not decode?)");
    }
    if (a.count > 64u << 20) context.fail(path + ".count", "too large for an accessor of zeros");
    out.values.assign(a.count * std::size_t(components), 0.0);
  }
  if (a.sparse.isSparse) {
    const std::string sparse = path + ".sparse";
    const int n = a.sparse.count;
    if (n < 1 || std::size_t(n) > a.count) {
      context.fail(
          sparse + ".count",
          std::to_string(n) + " is not from 1 to the accessor's count " + std::to_string(a.count));
    }
    const int indexType = a.sparse.indices.componentType;
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      context.fail(sparse + ".indices.componentType",
                   std::to_string(indexType) + " is not an unsigned integer type");
    }
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0) {
      context.fail(sparse, "negative byteOffset");
    }
    const Run indices =
        locate(model, a.sparse.indices.bufferView, std::size_t(a.sparse.indices.byteOffset),
               std::size_t(n), std::size_t(componentSize(indexType)), false,
               sparse + ".indices.bufferView", context);
    const Run values =
        locate(model, a.sparse.values.bufferView, std::size_t(a.sparse.values.byteOffset),
               std::size_t(n), elementSize, false, sparse + ".values.bufferView", context);
    double previous = -1.0;
    for (std::size_t i = 0; i < std::size_t(n); ++i) {
      const double target = decode(indices.first + i * indices.stride, indexType, false);
      if (target <= previous || target >= double(a.count)) {
        context.fail(sparse + ".indices", "index " + std::to_string(std::uint64_t(target)) +
                                              " is not increasing or not below the count " +
                                              std::to_string(a.count));
      }
      previous = target;
      for (int c = 0; c < components; ++c) {
        out.values[std::size_t(target) * std::size_t(components) + std::size_t(c)] =
            decode(values.first + i * values.stride + std::size_t(c * size), a.componentType,
                   a.normalized);
      }
    }
  }
  for (double v : out.values) {
    if (!std::isfinite(v)) context.fail(path, "holds a value that is not finite");
  }
  return out;
}

}  // namespace pt::gltf
