// Tests of the PLY reader (host/scene/ply_mesh): one mesh in many layouts and all three
// formats gives exactly the OBJ reader's triangles; vertex normals and texture coordinates
// follow the triangles; every kind of malformed file gives its one-line message; no
// truncation or corruption of a file crashes the reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/check.h"
#include "scene/obj_mesh.h"
#include "scene/ply_mesh.h"

namespace pt {
namespace {

using scene_detail::loadObjTriangles;
using scene_detail::loadPlyMesh;
using scene_detail::loadPlyTriangles;
using scene_detail::PlyMesh;
using Triangles = std::vector<std::array<glm::dvec3, 3>>;

const std::string kPlyContext = " (referenced by scene.json: shapes[0].file)";
const std::vector<std::string> kFormats = {"ascii", "binary_little_endian", "binary_big_endian"};

// ---- A small PLY writer, independent of the reader ----

struct Prop {
  std::string type;  // the scalar's type, or a list's item type
  std::string name;
  std::string countType;  // non-empty for a list
};

struct Elem {
  std::string name;
  std::vector<Prop> props;
  // One row per entry: the values in property order, a list as its count then its items.
  std::vector<std::vector<double>> rows;
};

void putBinary(std::string& out, double value, const std::string& type, bool bigEndian) {
  unsigned char bytes[8];
  std::size_t size = 0;
  auto store = [&](auto v) {
    std::memcpy(bytes, &v, sizeof v);
    size = sizeof v;
  };
  if (type == "char" || type == "int8") {
    store(static_cast<std::int8_t>(value));
  } else if (type == "uchar" || type == "uint8") {
    store(static_cast<std::uint8_t>(value));
  } else if (type == "short" || type == "int16") {
    store(static_cast<std::int16_t>(value));
  } else if (type == "ushort" || type == "uint16") {
    store(static_cast<std::uint16_t>(value));
  } else if (type == "int" || type == "int32") {
    store(static_cast<std::int32_t>(value));
  } else if (type == "uint" || type == "uint32") {
    store(static_cast<std::uint32_t>(value));
  } else if (type == "float" || type == "float32") {
    store(static_cast<float>(value));
  } else if (type == "double" || type == "float64") {
    store(value);
  } else {
    ADD_FAILURE() << "test writer: unknown type " << type;
  }
  if ((std::endian::native == std::endian::big) != bigEndian) std::reverse(bytes, bytes + size);
  out.append(reinterpret_cast<const char*>(bytes), size);
}

std::string asciiValue(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

std::string plyHeader(const std::string& format, const std::vector<Elem>& elements) {
  std::string out = "ply\nformat " + format + " 1.0\ncomment written by ply_mesh_test\n";
  for (const Elem& e : elements) {
    out += "element " + e.name + " " + std::to_string(e.rows.size()) + "\n";
    for (const Prop& p : e.props) {
      out += p.countType.empty()
                 ? "property " + p.type + " " + p.name + "\n"
                 : "property list " + p.countType + " " + p.type + " " + p.name + "\n";
    }
  }
  return out + "end_header\n";
}

std::string plyData(const std::string& format, const std::vector<Elem>& elements) {
  std::string out;
  const bool bigEndian = format == "binary_big_endian";
  for (const Elem& e : elements) {
    for (const std::vector<double>& row : e.rows) {
      if (format == "ascii") {
        for (std::size_t k = 0; k < row.size(); ++k) out += (k ? " " : "") + asciiValue(row[k]);
        out += "\n";
        continue;
      }
      std::size_t k = 0;
      for (const Prop& p : e.props) {
        if (p.countType.empty()) {
          putBinary(out, row.at(k++), p.type, bigEndian);
          continue;
        }
        const double n = row.at(k++);
        putBinary(out, n, p.countType, bigEndian);
        for (int i = 0; i < static_cast<int>(n); ++i)
          putBinary(out, row.at(k++), p.type, bigEndian);
      }
    }
  }
  return out;
}

std::string plyFile(const std::string& format, const std::vector<Elem>& elements) {
  return plyHeader(format, elements) + plyData(format, elements);
}

// ---- The mesh: a triangle, a quad, a pentagon and a triangle over 7 vertices ----

const std::vector<glm::dvec3> kVertices = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 1.5, 0.25}, {-1, 0.5, 2}, {2, -0.75, 1.5}};
const std::vector<std::vector<int>> kFaces = {{0, 1, 2}, {0, 2, 3, 4}, {1, 6, 2, 4, 3}, {4, 5, 6}};

std::string objText() {
  std::string text = "# the PLY mesh as OBJ\n";
  for (const glm::dvec3& v : kVertices) {
    text += "v " + asciiValue(v.x) + " " + asciiValue(v.y) + " " + asciiValue(v.z) + "\n";
  }
  for (const std::vector<int>& face : kFaces) {
    text += "f";
    for (int i : face) text += " " + std::to_string(i + 1);
    text += "\n";
  }
  return text;
}

struct Layout {
  std::string vertexType;  // of x, y, z
  std::string indexType;
  std::string countType;
  bool extras = false;      // other vertex and face properties, other elements
  bool vertexList = false;  // a list property in the vertex element
  bool facesFirst = false;  // the face element before the vertex element
};

std::string describeLayout(const Layout& l) {
  return l.vertexType + " vertices, " + l.countType + " " + l.indexType + " indices" +
         (l.extras ? ", extras" : "") + (l.vertexList ? ", vertex list" : "") +
         (l.facesFirst ? ", faces first" : "");
}

std::vector<Elem> meshElements(const Layout& l) {
  Elem vertex{"vertex", {}, {}};
  if (l.extras) {
    // A property between x and y, normals after, like real scanner output.
    vertex.props = {{"uchar", "flags", ""},  {l.vertexType, "x", ""}, {"float", "confidence", ""},
                    {l.vertexType, "y", ""}, {l.vertexType, "z", ""}, {"float", "nx", ""},
                    {"float", "ny", ""},     {"float", "nz", ""}};
  } else {
    vertex.props = {{l.vertexType, "x", ""}, {l.vertexType, "y", ""}, {l.vertexType, "z", ""}};
  }
  if (l.vertexList) vertex.props.push_back({"float", "uv", "uint8"});
  for (std::size_t i = 0; i < kVertices.size(); ++i) {
    const glm::dvec3& v = kVertices[i];
    std::vector<double> row = l.extras
                                  ? std::vector<double>{double(i % 3), v.x, 0.75, v.y, v.z, 0, 0, 1}
                                  : std::vector<double>{v.x, v.y, v.z};
    if (l.vertexList) {
      row.push_back(double(i % 3));  // 0, 1 or 2 items
      for (std::size_t k = 0; k < i % 3; ++k) row.push_back(0.25 * double(k + i));
    }
    vertex.rows.push_back(row);
  }

  Elem face{"face", {}, {}};
  if (l.extras) {
    face.props = {{"int", "flags", ""},
                  {l.indexType, "vertex_indices", l.countType},
                  {"float", "quality", ""},
                  {"float", "texcoord", "uchar"}};
  } else {
    face.props = {{l.indexType, "vertex_indices", l.countType}};
  }
  for (const std::vector<int>& f : kFaces) {
    std::vector<double> row;
    if (l.extras) row.push_back(-7);
    row.push_back(double(f.size()));
    for (int i : f) row.push_back(i);
    if (l.extras) row.insert(row.end(), {0.5, 2, 0.125, 0.375});
    face.rows.push_back(row);
  }

  std::vector<Elem> elements;
  if (l.extras) {
    elements.push_back({"material",
                        {{"float", "red", ""}, {"float", "green", ""}, {"uchar", "tags", "ushort"}},
                        {{0.5, 0.25, 3, 1, 2, 3}, {1, 1, 0}}});
  }
  if (l.facesFirst) {
    elements.push_back(face);
    elements.push_back(vertex);
  } else {
    elements.push_back(vertex);
    elements.push_back(face);
  }
  if (l.extras) {
    elements.push_back({"edge",
                        {{"int", "vertex1", ""}, {"int", "vertex2", ""}, {"uchar", "crease", ""}},
                        {{0, 1, 255}, {1, 2, 0}}});
  }
  return elements;
}

const std::vector<Layout> kLayouts = {
    {"float", "int", "uchar", false, false, false},
    {"double", "uint", "ushort", true, true, false},
    {"float32", "uchar", "int", true, false, true},
    {"float", "short", "uint8", true, true, false},
    {"float64", "int32", "uint", false, false, true},
    {"float", "uint16", "char", true, true, true},
};

TEST(PlyMesh, EveryFormatAndLayoutGivesTheObjTriangles) {
  const Triangles obj = loadObjTriangles(objText(), "mesh.obj", kPlyContext);
  ASSERT_EQ(obj.size(), 7u);
  for (const Layout& layout : kLayouts) {
    for (const std::string& format : kFormats) {
      SCOPED_TRACE(format + ", " + describeLayout(layout));
      const PlyMesh ply =
          loadPlyMesh(plyFile(format, meshElements(layout)), "mesh.ply", kPlyContext);
      EXPECT_TRUE(ply.triangles == obj);
      // The extras include normals, all (0, 0, 1).
      if (layout.extras) {
        ASSERT_EQ(ply.normals.size(), obj.size());
        for (const auto& triple : ply.normals) {
          for (const glm::dvec3& n : triple) EXPECT_EQ(n, glm::dvec3(0, 0, 1));
        }
      } else {
        EXPECT_TRUE(ply.normals.empty());
      }
      EXPECT_TRUE(
          loadPlyTriangles(plyFile(format, meshElements(layout)), "mesh.ply", kPlyContext) == obj);
    }
  }
}

TEST(PlyMesh, PolygonsAreFannedFromTheirFirstVertex) {
  const Triangles ply =
      loadPlyTriangles(plyFile("ascii", meshElements(kLayouts[0])), "mesh.ply", kPlyContext);
  ASSERT_EQ(ply.size(), 7u);
  // The pentagon (1, 6, 2, 4, 3) is triangles 3 to 5.
  const std::array<std::array<int, 3>, 3> expected = {{{1, 6, 2}, {1, 2, 4}, {1, 4, 3}}};
  for (std::size_t t = 0; t < 3; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(ply[3 + t][k], kVertices[static_cast<std::size_t>(expected[t][k])]);
    }
  }
}

