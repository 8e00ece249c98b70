// OBJ loading: a light pre-scan of the text gives line-accurate errors for what
// tinyobjloader would silently accept or mangle (index 0, out-of-range indices, unparsable
// or non-finite coordinates, texture coordinates and normals, polygons of more than 255
// vertices); tinyobjloader then does the actual load and the faces are fan-triangulated
// here, with their normals and texture coordinates.
#include "scene/obj_mesh.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <sstream>
#include <string_view>
#include <thread>

#include <tiny_obj_loader.h>

#include "scene/json_reader.h"

namespace pt::scene_detail {

namespace {

// tinyobjloader stores the vertex count of a face in an unsigned char.
constexpr std::size_t kMaxFaceVertices = 255;

// Calls fn(lineNumber, line) for every line, splitting exactly as tinyobjloader does
// ("\n", "\r\n" or a lone "\r"), so that our line numbers match the file as it reads it.
template <typename Fn>
void forEachLine(std::string_view text, Fn&& fn) {
  std::size_t lineNumber = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    std::string_view line = text.substr(pos, end - pos);
    // tinyobjloader reads each line as a C string: a NUL byte ends it.
    line = line.substr(0, line.find('\0'));
    ++lineNumber;
    fn(lineNumber, line);
    if (end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n') {
      ++end;
    }
    pos = end + 1;
  }
}

bool isBlank(char c) {
  return c == ' ' || c == '\t';
}

// The statement keyword of a line ("v", "vt", "f", ...) or empty for blank/comment lines.
// Like tinyobjloader, a keyword counts only when followed by a space or a tab.
std::string_view keyword(std::string_view line, std::string_view* rest) {
  std::size_t start = 0;
  while (start < line.size() && isBlank(line[start])) ++start;
  line.remove_prefix(start);
  if (line.empty() || line[0] == '#') return {};
  std::size_t end = 0;
  while (end < line.size() && !isBlank(line[end])) ++end;
  if (end == line.size()) return {};  // a bare keyword: tinyobjloader ignores the line
  *rest = line.substr(end);
  return line.substr(0, end);
}

std::vector<std::string_view> splitBlanks(std::string_view s) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && isBlank(s[i])) ++i;
    const std::size_t start = i;
    while (i < s.size() && !isBlank(s[i])) ++i;
    if (i > start) tokens.push_back(s.substr(start, i - start));
  }
  return tokens;
}

// from_chars takes no '+' sign: drop one, but refuse "+-3" and "++3", which tinyobjloader
// would read as 0.
bool skipPlus(std::string_view* token) {
  if (token->empty() || (*token)[0] != '+') return true;
  token->remove_prefix(1);
  return !token->empty() && (*token)[0] != '+' && (*token)[0] != '-';
}

// Parses a whole token as an integer ("+3" and "-3" allowed).
bool parseIndex(std::string_view token, std::int64_t* value) {
  if (!skipPlus(&token)) return false;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), *value);
  return ec == std::errc() && ptr == token.data() + token.size();
}

// Parses a whole token as a real number. from_chars also takes "inf" and "nan", which the
// caller reports as non-finite.
bool parseReal(std::string_view token, double* value) {
  if (!skipPlus(&token)) return false;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), *value,
                                         std::chars_format::general);
  if (ec == std::errc::result_out_of_range) {
    // Overflow or underflow: from_chars leaves the value alone, so decide by the exponent
    // sign whether this is "too large" (infinite) or "too small" (zero).
    const std::size_t e = token.find_first_of("eE");
    const bool negativeExponent =
        e != std::string_view::npos && e + 1 < token.size() && token[e + 1] == '-';
    *value = negativeExponent ? 0.0 : std::numeric_limits<double>::infinity();
    return ptr == token.data() + token.size();
  }
  return ec == std::errc() && ptr == token.data() + token.size();
}

struct Counts {
  std::int64_t vertices = 0;
  std::int64_t texcoords = 0;
  std::int64_t normals = 0;
  std::int64_t faces = 0;
};

class ObjScanner {
 public:
  ObjScanner(const std::string& file, const std::string& context, const Counts& totals)
      : file_(file), context_(context), totals_(totals) {}

