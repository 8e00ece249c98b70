// Small glTF files written by the tests: a JSON document and one binary buffer, given as a
// .gltf with the buffer as a base64 data URI, as a .gltf beside an external .bin, or packed
// as a .glb.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pt::test {

inline std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* const kDigits =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = bytes[i];
    const std::uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0u;
    const std::uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0u;
    const std::uint32_t n = (b0 << 16) | (b1 << 8) | b2;
    out += kDigits[(n >> 18) & 63];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

class GltfBuilder {
 public:
  static constexpr int kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123, kUInt = 5125,
                       kFloat = 5126;

  nlohmann::json doc = {{"asset", {{"version", "2.0"}}}};
  std::vector<std::uint8_t> bin;

  // Appends `size` bytes (from a 4-byte boundary) as a new buffer view; returns its index.
  int view(const void* data, std::size_t size, std::size_t stride = 0) {
    while (bin.size() % 4 != 0) bin.push_back(0);
    const std::size_t offset = bin.size();
    bin.resize(offset + size);
    std::memcpy(bin.data() + offset, data, size);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
    if (stride != 0) v["byteStride"] = stride;
    doc["bufferViews"].push_back(v);
    return int(doc["bufferViews"].size()) - 1;
  }
  template <typename T>
  int view(const std::vector<T>& values, std::size_t stride = 0) {
    return view(values.data(), values.size() * sizeof(T), stride);
  }
  int accessor(int bufferView, int componentType, std::size_t count, const char* type,
               std::size_t byteOffset = 0, bool normalized = false) {
    nlohmann::json a = {{"componentType", componentType}, {"count", count}, {"type", type}};
    if (bufferView >= 0) a["bufferView"] = bufferView;
    if (byteOffset != 0) a["byteOffset"] = byteOffset;
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size()) - 1;
  }
  // Floats, `components` to an element (VEC3 for 3), in a view of their own.
  int floats(const std::vector<float>& values, const char* type, int components) {
    return accessor(view(values), kFloat, values.size() / std::size_t(components), type);
  }
  // A mesh of the given primitives; returns its index.
  int mesh(const nlohmann::json& primitives) {
    doc["meshes"].push_back({{"primitives", primitives}});
    return int(doc["meshes"].size()) - 1;
  }
  int node(const nlohmann::json& node) {
    doc["nodes"].push_back(node);
    return int(doc["nodes"].size()) - 1;
  }
  // A UV sphere of radius 1: its positions, normals (the same points), texture coordinates
  // (u around, v from the top; only where `uvs`, else -1) and 16-bit indices, without the
  // triangles collapsed to a point at the poles.
  struct SphereAccessors {
    int positions, normals, uvs, indices;
  };
  SphereAccessors sphere(int rings, int segments, bool uvs) {
    std::vector<float> p, uv;
    std::vector<std::uint16_t> idx;
    for (int i = 0; i <= rings; ++i) {
      const double theta = 3.14159265358979 * i / rings;
      for (int j = 0; j <= segments; ++j) {
        const double phi = 2.0 * 3.14159265358979 * j / segments;
        p.push_back(float(std::sin(theta) * std::cos(phi)));
        p.push_back(float(std::cos(theta)));
        p.push_back(float(-std::sin(theta) * std::sin(phi)));
        uv.push_back(float(j) / float(segments));
        uv.push_back(float(i) / float(rings));
      }
    }
    for (int i = 0; i < rings; ++i) {
      for (int j = 0; j < segments; ++j) {
        const int a = i * (segments + 1) + j, c = a + segments + 1;
        if (i != 0) {
          for (int v : {a, c, a + 1}) idx.push_back(std::uint16_t(v));
        }
        if (i != rings - 1) {
          for (int v : {a + 1, c, c + 1}) idx.push_back(std::uint16_t(v));
        }
      }
    }
    SphereAccessors s;
    s.positions = floats(p, "VEC3", 3);
    s.normals = floats(p, "VEC3", 3);  // a unit sphere's normals are its points
    s.uvs = uvs ? floats(uv, "VEC2", 2) : -1;
    s.indices = accessor(view(idx), kUShort, idx.size(), "SCALAR");
    return s;
  }

  // scenes[0] of the given root nodes.
  void scene(const std::vector<int>& roots) {
    doc["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
    doc["scene"] = 0;
  }

  // The .gltf text, the buffer a data URI (or `uri` where given: an external file).
  std::string gltf(const std::string& uri = "") const {
    nlohmann::json d = doc;
    if (!bin.empty()) {
      d["buffers"] = nlohmann::json::array(
          {{{"byteLength", bin.size()},
            {"uri", uri.empty() ? "data:application/octet-stream;base64," + base64(bin) : uri}}});
    }
    return d.dump();
  }
  std::string binBytes() const { return std::string(bin.begin(), bin.end()); }

  // The .glb: header, JSON chunk (padded with spaces), BIN chunk (padded with zeros).
  std::string glb() const {
    nlohmann::json d = doc;
    std::vector<std::uint8_t> data = bin;
    while (data.size() % 4 != 0) data.push_back(0);
    if (!bin.empty()) d["buffers"] = nlohmann::json::array({{{"byteLength", bin.size()}}});
    std::string json = d.dump();
    while (json.size() % 4 != 0) json += ' ';
    std::string out;
    const auto u32 = [&](std::uint32_t v) {
      for (int i = 0; i < 4; ++i) out += char((v >> (8 * i)) & 0xFF);
    };
    const std::size_t total = 12 + 8 + json.size() + (data.empty() ? 0 : 8 + data.size());
    out += "glTF";
    u32(2);
    u32(std::uint32_t(total));
    u32(std::uint32_t(json.size()));
    out += "JSON";
    out += json;
    if (!data.empty()) {
      u32(std::uint32_t(data.size()));
      out += std::string("BIN\0", 4);
      out.append(data.begin(), data.end());
    }
    return out;
  }
};

}  // namespace pt::test