TEST(PlyMesh, CrlfLinesAndBlankDataLinesAreTolerated) {
  const Triangles expected =
      loadPlyTriangles(plyFile("ascii", meshElements(kLayouts[1])), "mesh.ply", kPlyContext);
  std::string crlf;
  for (char c : plyFile("ascii", meshElements(kLayouts[1]))) {
    crlf += c == '\n' ? std::string("\r\n\r\n") : std::string(1, c);
  }
  // Blank lines inside the header are tolerated too.
  EXPECT_TRUE(loadPlyTriangles(crlf, "mesh.ply", kPlyContext) == expected);
  for (const std::string& format : {kFormats[1], kFormats[2]}) {
    const std::vector<Elem> elements = meshElements(kLayouts[1]);
    std::string header = plyHeader(format, elements);
    std::string crlfHeader;
    for (char c : header) crlfHeader += c == '\n' ? std::string("\r\n") : std::string(1, c);
    EXPECT_TRUE(loadPlyTriangles(crlfHeader + plyData(format, elements), "mesh.ply", kPlyContext) ==
                expected)
        << format;
  }
}

TEST(PlyMesh, DoubleCoordinatesKeepTheirPrecision) {
  for (const std::string& format : kFormats) {
    for (const std::string type : {"float", "double"}) {
      SCOPED_TRACE(format + " " + type);
      const std::vector<Elem> elements = {
          {"vertex",
           {{type, "x", ""}, {type, "y", ""}, {type, "z", ""}},
           {{0.1, 0, 0}, {1, 0, 0}, {0, 1, 0.3}}},
          {"face", {{"int", "vertex_indices", "uchar"}}, {{3, 0, 1, 2}}}};
      const Triangles t = loadPlyTriangles(plyFile(format, elements), "m.ply", kPlyContext);
      ASSERT_EQ(t.size(), 1u);
      const bool isDouble = type == "double";
      EXPECT_EQ(t[0][0].x, isDouble ? 0.1 : double(0.1f));
      EXPECT_EQ(t[0][2].z, isDouble ? 0.3 : double(0.3f));
    }
  }
}

// Triangle strips, Stanford style: -1 restarts; odd triangles swap their first two
// vertices; triangles with a repeated vertex (stitching) are skipped.
TEST(PlyMesh, TristripsAreAccepted) {
  std::vector<Elem> elements = meshElements(kLayouts[0]);
  elements[1] = {"tristrips",
                 {{"int", "vertex_indices", "int"}},
                 {{15, 0, 1, 2, 3, -1, 4, 5, 6, 3, -1, 0, 1, 1, 2, 3}}};
  const std::vector<std::array<int, 3>> expected = {
      {0, 1, 2}, {2, 1, 3}, {4, 5, 6}, {6, 5, 3}, {1, 2, 3}};
  for (const std::string& format : kFormats) {
    SCOPED_TRACE(format);
    const Triangles t = loadPlyTriangles(plyFile(format, elements), "strips.ply", kPlyContext);
    ASSERT_EQ(t.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
      for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(t[i][k], kVertices[static_cast<std::size_t>(expected[i][k])]) << i << " " << k;
      }
    }
  }
}

// ---- Vertex normals ----

// A normal per vertex of kVertices, distinct, exact in a float, and not of unit length (the
// reader keeps them as read).
glm::dvec3 vertexNormal(std::size_t i) {
  return {0.25 * double(i), -0.5, 1.0 + double(i)};
}