  // Validates one line; counts what has been defined so far.
  void scan(std::size_t lineNumber, std::string_view line) {
    line_ = lineNumber;
    std::string_view rest;
    const std::string_view key = keyword(line, &rest);
    if (key == "v") {
      vertex(rest);
      vertexLines_.push_back(lineNumber);
      ++sofar_.vertices;
    } else if (key == "vt") {
      texcoord(rest);
      texcoordLines_.push_back(lineNumber);
      ++sofar_.texcoords;
    } else if (key == "vn") {
      normal(rest);
      normalLines_.push_back(lineNumber);
      ++sofar_.normals;
    } else if (key == "f" || key == "l" || key == "p") {
      element(key, rest);
    } else if (key == "usemtl") {
      useMaterial(rest);
    } else if (key == "mtllib") {
      for (std::string_view name : splitBlanks(rest)) {
        mtllib_.push_back({std::string(name), lineNumber});
      }
    }
  }

  // The usemtl index in force for each face, in file order.
  const std::vector<int>& faceMaterials() const { return faceMaterials_; }
  const std::vector<ObjMesh::Statement>& usemtl() const { return usemtl_; }
  const std::vector<ObjMesh::Statement>& mtllib() const { return mtllib_; }

  const std::vector<std::size_t>& vertexLines() const { return vertexLines_; }
  const std::vector<std::size_t>& normalLines() const { return normalLines_; }
  const std::vector<std::size_t>& texcoordLines() const { return texcoordLines_; }
  std::int64_t faces() const { return sofar_.faces; }

  [[noreturn]] void fail(std::size_t line, const std::string& problem) const {
    throwInputError(file_, "line " + std::to_string(line), problem + context_);
  }

 private:
  void vertex(std::string_view rest) const { threeReals(rest, "vertex", "coordinate"); }

  // tinyobjloader reads missing components of a normal as 0 and stores them as floats: a
  // short line or a value beyond the float range would give a normal other than the file's.
  void normal(std::string_view rest) const { threeReals(rest, "normal", "component"); }

  // `vt u [v [w]]`: tinyobjloader reads a missing v as 0 and ignores w; u and v are stored as
  // floats, so they must fit one.
  void texcoord(std::string_view rest) const {
    const std::vector<std::string_view> tokens = splitBlanks(rest);
    if (tokens.empty()) fail(line_, "texture coordinate has no values (need at least u)");
    for (std::size_t i = 0; i < 2 && i < tokens.size(); ++i) {
      checkReal(tokens[i], "texture coordinate", "value");
    }
  }

  // The first three values of a `v` or `vn` line (more are allowed: colours, weights).
  void threeReals(std::string_view rest, const std::string& what, const std::string& part) const {
    const std::vector<std::string_view> tokens = splitBlanks(rest);
    if (tokens.size() < 3) {
      fail(line_, what + " has " + std::to_string(tokens.size()) + " " + part +
                      (tokens.size() == 1 ? "" : "s") + " (need 3)");
    }
    for (std::size_t i = 0; i < 3; ++i) checkReal(tokens[i], what, part);
  }

  // One value that must be a number and fit a 32-bit float.
  void checkReal(std::string_view token, const std::string& what, const std::string& part) const {
    double v = 0.0;
    if (!parseReal(token, &v)) {
      fail(line_, what + " " + part + " " + singleQuoted(token) + " is not a number");
    }
    if (!std::isfinite(static_cast<float>(v))) {
      fail(line_, "non-finite " + what + " " + part + " " + singleQuoted(token) +
                      (std::isfinite(v) ? " (too large for a 32-bit float)" : ""));
    }
  }

  // A face, line or point statement: a list of v, v/vt, v//vn or v/vt/vn references.
  void element(std::string_view key, std::string_view rest) {
    const std::vector<std::string_view> refs = splitBlanks(rest);
    for (std::string_view ref : refs) {
      std::string_view parts[3];
      std::size_t count = 0;
      std::size_t start = 0;
      for (std::size_t i = 0; i <= ref.size(); ++i) {
        if (i == ref.size() || ref[i] == '/') {
          if (count == 3) fail(line_, "malformed vertex reference " + singleQuoted(ref));
          parts[count++] = ref.substr(start, i - start);
          start = i + 1;
        }
      }
      // v, v/vt, v//vn, v/vt/vn: the vertex is required; an empty texture slot only
      // as "v//vn".
      if (parts[0].empty() || (count == 2 && parts[1].empty()) ||
          (count == 3 && parts[2].empty())) {
        fail(line_, "malformed vertex reference " + singleQuoted(ref));
      }
      checkIndex(parts[0], "vertex", sofar_.vertices, totals_.vertices);
      if (count >= 2 && !parts[1].empty()) {
        checkIndex(parts[1], "texture coordinate", sofar_.texcoords, totals_.texcoords);
      }
      if (count == 3) checkIndex(parts[2], "normal", sofar_.normals, totals_.normals);
    }
    if (key == "f") {
      if (refs.size() < 3) {
        fail(line_, "face has " + std::to_string(refs.size()) + " vertices (need at least 3)");
      }
      if (refs.size() > kMaxFaceVertices) {
        fail(line_, "face has " + std::to_string(refs.size()) + " vertices (at most " +
                        std::to_string(kMaxFaceVertices) + " supported)");
      }
      ++sofar_.faces;
      faceMaterials_.push_back(currentMaterial_);
    }
  }

  // `usemtl NAME`: NAME is the first word, as tinyobjloader reads both usemtl and newmtl.
  void useMaterial(std::string_view rest) {
    const std::vector<std::string_view> words = splitBlanks(rest);
    if (words.empty()) fail(line_, "usemtl without a material name");
    const std::string name(words[0]);
    for (std::size_t i = 0; i < usemtl_.size(); ++i) {
      if (usemtl_[i].name == name) {
        currentMaterial_ = static_cast<int>(i);
        return;
      }
    }
    currentMaterial_ = static_cast<int>(usemtl_.size());
    usemtl_.push_back({name, line_});
  }

  // Positive indices count from 1 over the whole file; negative ones count back from the
  // last element defined before this line.
  void checkIndex(std::string_view token, const std::string& what, std::int64_t sofar,
                  std::int64_t total) const {
    std::int64_t index = 0;
    if (!parseIndex(token, &index)) {
      fail(line_, what + " index " + singleQuoted(token) + " is not an integer");
    }
    const std::string plural = what == "vertex" ? "vertices" : what + "s";
    if (index == 0) fail(line_, what + " index 0 is invalid (OBJ indices start at 1)");
    if (index > total) {
      fail(line_, what + " index " + std::to_string(index) + " out of range (file has " +
                      std::to_string(total) + " " + plural + ")");
    }
    if (index < 0 && -index > sofar) {
      fail(line_, what + " index " + std::to_string(index) + " out of range (" +
                      std::to_string(sofar) + " " + plural + " defined before this line)");
    }
  }

  const std::string& file_;
  const std::string& context_;
  const Counts& totals_;
  Counts sofar_;
  std::size_t line_ = 0;
  std::vector<std::size_t> vertexLines_;    // line of each vertex, for post-load checks
  std::vector<std::size_t> normalLines_;    // line of each normal, ditto
  std::vector<std::size_t> texcoordLines_;  // line of each texture coordinate, ditto
  int currentMaterial_ = -1;
  std::vector<int> faceMaterials_;
  std::vector<ObjMesh::Statement> usemtl_, mtllib_;
};

}  // namespace