// The vertex element with normals: the components among the coordinates and out of order,
// each of `type`; with `list`, a list property too (binary: entries of varying size).
Elem normalVertices(const std::string& type, bool list) {
  Elem vertex{"vertex",
              {{type, "nz", ""},
               {type, "x", ""},
               {"uchar", "flags", ""},
               {type, "nx", ""},
               {type, "y", ""},
               {type, "z", ""},
               {type, "ny", ""}},
              {}};
  if (list) vertex.props.push_back({"float", "uv", "uint8"});
  for (std::size_t i = 0; i < kVertices.size(); ++i) {
    const glm::dvec3& v = kVertices[i];
    const glm::dvec3 n = vertexNormal(i);
    std::vector<double> row = {n.z, v.x, double(i), n.x, v.y, v.z, n.y};
    if (list) {
      row.push_back(double(i % 3));
      for (std::size_t k = 0; k < i % 3; ++k) row.push_back(0.5 * double(k));
    }
    vertex.rows.push_back(row);
  }
  return vertex;
}

// Checks triangle t of `mesh` against the vertex indices `expected`, points and normals.
void expectPlyTriangle(const PlyMesh& mesh, std::size_t t, const std::array<int, 3>& expected) {
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t v = static_cast<std::size_t>(expected[k]);
    EXPECT_EQ(mesh.triangles[t][k], kVertices[v]) << "triangle " << t << " vertex " << k;
    EXPECT_EQ(mesh.normals[t][k], vertexNormal(v)) << "triangle " << t << " vertex " << k;
  }
}

TEST(PlyMesh, NormalsFollowTheFannedPolygons) {
  // kFaces fanned as (0, i, i + 1).
  const std::vector<std::array<int, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {1, 6, 2},
                                                    {1, 2, 4}, {1, 4, 3}, {4, 5, 6}};
  for (const std::string& format : kFormats) {
    for (const std::string type : {"float", "double"}) {
      for (const bool list : {false, true}) {
        SCOPED_TRACE(format + ", " + type + (list ? ", vertex list" : ""));
        std::vector<Elem> elements = meshElements(kLayouts[0]);
        elements[0] = normalVertices(type, list);
        const PlyMesh mesh = loadPlyMesh(plyFile(format, elements), "normals.ply", kPlyContext);
        ASSERT_EQ(mesh.triangles.size(), expected.size());
        ASSERT_EQ(mesh.normals.size(), expected.size());
        for (std::size_t t = 0; t < expected.size(); ++t) expectPlyTriangle(mesh, t, expected[t]);
      }
    }
  }
}

TEST(PlyMesh, NormalsFollowTheTristrips) {
  std::vector<Elem> elements = meshElements(kLayouts[0]);
  elements[0] = normalVertices("float", false);
  elements[1] = {"tristrips",
                 {{"int", "vertex_indices", "int"}},
                 {{15, 0, 1, 2, 3, -1, 4, 5, 6, 3, -1, 0, 1, 1, 2, 3}}};
  const std::vector<std::array<int, 3>> expected = {
      {0, 1, 2}, {2, 1, 3}, {4, 5, 6}, {6, 5, 3}, {1, 2, 3}};
  for (const std::string& format : kFormats) {
    SCOPED_TRACE(format);
    const PlyMesh mesh = loadPlyMesh(plyFile(format, elements), "strips.ply", kPlyContext);
    ASSERT_EQ(mesh.triangles.size(), expected.size());
    ASSERT_EQ(mesh.normals.size(), expected.size());
    for (std::size_t t = 0; t < expected.size(); ++t) expectPlyTriangle(mesh, t, expected[t]);
  }
}

TEST(PlyMesh, DoubleNormalsKeepTheirPrecision) {
  for (const std::string& format : kFormats) {
    for (const std::string type : {"float", "double"}) {
      SCOPED_TRACE(format + " " + type);
      const std::vector<Elem> elements = {
          {"vertex",
           {{"float", "x", ""},
            {"float", "y", ""},
            {"float", "z", ""},
            {type, "nx", ""},
            {type, "ny", ""},
            {type, "nz", ""}},
           {{0, 0, 0, 0.1, 0, 0}, {1, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0.3}}},
          {"face", {{"int", "vertex_indices", "uchar"}}, {{3, 0, 1, 2}}}};
      const PlyMesh mesh = loadPlyMesh(plyFile(format, elements), "m.ply", kPlyContext);
      ASSERT_EQ(mesh.normals.size(), 1u);
      const bool isDouble = type == "double";
      EXPECT_EQ(mesh.normals[0][0].x, isDouble ? 0.1 : double(0.1f));
      EXPECT_EQ(mesh.normals[0][2].z, isDouble ? 0.3 : double(0.3f));
      // A zero normal is passed on as it is (the scene loader replaces it).
      EXPECT_EQ(mesh.normals[0][1], glm::dvec3(0.0));
    }
  }
}

TEST(PlyMesh, FilesWithoutNormalsHaveNone) {
  for (const std::string& format : kFormats) {
    SCOPED_TRACE(format);
    const PlyMesh mesh =
        loadPlyMesh(plyFile(format, meshElements(kLayouts[0])), "plain.ply", kPlyContext);
    EXPECT_EQ(mesh.triangles.size(), 7u);
    EXPECT_TRUE(mesh.normals.empty());
  }
}

// ---- Texture coordinates ----

// The property name pairs pbrt-v4 accepts, in its order of preference.
const std::vector<std::array<std::string, 2>> kUvNames = {
    {"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};

// A texture coordinate per vertex of kVertices, distinct, exact in a float, some outside
// [0, 1] (kept as read).
glm::vec2 vertexUv(std::size_t i) {
  return {0.125f * float(i), 1.0f - 0.375f * float(i)};
}

// The vertex element with texture coordinates named `names` and of `type`, v before u and
// between the coordinates; with `normals`, normals too; with `list`, a list property too
// (binary: entries of varying size).
Elem uvVertices(const std::string& type, const std::array<std::string, 2>& names, bool list,
                bool normals = false) {
  Elem vertex{"vertex",
              {{"float", "x", ""},
               {type, names[1], ""},
               {"uchar", "flags", ""},
               {"float", "y", ""},
               {type, names[0], ""},
               {"float", "z", ""}},
              {}};
  if (normals) {
    vertex.props.insert(vertex.props.end(),
                        {{"float", "nx", ""}, {"float", "ny", ""}, {"float", "nz", ""}});
  }
  if (list) vertex.props.push_back({"float", "uvlist", "uint8"});
  for (std::size_t i = 0; i < kVertices.size(); ++i) {
    const glm::dvec3& v = kVertices[i];
    const glm::vec2 uv = vertexUv(i);
    std::vector<double> row = {v.x, uv.y, double(i), v.y, uv.x, v.z};
    if (normals) {
      const glm::dvec3 n = vertexNormal(i);
      row.insert(row.end(), {n.x, n.y, n.z});
    }
    if (list) {
      row.push_back(double(i % 3));
      for (std::size_t k = 0; k < i % 3; ++k) row.push_back(0.5 * double(k));
    }
    vertex.rows.push_back(row);
  }
  return vertex;
}

// Checks triangle t of `mesh` against the vertex indices `expected`, points and texture
// coordinates.
void expectUvTriangle(const PlyMesh& mesh, std::size_t t, const std::array<int, 3>& expected) {
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t v = static_cast<std::size_t>(expected[k]);
    EXPECT_EQ(mesh.triangles[t][k], kVertices[v]) << "triangle " << t << " vertex " << k;
    EXPECT_EQ(mesh.uvs[t][k], vertexUv(v)) << "triangle " << t << " vertex " << k;
  }
}

TEST(PlyMeshUvs, UvsFollowTheFannedPolygons) {
  // kFaces fanned as (0, i, i + 1).
  const std::vector<std::array<int, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {1, 6, 2},
                                                    {1, 2, 4}, {1, 4, 3}, {4, 5, 6}};
  for (const std::string& format : kFormats) {
    for (const std::string type : {"float", "double"}) {
      for (const std::array<std::string, 2>& names : kUvNames) {
        for (const bool list : {false, true}) {
          SCOPED_TRACE(format + ", " + type + " " + names[0] + "/" + names[1] +
                       (list ? ", vertex list" : ""));
          std::vector<Elem> elements = meshElements(kLayouts[0]);
          elements[0] = uvVertices(type, names, list);
          const PlyMesh mesh = loadPlyMesh(plyFile(format, elements), "uvs.ply", kPlyContext);
          ASSERT_EQ(mesh.triangles.size(), expected.size());
          ASSERT_EQ(mesh.uvs.size(), expected.size());
          EXPECT_TRUE(mesh.normals.empty());
          for (std::size_t t = 0; t < expected.size(); ++t) {
            expectUvTriangle(mesh, t, expected[t]);
          }
        }
      }
    }
  }
}

TEST(PlyMeshUvs, UvsAndNormalsTogether) {
  const std::vector<std::array<int, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {1, 6, 2},
                                                    {1, 2, 4}, {1, 4, 3}, {4, 5, 6}};
  for (const std::string& format : kFormats) {
    for (const bool list : {false, true}) {
      SCOPED_TRACE(format + (list ? ", vertex list" : ""));
      std::vector<Elem> elements = meshElements(kLayouts[0]);
      elements[0] = uvVertices("float", kUvNames[0], list, /*normals=*/true);
      const PlyMesh mesh = loadPlyMesh(plyFile(format, elements), "uvs.ply", kPlyContext);
      ASSERT_EQ(mesh.uvs.size(), expected.size());
      ASSERT_EQ(mesh.normals.size(), expected.size());
      for (std::size_t t = 0; t < expected.size(); ++t) {
        expectUvTriangle(mesh, t, expected[t]);
        for (std::size_t k = 0; k < 3; ++k) {
          EXPECT_EQ(mesh.normals[t][k], vertexNormal(static_cast<std::size_t>(expected[t][k])));
        }
      }
    }
  }
}

TEST(PlyMeshUvs, UvsFollowTheTristrips) {
  std::vector<Elem> elements = meshElements(kLayouts[0]);
  elements[0] = uvVertices("float", kUvNames[1], false);
  elements[1] = {"tristrips",
                 {{"int", "vertex_indices", "int"}},
                 {{15, 0, 1, 2, 3, -1, 4, 5, 6, 3, -1, 0, 1, 1, 2, 3}}};
  const std::vector<std::array<int, 3>> expected = {
      {0, 1, 2}, {2, 1, 3}, {4, 5, 6}, {6, 5, 3}, {1, 2, 3}};
  for (const std::string& format : kFormats) {
    SCOPED_TRACE(format);
    const PlyMesh mesh = loadPlyMesh(plyFile(format, elements), "strips.ply", kPlyContext);
    ASSERT_EQ(mesh.triangles.size(), expected.size());
    ASSERT_EQ(mesh.uvs.size(), expected.size());
    for (std::size_t t = 0; t < expected.size(); ++t) expectUvTriangle(mesh, t, expected[t]);
  }
}

TEST(PlyMeshUvs, DoubleUvsAreRoundedToFloat) {
  for (const std::string& format : kFormats) {
    for (const std::string type : {"float", "double"}) {
      SCOPED_TRACE(format + " " + type);
      const std::vector<Elem> elements = {
          {"vertex",
           {{"float", "x", ""},
            {"float", "y", ""},
            {"float", "z", ""},
            {type, "texture_u", ""},
            {type, "texture_v", ""}},
           {{0, 0, 0, 0.1, -2.5}, {1, 0, 0, 0, 0}, {0, 1, 0, 1e-3, 0.3}}},
          {"face", {{"int", "vertex_indices", "uchar"}}, {{3, 0, 1, 2}}}};
      const PlyMesh mesh = loadPlyMesh(plyFile(format, elements), "m.ply", kPlyContext);
      ASSERT_EQ(mesh.uvs.size(), 1u);
      EXPECT_EQ(mesh.uvs[0][0], glm::vec2(0.1f, -2.5f));
      EXPECT_EQ(mesh.uvs[0][1], glm::vec2(0.0f));
      EXPECT_EQ(mesh.uvs[0][2], glm::vec2(1e-3f, 0.3f));
    }
  }
}

TEST(PlyMeshUvs, FilesWithoutUvsHaveNone) {
  for (const std::string& format : kFormats) {
    SCOPED_TRACE(format);
    for (const Layout& layout : kLayouts) {
      const PlyMesh mesh =
          loadPlyMesh(plyFile(format, meshElements(layout)), "plain.ply", kPlyContext);
      EXPECT_EQ(mesh.triangles.size(), 7u);
      EXPECT_TRUE(mesh.uvs.empty());
    }
  }
}

// ---- Malformed files ----