ObjMesh loadObjMesh(const std::string& text, const std::string& file, const std::string& context) {
  // Pass 1: totals, needed to check positive (absolute) indices that refer forward.
  Counts totals;
  forEachLine(text, [&](std::size_t, std::string_view line) {
    std::string_view rest;
    const std::string_view key = keyword(line, &rest);
    if (key == "v") ++totals.vertices;
    if (key == "vt") ++totals.texcoords;
    if (key == "vn") ++totals.normals;
  });

  // Pass 2: validate every statement tinyobjloader will interpret. It runs on a thread of
  // its own beside tinyobjloader's parse (the larger cost), whose result is only used once
  // the scan has passed.
  ObjScanner scanner(file, context, totals);
  std::exception_ptr scanError;
  std::jthread scan([&] {  // joins on destruction too, should the parse throw
    try {
      forEachLine(text, [&](std::size_t n, std::string_view line) { scanner.scan(n, line); });
    } catch (...) {
      scanError = std::current_exception();
    }
  });

  // The actual load. No material reader: the pre-scan has the usemtl of every face, and the
  // scene loader reads MTL files itself (mtl_materials.h).
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn;
  std::string err;
  std::istringstream stream(text);
  const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, nullptr,
                                   /*triangulate=*/false, /*default_vcols_fallback=*/false);
  scan.join();
  if (scanError) std::rethrow_exception(scanError);
  if (scanner.faces() == 0) {
    throwInputError(file, "", "no faces (an OBJ mesh needs at least one 'f' line)" + context);
  }
  if (!ok) {
    throwInputError(file, "", "tinyobjloader: " + err.substr(0, err.find('\n')) + context);
  }

  // The pre-scan and tinyobjloader must agree; if they ever do not, say so rather than
  // index out of range.
  const std::size_t vertexCount = attrib.vertices.size() / 3;
  if (vertexCount != scanner.vertexLines().size()) {
    throwInputError(file, "",
                    "tinyobjloader read " + std::to_string(vertexCount) + " vertices, expected " +
                        std::to_string(scanner.vertexLines().size()) + context);
  }
  const std::size_t normalCount = attrib.normals.size() / 3;
  if (normalCount != scanner.normalLines().size()) {
    throwInputError(file, "",
                    "tinyobjloader read " + std::to_string(normalCount) + " normals, expected " +
                        std::to_string(scanner.normalLines().size()) + context);
  }
  const std::size_t texcoordCount = attrib.texcoords.size() / 2;
  if (texcoordCount != scanner.texcoordLines().size()) {
    throwInputError(file, "",
                    "tinyobjloader read " + std::to_string(texcoordCount) +
                        " texture coordinates, expected " +
                        std::to_string(scanner.texcoordLines().size()) + context);
  }
  // tinyobjloader's own number parser may round differently near the float limit.
  auto finite = [&](const std::vector<tinyobj::real_t>& values, std::size_t count,
                    const std::vector<std::size_t>& lines, const std::string& what) {
    std::vector<glm::dvec3> result(count);
    for (std::size_t i = 0; i < count; ++i) {
      for (int c = 0; c < 3; ++c) {
        const float value = values[3 * i + static_cast<std::size_t>(c)];
        if (!std::isfinite(value)) {
          throwInputError(file, "line " + std::to_string(lines[i]), "non-finite " + what + context);
        }
        result[i][c] = value;
      }
    }
    return result;
  };
  const std::vector<glm::dvec3> vertices =
      finite(attrib.vertices, vertexCount, scanner.vertexLines(), "vertex coordinate");
  const std::vector<glm::dvec3> normals =
      finite(attrib.normals, normalCount, scanner.normalLines(), "normal component");
  std::vector<glm::vec2> texcoords(texcoordCount);
  for (std::size_t i = 0; i < texcoordCount; ++i) {
    for (int c = 0; c < 2; ++c) {
      const float value = attrib.texcoords[2 * i + static_cast<std::size_t>(c)];
      if (!std::isfinite(value)) {
        throwInputError(file, "line " + std::to_string(scanner.texcoordLines()[i]),
                        "non-finite texture coordinate value" + context);
      }
      texcoords[i][c] = value;
    }
  }

  ObjMesh mesh;
  std::vector<std::array<glm::dvec3, 3>>& triangles = mesh.triangles;
  std::int64_t faceCount = 0;
  // tinyobjloader keeps the faces in file order (shapes in order of appearance), so the
  // pre-scan's per-face material applies face by face.
  const std::vector<int>& faceMaterials = scanner.faceMaterials();
  // Normals are kept from the first face that references one on; the triangles before it get
  // their zeros then, so that a file without normals costs nothing.
  bool anyNormals = false;
  // Texture coordinates likewise, with pbrt-v4's default per-triangle coordinates for the
  // triangles of faces without them.
  const std::array<glm::vec2, 3> defaultUvs = {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1)};
  bool anyUvs = false;
  std::vector<std::size_t> face;
  std::vector<glm::dvec3> faceNormals;
  std::vector<glm::vec2> faceUvs;
  for (const tinyobj::shape_t& shape : shapes) {
    const tinyobj::mesh_t& faces = shape.mesh;
    std::size_t offset = 0;
    for (const unsigned char faceSize : faces.num_face_vertices) {
      const std::size_t n = faceSize;
      if (offset + n > faces.indices.size()) break;  // reported by the count check below
      if (faceCount >= static_cast<std::int64_t>(faceMaterials.size())) break;  // ditto
      face.resize(n);
      faceNormals.assign(n, glm::dvec3(0.0));
      faceUvs.resize(n);
      std::size_t withNormal = 0;
      std::size_t withUv = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const tinyobj::index_t& ref = faces.indices[offset + k];
        const int index = ref.vertex_index;
        if (index < 0 || static_cast<std::size_t>(index) >= vertexCount) {
          throwInputError(file, "",
                          "tinyobjloader produced vertex index " + std::to_string(index) +
                              " out of range" + context);
        }
        face[k] = static_cast<std::size_t>(index);
        // -1: no texture coordinate referenced (v or v//vn).
        if (ref.texcoord_index != -1) {
          if (ref.texcoord_index < 0 ||
              static_cast<std::size_t>(ref.texcoord_index) >= texcoordCount) {
            throwInputError(file, "",
                            "tinyobjloader produced texture coordinate index " +
                                std::to_string(ref.texcoord_index) + " out of range" + context);
          }
          faceUvs[k] = texcoords[static_cast<std::size_t>(ref.texcoord_index)];
          ++withUv;
        }
        // -1: no normal referenced (v or v/vt).
        if (ref.normal_index == -1) continue;
        if (ref.normal_index < 0 || static_cast<std::size_t>(ref.normal_index) >= normalCount) {
          throwInputError(file, "",
                          "tinyobjloader produced normal index " +
                              std::to_string(ref.normal_index) + " out of range" + context);
        }
        faceNormals[k] = normals[static_cast<std::size_t>(ref.normal_index)];
        ++withNormal;
      }
      anyNormals = anyNormals || withNormal > 0;
      // Normals at only some corners (tinyobjloader allows "f 1//1 2 3") cannot be
      // interpolated over the face: it is shaded like a face without any.
      if (withNormal != n) faceNormals.assign(n, glm::dvec3(0.0));
      if (anyNormals) mesh.normals.resize(triangles.size(), {});
      // Likewise texture coordinates at only some corners ("f 1/1 2 3"): the face gets the
      // defaults.
      const bool faceHasUvs = withUv == n;
      anyUvs = anyUvs || withUv > 0;
      if (anyUvs) mesh.uvs.resize(triangles.size(), defaultUvs);
      for (std::size_t k = 1; k + 1 < n; ++k) {
        triangles.push_back({vertices[face[0]], vertices[face[k]], vertices[face[k + 1]]});
        if (anyNormals) {
          mesh.normals.push_back({faceNormals[0], faceNormals[k], faceNormals[k + 1]});
        }
        if (anyUvs) {
          mesh.uvs.push_back(faceHasUvs
                                 ? std::array<glm::vec2, 3>{faceUvs[0], faceUvs[k], faceUvs[k + 1]}
                                 : defaultUvs);
        }
        mesh.material.push_back(faceMaterials[static_cast<std::size_t>(faceCount)]);
      }
      offset += n;
      ++faceCount;
    }
  }
  if (faceCount != scanner.faces()) {
    throwInputError(file, "",
                    "tinyobjloader read " + std::to_string(faceCount) + " faces, expected " +
                        std::to_string(scanner.faces()) + context);
  }
  mesh.usemtl = scanner.usemtl();
  mesh.mtllib = scanner.mtllib();
  return mesh;
}

}  // namespace pt::scene_detail