// The message for `bytes`, checked to be one line naming the file and ending with the
// context; empty (and a test failure) if it loads or throws anything else.
std::string plyError(const std::string& bytes, const std::string& file = "bad.ply") {
  try {
    loadPlyTriangles(bytes, file, kPlyContext);
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(file + ": ", 0), 0u) << message;
    EXPECT_TRUE(
        message.size() >= kPlyContext.size() &&
        message.compare(message.size() - kPlyContext.size(), kPlyContext.size(), kPlyContext) == 0)
        << message;
    return message;
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

#define EXPECT_PLY_ERROR(bytes, expected)                                                    \
  do {                                                                                       \
    const std::string message_ = plyError(bytes);                                            \
    EXPECT_NE(message_.find(expected), std::string::npos) << "message: " << message_ << "\n" \
                                                          << "expected: " << (expected);     \
  } while (0)

// Lines 1-9 the header, 10-12 the vertices, 13 the face.
const std::string kHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
const std::string kVertexLines = "0 0 0\n1 0 0\n0 1 0\n";
const std::string kAscii = kHeader + kVertexLines + "3 0 1 2\n";

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST(PlyMesh, ValidAsciiBaseline) {
  EXPECT_EQ(loadPlyTriangles(kAscii, "good.ply", kPlyContext).size(), 1u);
}

TEST(PlyMesh, HeaderErrorsNameTheLine) {
  EXPECT_PLY_ERROR("", "bad.ply: line 1: not a PLY file (it is empty)");
  EXPECT_PLY_ERROR("plx\n" + kAscii.substr(4), "bad.ply: line 1: not a PLY file");
  EXPECT_PLY_ERROR(replaced(kAscii, "ascii", "binary_middle_endian"),
                   "bad.ply: line 2: unknown format 'binary_middle_endian'");
  EXPECT_PLY_ERROR(replaced(kAscii, "ascii", "asci"),
                   "line 2: unknown format 'asci' (did you mean 'ascii'?)");
  EXPECT_PLY_ERROR(replaced(kAscii, "1.0", "2.0"), "line 2: unsupported format version '2.0'");
  EXPECT_PLY_ERROR(replaced(kAscii, "format ascii 1.0\n", ""),
                   "line 8: the header has no 'format' line");
  EXPECT_PLY_ERROR(replaced(kAscii, "property float z", "property float16 z"),
                   "bad.ply: line 6: unknown property type 'float16'");
  EXPECT_PLY_ERROR(replaced(kAscii, "int vertex_indices", "unit vertex_indices"),
                   "line 8: unknown property type 'unit' (did you mean 'uint'?)");
  EXPECT_PLY_ERROR(replaced(kAscii, "list uchar", "list float"),
                   "line 8: the count type of list 'vertex_indices' is 'float'");
  EXPECT_PLY_ERROR(replaced(kAscii, "list uchar int", "list uchar"),
                   "line 8: a list property needs a count type, an item type and a name");
  EXPECT_PLY_ERROR(kHeader.substr(0, kHeader.find("end_header")),
                   "bad.ply: line 8: the file ends in the header (no 'end_header' line)");
  EXPECT_PLY_ERROR(replaced(kAscii, "end_header", "end_header x"),
                   "line 9: unexpected 'x' after 'end_header'");
  EXPECT_PLY_ERROR(replaced(kAscii, "element vertex 3", "elemnt vertex 3"),
                   "line 3: unknown header keyword 'elemnt' (did you mean 'element'?)");
  EXPECT_PLY_ERROR(
      replaced(kAscii, "element vertex 3\n", "property uchar flags\nelement vertex 3\n"),
      "line 3: a property before any 'element' line");
  EXPECT_PLY_ERROR(replaced(kAscii, "vertex 3", "vertex -3"),
                   "line 3: element count '-3' is not a non-negative integer");
  EXPECT_PLY_ERROR(replaced(kAscii, "vertex 3", "vertex 99999999999999999999"),
                   "line 3: element count '99999999999999999999' is not a non-negative 64-bit");
  EXPECT_PLY_ERROR(replaced(kAscii, "face 1", "face 1 2"),
                   "line 7: unexpected '2' after the element count");
}

TEST(PlyMesh, MissingElementsAndPropertiesAreErrors) {
  EXPECT_PLY_ERROR(replaced(kAscii, "element vertex", "element point"),
                   "bad.ply: header: no 'vertex' element");
  EXPECT_PLY_ERROR(replaced(kAscii, "element face", "element polygon"),
                   "bad.ply: header: no 'face' element");
  EXPECT_PLY_ERROR(replaced(kAscii, "property float z", "property float w"),
                   "bad.ply: line 3: element 'vertex' has no property 'z'");
  EXPECT_PLY_ERROR(replaced(kAscii, "property float x", "property int x"),
                   "line 4: vertex property 'x' is 'int' (it must be float or double)");
  EXPECT_PLY_ERROR(replaced(kAscii, "property float y", "property list uchar float y"),
                   "line 5: vertex property 'y' is a list");
  EXPECT_PLY_ERROR(replaced(kAscii, "property float z\n", "property float z\nproperty double x\n"),
                   "line 7: element 'vertex' already has a property 'x' (line 4)");
  EXPECT_PLY_ERROR(replaced(kAscii, "vertex_indices", "corners"),
                   "line 7: element 'face' has no list property 'vertex_indices'");
  EXPECT_PLY_ERROR(replaced(kAscii, "list uchar int vertex_indices", "int vertex_indices"),
                   "line 8: 'vertex_indices' of element 'face' must be a list of an integer type");
  EXPECT_PLY_ERROR(
      replaced(kAscii, "list uchar int vertex_indices", "list uchar float vertex_index"),
      "line 8: 'vertex_index' of element 'face' must be a list of an integer type");
  EXPECT_PLY_ERROR(replaced(kAscii, "end_header", "element vertex 1\nproperty float x\nend_header"),
                   "line 9: a second 'vertex' element (the first is on line 3)");
  EXPECT_PLY_ERROR(kHeader.substr(0, kHeader.find("element face")) +
                       "element face 0\nproperty list uchar int vertex_indices\nend_header\n" +
                       kVertexLines,
                   "bad.ply: no faces (the header declares 0)");
}

TEST(PlyMesh, AsciiDataErrorsNameTheEntryAndLine) {
  // Counts that do not match the data.
  EXPECT_PLY_ERROR(replaced(kAscii, "1 0 0\n", "1 0\n"),
                   "bad.ply: vertex 1 (line 11): the line has 2 values, expected 3");
  EXPECT_PLY_ERROR(replaced(kAscii, "vertex 3", "vertex 4"),
                   "bad.ply: vertex 3 (line 13): the line has 4 values, expected 3");
  EXPECT_PLY_ERROR(replaced(kAscii, "vertex 3", "vertex 2"),
                   "bad.ply: face 0 (line 12): face has 0 vertices (need at least 3)");
  EXPECT_PLY_ERROR(kAscii + "3 2 1 0\n",
                   "bad.ply: line 14: data after the last element (do the header's counts match");
  EXPECT_PLY_ERROR(replaced(kAscii, "face 1", "face 2"),
                   "bad.ply: face 1 (line 14): the file ends before this entry (the header "
                   "declares 2 'face' entries)");
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "3 0 1"),
                   "bad.ply: face 0 (line 13): the line has 3 values, expected 4");
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "3 0 1 2 0"),
                   "bad.ply: face 0 (line 13): the line has 5 values, expected 4");
  // Numbers.
  EXPECT_PLY_ERROR(replaced(kAscii, "1 0 0\n", "1 abc 0\n"),
                   "bad.ply: vertex 1 (line 11): coordinate y 'abc' is not a number");
  EXPECT_PLY_ERROR(replaced(kAscii, "1 0 0\n", "1 0x1p3 0\n"),
                   "coordinate y '0x1p3' is not a number");
  EXPECT_PLY_ERROR(replaced(kAscii, "0 0 0\n", "nan 0 0\n"),
                   "bad.ply: vertex 0 (line 10): coordinate is not finite (x = 'nan')");
  EXPECT_PLY_ERROR(replaced(kAscii, "0 1 0\n", "0 1 -inf\n"),
                   "bad.ply: vertex 2 (line 12): coordinate is not finite (z = '-inf')");
  EXPECT_PLY_ERROR(replaced(kAscii, "1 0 0\n", "1e39 0 0\n"),
                   "vertex 1 (line 11): coordinate is too large for a 32-bit float (x = '1e39')");
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "3 0 1.5 2"),
                   "bad.ply: face 0 (line 13): vertex index '1.5' is not an integer");
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "3.0 0 1 2"),
                   "face 0 (line 13): list 'vertex_indices' count '3.0' is not an integer");
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "300 0 1 2"),
                   "list 'vertex_indices' count '300' is out of range for its type 'uchar'");
  // Indices.
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "3 0 1 3"),
                   "bad.ply: face 0 (line 13): vertex index 3 out of range (file has 3 vertices)");
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "3 0 -1 2"),
                   "bad.ply: face 0 (line 13): negative vertex index -1");
  EXPECT_PLY_ERROR(replaced(kAscii, "3 0 1 2", "2 0 1"),
                   "bad.ply: face 0 (line 13): face has 2 vertices (need at least 3)");
  EXPECT_PLY_ERROR(
      replaced(replaced(kAscii, "list uchar int", "list char int"), "3 0 1 2", "-3 0 1 2"),
      "bad.ply: face 0 (line 13): list 'vertex_indices' has a negative count (-3)");
  // A huge count is refused before anything is allocated.
  EXPECT_PLY_ERROR(replaced(kAscii, "vertex 3", "vertex 4000000000"),
                   "bad.ply: line 3: element 'vertex' count 4000000000 cannot fit in the file");
  EXPECT_PLY_ERROR(replaced(kAscii, "face 1", "face 18446744073709551615"),
                   "bad.ply: line 7: element 'face' count 18446744073709551615 cannot fit");
}

// The little-endian file of the basic layout, its header length and the element rows.
struct BinaryCase {
  std::vector<Elem> elements = meshElements(kLayouts[0]);
  std::string file(const std::string& format = "binary_little_endian") const {
    return plyFile(format, elements);
  }
  std::size_t headerSize(const std::string& format = "binary_little_endian") const {
    return plyHeader(format, elements).size();
  }
};

TEST(PlyMesh, BinaryDataErrorsNameTheEntry) {
  {
    // Cut inside the last face: 4 faces of 13, 17, 21 and 13 bytes after 7 vertices of 12.
    const std::string file = BinaryCase().file();
    const std::string cut = file.substr(0, file.size() - 5);
    EXPECT_PLY_ERROR(cut, "bad.ply: face 3: truncated binary data (file ends at byte " +
                              std::to_string(cut.size()) + ")");
  }
  {
    BinaryCase c;
    const std::string cut = c.file().substr(0, c.headerSize() + 5 * 12 + 6);
    EXPECT_PLY_ERROR(cut, "bad.ply: vertex 5: truncated binary data (file ends at byte " +
                              std::to_string(cut.size()) + ";");
  }
  for (const std::string& format : {kFormats[1], kFormats[2]}) {
    SCOPED_TRACE(format);
    BinaryCase c;
    c.elements[1].rows[1][2] = 7;
    EXPECT_PLY_ERROR(c.file(format),
                     "bad.ply: face 1: vertex index 7 out of range (file has 7 vertices)");
    c = BinaryCase();
    c.elements[1].rows[2][1] = -1;
    EXPECT_PLY_ERROR(c.file(format), "bad.ply: face 2: negative vertex index -1");
    c = BinaryCase();
    c.elements[1].rows[0] = {2, 0, 1};
    EXPECT_PLY_ERROR(c.file(format), "bad.ply: face 0: face has 2 vertices (need at least 3)");
    c = BinaryCase();
    c.elements[0].rows[3][1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_PLY_ERROR(c.file(format), "bad.ply: vertex 3: coordinate is not finite (y = nan)");
    c = BinaryCase();
    c.elements[0].rows[4][2] = -std::numeric_limits<double>::infinity();
    EXPECT_PLY_ERROR(c.file(format), "bad.ply: vertex 4: coordinate is not finite (z = inf)");
    c = BinaryCase();
    for (Prop& p : c.elements[0].props) p.type = "double";
    c.elements[0].rows[3][0] = 1e300;
    EXPECT_PLY_ERROR(c.file(format),
                     "bad.ply: vertex 3: coordinate is too large for a 32-bit float (x = 1e+300)");
    c = BinaryCase();
    c.elements[1].props[0].countType = "char";
    c.elements[1].rows[1] = {-1};
    EXPECT_PLY_ERROR(c.file(format),
                     "bad.ply: face 1: list 'vertex_indices' has a negative count (-1)");
    // A list count larger than the rest of the file could hold.
    c = BinaryCase();
    c.elements[1].props[0].countType = "uint";
    std::string file = c.file(format);
    std::string huge;
    putBinary(huge, 4000000000.0, "uint", format == kFormats[2]);
    file.replace(c.headerSize(format) + 7 * 12, 4, huge);  // the count of face 0
    EXPECT_PLY_ERROR(file,
                     "bad.ply: face 0: list 'vertex_indices' count 4000000000 is more than the "
                     "rest of the file can hold");
    // Bytes the header does not account for.
    EXPECT_PLY_ERROR(BinaryCase().file(format) + "xyz",
                     "3 bytes of data after the last element (do the header's counts match");
  }
}

TEST(PlyMesh, HugeBinaryCountsAreRefusedBeforeAllocating) {
  const BinaryCase c;
  const std::string file = c.file();
  // Fixed-size entries: the exact check names the entry where the data runs out.
  const std::size_t dataBytes = file.size() - c.headerSize();
  EXPECT_PLY_ERROR(replaced(file, "vertex 7", "vertex 4000000000"),
                   "bad.ply: vertex " + std::to_string(dataBytes / 12) +
                       ": truncated binary data (file ends at byte " +
                       std::to_string(file.size() + 9) +
                       "; the header declares 4000000000 entries of 12 bytes");
  // Entries with lists: refused from the header.
  EXPECT_PLY_ERROR(replaced(file, "face 4", "face 4000000000"),
                   "bad.ply: line 8: element 'face' count 4000000000 cannot fit in the file");
  // An element nobody reads is checked too.
  std::vector<Elem> elements = c.elements;
  elements.push_back({"junk", {{"uchar", "tags", "uint"}}, {{0}}});
  EXPECT_PLY_ERROR(replaced(plyFile("binary_big_endian", elements), "junk 1", "junk 4294967295"),
                   "element 'junk' count 4294967295 cannot fit in the file");
}

TEST(PlyMesh, TristripErrors) {
  std::vector<Elem> elements = meshElements(kLayouts[0]);
  elements[1] = {"tristrips", {{"int", "vertex_indices", "int"}}, {{4, 0, 1, -2, 3}}};
  for (const std::string& format : kFormats) {
    SCOPED_TRACE(format);
    EXPECT_PLY_ERROR(plyFile(format, elements),
                     "tristrips 0" + std::string(format == "ascii" ? " (line 18)" : "") +
                         ": negative vertex index -2 (only -1, which restarts a strip, is "
                         "allowed)");
  }
  elements[1].rows = {{4, 0, 1, 7, 3}};
  EXPECT_PLY_ERROR(plyFile("binary_little_endian", elements),
                   "bad.ply: tristrips 0: vertex index 7 out of range (file has 7 vertices)");
  elements[1].rows = {{4, 0, 1, -1, 3}};
  EXPECT_PLY_ERROR(plyFile("ascii", elements), "bad.ply: no faces (the 'tristrips' element");
}

// Lines 1-12 the header, 13-15 the vertices, 16 the face.
const std::string kNormalHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
const std::string kNormalAscii = kNormalHeader + "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";

TEST(PlyMesh, NormalErrors) {
  ASSERT_EQ(loadPlyMesh(kNormalAscii, "good.ply", kPlyContext).normals.size(), 1u);
  // Only some of nx, ny, nz: the line of the first of them.
  const std::string needAll = " (a vertex normal needs all of 'nx', 'ny' and 'nz')" + kPlyContext;
  EXPECT_EQ(plyError(replaced(replaced(kNormalAscii, "property float ny\n", ""),
                              "property float nz\n", "")),
            "bad.ply: line 7: vertex property 'nx' without 'ny' and 'nz'" + needAll);
  EXPECT_EQ(plyError(replaced(kNormalAscii, "property float ny\n", "")),
            "bad.ply: line 7: vertex properties 'nx' and 'nz' without 'ny'" + needAll);
  EXPECT_EQ(plyError(replaced(kNormalAscii, "property float nx\n", "")),
            "bad.ply: line 7: vertex properties 'ny' and 'nz' without 'nx'" + needAll);
  EXPECT_EQ(plyError(replaced(kNormalAscii, "property float nx\nproperty float ny\n",
                              "property float ny\nproperty float nn\n")),
            "bad.ply: line 7: vertex properties 'ny' and 'nz' without 'nx'" + needAll);
  // Types, duplicates.
  EXPECT_EQ(plyError(replaced(kNormalAscii, "property float ny", "property uchar ny")),
            "bad.ply: line 8: vertex property 'ny' is 'uchar' (it must be float or double)" +
                kPlyContext);
  EXPECT_EQ(
      plyError(replaced(kNormalAscii, "property float nz", "property list uchar float nz")),
      "bad.ply: line 9: vertex property 'nz' is a list (it must be float or double)" + kPlyContext);
  EXPECT_EQ(
      plyError(
          replaced(kNormalAscii, "property float nz\n", "property float nz\nproperty double nx\n")),
      "bad.ply: line 10: element 'vertex' already has a property 'nx' (line 7)" + kPlyContext);
  // Values (ascii).
  // A normal that is not finite is read as 0 0 0 and counted (the scene loaders warn and use
  // the geometric normal there); the rest of the mesh is as written.
  for (const char* bad : {"1 0 0 0 nan 1\n", "1 0 0 0 0 -inf\n"}) {
    const PlyMesh mesh =
        loadPlyMesh(replaced(kNormalAscii, "1 0 0 0 0 1\n", bad), "n.ply", kPlyContext);
    EXPECT_EQ(mesh.nonFiniteNormals, 1u);
    const PlyMesh good = loadPlyMesh(kNormalAscii, "n.ply", kPlyContext);
    EXPECT_EQ(good.nonFiniteNormals, 0u);
    ASSERT_EQ(mesh.normals.size(), good.normals.size());
    size_t zeros = 0;
    for (size_t t = 0; t < mesh.normals.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        if (mesh.normals[t][k] == glm::dvec3(0.0)) {
          ++zeros;
        } else {
          EXPECT_EQ(mesh.normals[t][k], good.normals[t][k]);
        }
      }
    }
    EXPECT_GT(zeros, 0u);
  }
  EXPECT_EQ(plyError(replaced(kNormalAscii, "0 0 0 0 0 1\n", "0 0 0 1e39 0 1\n")),
            "bad.ply: vertex 0 (line 13): normal is too large for a 32-bit float (nx = '1e39')" +
                kPlyContext);
  EXPECT_EQ(plyError(replaced(kNormalAscii, "1 0 0 0 0 1\n", "1 0 0 0 abc 1\n")),
            "bad.ply: vertex 1 (line 14): normal ny 'abc' is not a number" + kPlyContext);
  // Values (binary), for entries of one size and, with a vertex list, of varying size.
  for (const std::string& format : {kFormats[1], kFormats[2]}) {
    for (const bool list : {false, true}) {
      SCOPED_TRACE(format + (list ? ", vertex list" : ""));
      std::vector<Elem> elements = meshElements(kLayouts[0]);
      elements[0] = normalVertices("float", list);
      // Properties: nz x flags nx y z ny.
      elements[0].rows[3][6] = std::numeric_limits<double>::quiet_NaN();
      elements[0].rows[5][0] = -std::numeric_limits<double>::infinity();
      EXPECT_EQ(loadPlyMesh(plyFile(format, elements), "n.ply", kPlyContext).nonFiniteNormals, 2u);
      elements[0] = normalVertices("double", list);
      elements[0].rows[2][3] = 1e300;
      EXPECT_EQ(
          plyError(plyFile(format, elements)),
          "bad.ply: vertex 2: normal is too large for a 32-bit float (nx = 1e+300)" + kPlyContext);
    }
  }
}

TEST(PlyMeshUvs, TheFirstWholePairIsRead) {
  // u, v before s, t, whatever the header order; a name alone does not count when a later
  // pair is whole (pbrt-v4 reads that pair too).
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty float s\nproperty float t\nproperty float u\n"
      "property float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string data = "0 0 0 1 2 3 4\n1 0 0 5 6 7 8\n0 1 0 9 10 11 12\n3 0 1 2\n";
  PlyMesh mesh = loadPlyMesh(header + data, "m.ply", kPlyContext);
  ASSERT_EQ(mesh.uvs.size(), 1u);
  EXPECT_EQ(mesh.uvs[0][0], glm::vec2(3, 4));
  EXPECT_EQ(mesh.uvs[0][2], glm::vec2(11, 12));
  mesh = loadPlyMesh(replaced(header, "property float v\n", "property float w\n") + data, "m.ply",
                     kPlyContext);
  ASSERT_EQ(mesh.uvs.size(), 1u);
  EXPECT_EQ(mesh.uvs[0][0], glm::vec2(1, 2));
  EXPECT_EQ(mesh.uvs[0][1], glm::vec2(5, 6));
}

// Lines 1-11 the header, 12-14 the vertices, 15 the face.
const std::string kUvHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nproperty float u\nproperty float v\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
const std::string kUvAscii = kUvHeader + "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n";

TEST(PlyMeshUvs, UvErrors) {
  ASSERT_EQ(loadPlyMesh(kUvAscii, "good.ply", kPlyContext).uvs.size(), 1u);
  // One of a pair alone: its line.
  EXPECT_EQ(plyError(replaced(kUvAscii, "property float v\n", "")),
            "bad.ply: line 7: vertex property 'u' without 'v' (texture coordinates need both "
            "'u' and 'v')" +
                kPlyContext);
  EXPECT_EQ(plyError(replaced(kUvAscii, "property float u\n", "property float w\n")),
            "bad.ply: line 8: vertex property 'v' without 'u' (texture coordinates need both "
            "'u' and 'v')" +
                kPlyContext);
  EXPECT_EQ(plyError(replaced(replaced(kUvAscii, "property float u\n", "property float q\n"),
                              "property float v\n", "property double texture_t\n")),
            "bad.ply: line 8: vertex property 'texture_t' without 'texture_s' (texture "
            "coordinates need both 'texture_s' and 'texture_t')" +
                kPlyContext);
  // Types, duplicates.
  EXPECT_EQ(plyError(replaced(kUvAscii, "property float v", "property ushort v")),
            "bad.ply: line 8: vertex property 'v' is 'ushort' (it must be float or double)" +
                kPlyContext);
  EXPECT_EQ(
      plyError(replaced(kUvAscii, "property float u", "property list uchar float u")),
      "bad.ply: line 7: vertex property 'u' is a list (it must be float or double)" + kPlyContext);
  EXPECT_EQ(
      plyError(replaced(kUvAscii, "property float v\n", "property float v\nproperty double u\n")),
      "bad.ply: line 9: element 'vertex' already has a property 'u' (line 7)" + kPlyContext);
  // Values (ascii).
  EXPECT_EQ(
      plyError(replaced(kUvAscii, "1 0 0 1 0\n", "1 0 0 nan 0\n")),
      "bad.ply: vertex 1 (line 13): texture coordinate is not finite (u = 'nan')" + kPlyContext);
  EXPECT_EQ(
      plyError(replaced(kUvAscii, "0 1 0 0 1\n", "0 1 0 0 -inf\n")),
      "bad.ply: vertex 2 (line 14): texture coordinate is not finite (v = '-inf')" + kPlyContext);
  EXPECT_EQ(plyError(replaced(kUvAscii, "0 0 0 0 0\n", "0 0 0 0 1e39\n")),
            "bad.ply: vertex 0 (line 12): texture coordinate is too large for a 32-bit float "
            "(v = '1e39')" +
                kPlyContext);
  EXPECT_EQ(
      plyError(replaced(kUvAscii, "1 0 0 1 0\n", "1 0 0 abc 0\n")),
      "bad.ply: vertex 1 (line 13): texture coordinate u 'abc' is not a number" + kPlyContext);
  // Values (binary), for entries of one size and, with a vertex list, of varying size.
  for (const std::string& format : {kFormats[1], kFormats[2]}) {
    for (const bool list : {false, true}) {
      SCOPED_TRACE(format + (list ? ", vertex list" : ""));
      std::vector<Elem> elements = meshElements(kLayouts[0]);
      // Properties: x v flags y u z.
      elements[0] = uvVertices("float", kUvNames[0], list);
      elements[0].rows[3][1] = std::numeric_limits<double>::quiet_NaN();
      EXPECT_EQ(plyError(plyFile(format, elements)),
                "bad.ply: vertex 3: texture coordinate is not finite (v = nan)" + kPlyContext);
      elements[0] = uvVertices("float", kUvNames[2], list);
      elements[0].rows[5][4] = -std::numeric_limits<double>::infinity();
      EXPECT_EQ(
          plyError(plyFile(format, elements)),
          "bad.ply: vertex 5: texture coordinate is not finite (texture_u = inf)" + kPlyContext);
      elements[0] = uvVertices("double", kUvNames[1], list);
      elements[0].rows[2][4] = 1e300;
      EXPECT_EQ(plyError(plyFile(format, elements)),
                "bad.ply: vertex 2: texture coordinate is too large for a 32-bit float (s = "
                "1e+300)" +
                    kPlyContext);
    }
  }
}

TEST(PlyMesh, MessagesCarryTheContextAndEscapeControlCharacters) {
  const std::string message = plyError(replaced(kAscii, "1 0 0\n", "1 \x01\x02 0\n"));
  EXPECT_NE(message.find("coordinate y '\\x01\\x02' is not a number"), std::string::npos)
      << message;
}

// Every prefix of a file and thousands of random corruptions: each loads or throws
// InputError, never anything else (run under a sanitizer, nothing out of bounds either).
TEST(PlyMesh, TruncationsAndCorruptionsNeverCrash) {
  std::mt19937 rng(12345);
  for (const std::string& format : kFormats) {
    SCOPED_TRACE(format);
    const std::string file = plyFile(format, meshElements(kLayouts[5]));
    const std::size_t headerSize = plyHeader(format, meshElements(kLayouts[5])).size();
    auto tryLoad = [&](const std::string& bytes) {
      try {
        const PlyMesh mesh = loadPlyMesh(bytes, "fuzz.ply", kPlyContext);
        ASSERT_TRUE(mesh.normals.empty() || mesh.normals.size() == mesh.triangles.size());
        for (const Triangles* list : {&mesh.triangles, &mesh.normals}) {
          for (const auto& tri : *list) {
            for (const glm::dvec3& v : tri) {
              ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
            }
          }
        }
      } catch (const InputError&) {
      }
    };
    for (std::size_t n = 0; n < file.size(); ++n) tryLoad(file.substr(0, n));
    for (int round = 0; round < 3000; ++round) {
      std::string bytes = file;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < edits; ++k) {
        // Half of the edits in the header, where one byte changes the meaning of the rest.
        const std::size_t at = rng() % 2 ? rng() % headerSize : rng() % bytes.size();
        const char* interesting = "0123456789 \n-";
        bytes[at] = rng() % 2 ? interesting[rng() % 13] : static_cast<char>(rng());
      }
      tryLoad(bytes);
    }
  }
}

// The same with texture coordinates and normals, for entries of one size and of varying size.
TEST(PlyMeshUvs, TruncationsAndCorruptionsNeverCrash) {
  std::mt19937 rng(54321);
  for (const std::string& format : kFormats) {
    for (const bool list : {false, true}) {
      SCOPED_TRACE(format + (list ? ", vertex list" : ""));
      std::vector<Elem> elements = meshElements(kLayouts[0]);
      elements[0] = uvVertices("float", kUvNames[3], list, /*normals=*/true);
      const std::string file = plyFile(format, elements);
      const std::size_t headerSize = plyHeader(format, elements).size();
      auto tryLoad = [&](const std::string& bytes) {
        try {
          const PlyMesh mesh = loadPlyMesh(bytes, "fuzz.ply", kPlyContext);
          ASSERT_TRUE(mesh.uvs.empty() || mesh.uvs.size() == mesh.triangles.size());
          for (const auto& tri : mesh.uvs) {
            for (const glm::vec2& uv : tri) ASSERT_TRUE(std::isfinite(uv.x) && std::isfinite(uv.y));
          }
        } catch (const InputError&) {
        }
      };
      for (std::size_t n = 0; n < file.size(); ++n) tryLoad(file.substr(0, n));
      for (int round = 0; round < 1000; ++round) {
        std::string bytes = file;
        const int edits = 1 + static_cast<int>(rng() % 4);
        for (int k = 0; k < edits; ++k) {
          const std::size_t at = rng() % 2 ? rng() % headerSize : rng() % bytes.size();
          const char* interesting = "0123456789 \n-";
          bytes[at] = rng() % 2 ? interesting[rng() % 13] : static_cast<char>(rng());
        }
        tryLoad(bytes);
      }
    }
  }
}

}  // namespace
}  // namespace pt
