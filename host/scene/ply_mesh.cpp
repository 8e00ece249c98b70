// PLY loading: the header is parsed into elements and properties and checked, then the data
// is decoded element by element straight from the bytes (memcpy and byte swaps for binary,
// std::from_chars for ascii), every size checked against what is left of the file before
// anything is read or allocated.
#include "scene/ply_mesh.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <string_view>

#include "common/check.h"
#include "scene/json_reader.h"

namespace pt::scene_detail {

namespace {

using IndexTri = std::array<std::uint32_t, 3>;

enum class Format { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

enum class Type : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

struct TypeName {
  std::string_view name;
  Type type;
};

// The classic names first: typeName() reports a type by its first entry.
constexpr std::array<TypeName, 16> kTypeNames{{{"char", Type::kInt8},
                                               {"uchar", Type::kUint8},
                                               {"short", Type::kInt16},
                                               {"ushort", Type::kUint16},
                                               {"int", Type::kInt32},
                                               {"uint", Type::kUint32},
                                               {"float", Type::kFloat32},
                                               {"double", Type::kFloat64},
                                               {"int8", Type::kInt8},
                                               {"uint8", Type::kUint8},
                                               {"int16", Type::kInt16},
                                               {"uint16", Type::kUint16},
                                               {"int32", Type::kInt32},
                                               {"uint32", Type::kUint32},
                                               {"float32", Type::kFloat32},
                                               {"float64", Type::kFloat64}}};

std::size_t sizeOf(Type type) {
  switch (type) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 1;
}

bool isInteger(Type type) {
  return type != Type::kFloat32 && type != Type::kFloat64;
}

std::string typeName(Type type) {
  for (const TypeName& t : kTypeNames) {
    if (t.type == type) return std::string(t.name);
  }
  return "?";
}

// The range of an integer type, for ascii values.
std::int64_t minOf(Type type) {
  switch (type) {
    case Type::kInt8:
      return std::numeric_limits<std::int8_t>::min();
    case Type::kInt16:
      return std::numeric_limits<std::int16_t>::min();
    case Type::kInt32:
      return std::numeric_limits<std::int32_t>::min();
    default:
      return 0;
  }
}

std::int64_t maxOf(Type type) {
  switch (type) {
    case Type::kInt8:
      return std::numeric_limits<std::int8_t>::max();
    case Type::kUint8:
      return std::numeric_limits<std::uint8_t>::max();
    case Type::kInt16:
      return std::numeric_limits<std::int16_t>::max();
    case Type::kUint16:
      return std::numeric_limits<std::uint16_t>::max();
    case Type::kInt32:
      return std::numeric_limits<std::int32_t>::max();
    default:
      return std::numeric_limits<std::uint32_t>::max();
  }
}

// One value of type T from possibly unaligned bytes, reversing them when the file's byte
// order differs from ours.
template <typename T>
T load(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T value;
  std::memcpy(&value, b, sizeof(T));
  return value;
}

// Integer types only (the header check guarantees it where this is called).
std::int64_t loadInteger(const unsigned char* p, Type type, bool swap) {
  switch (type) {
    case Type::kInt8:
      return load<std::int8_t>(p, swap);
    case Type::kUint8:
      return load<std::uint8_t>(p, swap);
    case Type::kInt16:
      return load<std::int16_t>(p, swap);
    case Type::kUint16:
      return load<std::uint16_t>(p, swap);
    case Type::kInt32:
      return load<std::int32_t>(p, swap);
    case Type::kUint32:
      return load<std::uint32_t>(p, swap);
    case Type::kFloat32:
    case Type::kFloat64:
      break;
  }
  return 0;
}

// Float types only.
double loadReal(const unsigned char* p, Type type, bool swap) {
  if (type == Type::kFloat64) return load<double>(p, swap);
  return load<float>(p, swap);
}

bool isPlyBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}

// Splits off the next blank-separated token of `rest`; empty when none is left.
std::string_view nextToken(std::string_view& rest) {
  std::size_t i = 0;
  while (i < rest.size() && isPlyBlank(rest[i])) ++i;
  std::size_t end = i;
  while (end < rest.size() && !isPlyBlank(rest[end])) ++end;
  const std::string_view token = rest.substr(i, end - i);
  rest.remove_prefix(end);
  return token;
}

std::size_t countTokens(std::string_view line) {
  std::size_t n = 0;
  while (!nextToken(line).empty()) ++n;
  return n;
}

// from_chars takes no '+' sign: drop one, but not from "+-3" or "++3".
bool skipPlyPlus(std::string_view* token) {
  if (token->empty() || (*token)[0] != '+') return true;
  token->remove_prefix(1);
  return !token->empty() && (*token)[0] != '+' && (*token)[0] != '-';
}

enum class Parse { kOk, kNotNumber, kOutOfRange };

Parse parseInteger(std::string_view token, std::int64_t* value) {
  if (!skipPlyPlus(&token)) return Parse::kNotNumber;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), *value);
  if (ptr != token.data() + token.size()) return Parse::kNotNumber;
  if (ec == std::errc::result_out_of_range) return Parse::kOutOfRange;
  return ec == std::errc() ? Parse::kOk : Parse::kNotNumber;
}

// A whole token as a T (float or double). from_chars also takes "inf" and "nan", left for
// the caller to report; an overflow becomes an infinity, an underflow a zero.
template <typename T>
bool parsePlyReal(std::string_view token, T* value) {
  if (!skipPlyPlus(&token)) return false;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), *value,
                                         std::chars_format::general);
  if (ptr != token.data() + token.size()) return false;
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves the value alone: decide by the exponent's sign.
    const std::size_t e = token.find_first_of("eE");
    const bool negativeExponent =
        e != std::string_view::npos && e + 1 < token.size() && token[e + 1] == '-';
    const T magnitude = negativeExponent ? T(0) : std::numeric_limits<T>::infinity();
    *value = token[0] == '-' ? -magnitude : magnitude;
    return true;
  }
  return ec == std::errc();
}

struct Property {
  std::string name;
  Type type = Type::kFloat32;  // the scalar's type, or the type of a list's items
  bool isList = false;
  Type countType = Type::kUint8;
  std::size_t line = 0;
};

enum class Role { kOther, kVertex, kFace, kTristrips };

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::size_t line = 0;  // of its "element" line
  Role role = Role::kOther;
  std::vector<Property> properties;
  std::array<std::size_t, 3> coords{};   // vertex: the properties x, y and z
  bool hasNormals = false;               // vertex: nx, ny and nz are all there
  std::array<std::size_t, 3> normals{};  // vertex: the properties nx, ny and nz
  bool hasUvs = false;                   // vertex: a pair of texture coordinate properties
  std::array<std::size_t, 2> uvs{};      // vertex: the properties u and v (or s and t, ...)
  std::size_t indexList = 0;             // face, tristrips: the vertex index list
};

// The property names of a vertex's coordinates and of its normal's components, which are
// also their names in messages.
constexpr std::array<std::string_view, 3> kCoordinateNames{"x", "y", "z"};
constexpr std::array<std::string_view, 3> kNormalNames{"nx", "ny", "nz"};

// What a vertex property holds, for reading and for messages.
struct VectorKind {
  const char* what;  // "coordinate" or "normal"
  const std::array<std::string_view, 3>& names;
};
const VectorKind kCoordinate{"coordinate", kCoordinateNames};
const VectorKind kNormal{"normal", kNormalNames};

// The property names of a vertex's texture coordinates that pbrt-v4's PLY reader accepts, in
// its order of preference.
constexpr std::array<std::array<std::string_view, 2>, 4> kUvNames{
    {{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}}};

class PlyReader {
 public:
  PlyReader(const std::string& bytes, const std::string& file, const std::string& context)
      : bytes_(bytes),
        data_(reinterpret_cast<const unsigned char*>(bytes.data())),
        file_(file),
        context_(context) {}

  PlyMesh load() {
    parseHeader();
    checkHeader();
    if (format_ == Format::kAscii) {
      readAscii();
    } else {
      readBinary();
    }
    if (tris_.empty()) fail("", "no faces (the 'tristrips' element holds no triangle)");
    PT_CHECK(vertices_.size() == vertexCount_, "PLY vertices not all read");
    PT_CHECK(normals_.empty() || normals_.size() == vertexCount_, "PLY normals not all read");
    PT_CHECK(uvs_.empty() || uvs_.size() == vertexCount_, "PLY texture coordinates not all read");
    PlyMesh mesh;
    mesh.triangles.reserve(tris_.size());
    for (const IndexTri& t : tris_) {
      mesh.triangles.push_back({vertices_[t[0]], vertices_[t[1]], vertices_[t[2]]});
    }
    mesh.nonFiniteNormals = nonFiniteNormals_;
    if (!normals_.empty()) {
      mesh.normals.reserve(tris_.size());
      for (const IndexTri& t : tris_) {
        mesh.normals.push_back({normals_[t[0]], normals_[t[1]], normals_[t[2]]});
      }
    }
    if (!uvs_.empty()) {
      mesh.uvs.reserve(tris_.size());
      for (const IndexTri& t : tris_) mesh.uvs.push_back({uvs_[t[0]], uvs_[t[1]], uvs_[t[2]]});
    }
    return mesh;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throwInputError(file_, where, problem + context_);
  }
  [[noreturn]] void failLine(std::size_t line, const std::string& problem) const {
    fail("line " + std::to_string(line), problem);
  }
  // An error in entry `index` of element `e`; `line` is its line in an ascii file.
  [[noreturn]] void failEntry(const Element& e, std::uint64_t index, const std::string& problem,
                              std::size_t line = 0) const {
    std::string where = e.name + " " + std::to_string(index);
    if (line > 0) where += " (line " + std::to_string(line) + ")";
    fail(where, problem);
  }

  // ---- Header ----

  void parseHeader() {
    const std::string_view text(bytes_);
    std::size_t pos = 0;
    std::size_t line = 0;
    bool sawFormat = false;
    while (true) {
      if (pos >= text.size()) {
        if (line == 0) failLine(1, "not a PLY file (it is empty)");
        failLine(line, "the file ends in the header (no 'end_header' line)");
      }
      const std::size_t end = std::min(text.find('\n', pos), text.size());
      std::string_view rest = text.substr(pos, end - pos);
      pos = end + 1;
      ++line;
      if (!rest.empty() && rest.back() == '\r') rest.remove_suffix(1);
      if (line == 1) {
        std::string_view magic = rest;
        if (nextToken(magic) != "ply" || !nextToken(magic).empty()) {
          failLine(1,
                   "not a PLY file (the first line must be 'ply', not " + singleQuoted(rest) + ")");
        }
        continue;
      }
      const std::string_view keyword = nextToken(rest);
      if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
      if (keyword == "format") {
        if (sawFormat) failLine(line, "a second 'format' line");
        format(line, rest);
        sawFormat = true;
      } else if (keyword == "element") {
        element(line, rest);
      } else if (keyword == "property") {
        property(line, rest);
      } else if (keyword == "end_header") {
        noMoreTokens(line, rest, "'end_header'");
        if (!sawFormat) failLine(line, "the header has no 'format' line");
        headerLines_ = line;
        dataStart_ = std::min(pos, text.size());
        return;
      } else {
        failLine(line, "unknown header keyword " + singleQuoted(keyword) +
                           didYouMean(keyword, {"format", "comment", "obj_info", "element",
                                                "property", "end_header"}));
      }
    }
  }

  void noMoreTokens(std::size_t line, std::string_view rest, const std::string& after) const {
    const std::string_view extra = nextToken(rest);
    if (!extra.empty()) failLine(line, "unexpected " + singleQuoted(extra) + " after " + after);
  }

  void format(std::size_t line, std::string_view rest) {
    const std::string_view name = nextToken(rest);
    const std::string_view version = nextToken(rest);
    if (version.empty()) {
      failLine(line, "the format line needs a format and a version, e.g. 'format ascii 1.0'");
    }
    if (name == "ascii") {
      format_ = Format::kAscii;
    } else if (name == "binary_little_endian") {
      format_ = Format::kBinaryLittleEndian;
    } else if (name == "binary_big_endian") {
      format_ = Format::kBinaryBigEndian;
    } else {
      failLine(line, "unknown format " + singleQuoted(name) +
                         didYouMean(name, {"ascii", "binary_little_endian", "binary_big_endian"}));
    }
    if (version != "1.0") {
      failLine(line, "unsupported format version " + singleQuoted(version) + " (only 1.0 is)");
    }
    noMoreTokens(line, rest, "the format version");
  }

  void element(std::size_t line, std::string_view rest) {
    const std::string_view name = nextToken(rest);
    const std::string_view countToken = nextToken(rest);
    if (countToken.empty()) failLine(line, "the element line needs a name and a count");
    Element e;
    e.name = name;
    e.line = line;
    const auto [ptr, ec] =
        std::from_chars(countToken.data(), countToken.data() + countToken.size(), e.count);
    if (ec != std::errc() || ptr != countToken.data() + countToken.size()) {
      failLine(line, "element count " + singleQuoted(countToken) + " is not a non-negative " +
                         (ec == std::errc::result_out_of_range ? "64-bit " : "") + "integer");
    }
    noMoreTokens(line, rest, "the element count");
    if (name == "vertex") e.role = Role::kVertex;
    if (name == "face") e.role = Role::kFace;
    if (name == "tristrips") e.role = Role::kTristrips;
    // Two elements of a role would make the indices ambiguous; other names do not matter.
    if (e.role != Role::kOther) {
      for (const Element& other : elements_) {
        if (other.name == e.name) {
          failLine(line, "a second '" + e.name + "' element (the first is on line " +
                             std::to_string(other.line) + ")");
        }
      }
    }
    elements_.push_back(std::move(e));
  }

  Type parseType(std::size_t line, std::string_view name) const {
    for (const TypeName& t : kTypeNames) {
      if (t.name == name) return t.type;
    }
    std::vector<std::string_view> names;
    for (const TypeName& t : kTypeNames) names.push_back(t.name);
    failLine(line, "unknown property type " + singleQuoted(name) + didYouMean(name, names));
  }

  void property(std::size_t line, std::string_view rest) {
    if (elements_.empty()) failLine(line, "a property before any 'element' line");
    Property p;
    p.line = line;
    std::string_view first = nextToken(rest);
    if (first == "list") {
      const std::string_view countType = nextToken(rest);
      const std::string_view itemType = nextToken(rest);
      const std::string_view name = nextToken(rest);
      if (name.empty()) {
        failLine(line,
                 "a list property needs a count type, an item type and a name, e.g. "
                 "'property list uchar int vertex_indices'");
      }
      p.isList = true;
      p.countType = parseType(line, countType);
      p.type = parseType(line, itemType);
      p.name = name;
      if (!isInteger(p.countType)) {
        failLine(line, "the count type of list '" + p.name + "' is '" + typeName(p.countType) +
                           "' (it must be an integer type)");
      }
    } else {
      const std::string_view name = nextToken(rest);
      if (name.empty()) {
        failLine(line, "a property needs a type and a name, e.g. 'property float x'");
      }
      p.type = parseType(line, first);
      p.name = name;
    }
    noMoreTokens(line, rest, "the property name");
    elements_.back().properties.push_back(std::move(p));
  }

  // Finds the one property of `e` named one of `names`: npos if none; an error if two.
  std::size_t findProperty(const Element& e, std::initializer_list<std::string_view> names) const {
    std::size_t found = std::string::npos;
    for (std::size_t j = 0; j < e.properties.size(); ++j) {
      const Property& p = e.properties[j];
      if (std::find(names.begin(), names.end(), p.name) == names.end()) continue;
      if (found != std::string::npos) {
        failLine(p.line, "element '" + e.name + "' already has a property '" +
                             e.properties[found].name + "' (line " +
                             std::to_string(e.properties[found].line) + ")");
      }
      found = j;
    }
    return found;
  }

  void checkHeader() {
    const Element* vertex = nullptr;
    bool anyFaces = false;
    bool anyFaceEntries = false;
    for (Element& e : elements_) {
      if (e.role == Role::kVertex) {
        vertex = &e;
        for (std::size_t c = 0; c < 3; ++c) {
          const std::string name(kCoordinateNames[c]);
          const std::size_t j = findProperty(e, {name});
          if (j == std::string::npos) {
            failLine(e.line, "element 'vertex' has no property '" + name + "'");
          }
          checkRealProperty(e.properties[j]);
          e.coords[c] = j;
        }
        checkNormalProperties(e);
        checkUvProperties(e);
      } else if (e.role == Role::kFace || e.role == Role::kTristrips) {
        const std::size_t j = e.role == Role::kFace
                                  ? findProperty(e, {"vertex_indices", "vertex_index"})
                                  : findProperty(e, {"vertex_indices"});
        if (j == std::string::npos) {
          failLine(e.line, "element '" + e.name + "' has no list property 'vertex_indices'");
        }
        const Property& p = e.properties[j];
        if (!p.isList || !isInteger(p.type)) {
          failLine(p.line, "'" + p.name + "' of element '" + e.name + "' must be a list of an " +
                               "integer type, e.g. 'property list uchar int " + p.name + "'");
        }
        e.indexList = j;
        anyFaces = true;
        anyFaceEntries = anyFaceEntries || e.count > 0;
      }
    }
    if (vertex == nullptr) fail("header", "no 'vertex' element");
    if (!anyFaces) fail("header", "no 'face' element");
    if (!anyFaceEntries) fail("", "no faces (the header declares 0)");
    vertexCount_ = vertex->count;

    // Counts that could not fit in the file even at the smallest size of an entry, so that a
    // header claiming billions of entries is an error before anything is allocated. Binary
    // entries of one size are left to readBinaryElement, whose exact check can name the
    // entry where a truncated file ends.
    const std::uint64_t dataBytes = bytes_.size() - dataStart_;
    for (const Element& e : elements_) {
      if (e.properties.empty()) continue;
      if (format_ != Format::kAscii && !hasList(e)) continue;
      const std::uint64_t minBytes = minEntryBytes(e);
      // An ascii entry with p values takes at least 2p - 1 characters, plus a line break
      // before the next entry.
      const bool fits = format_ == Format::kAscii ? e.count <= (dataBytes + 1) / minBytes
                                                  : e.count <= dataBytes / minBytes;
      if (!fits) {
        failLine(e.line, "element '" + e.name + "' count " + std::to_string(e.count) +
                             " cannot fit in the file (each entry takes at least " +
                             std::to_string(minBytes) + " bytes, and the data after the " +
                             "header is " + std::to_string(dataBytes) + " bytes)");
      }
    }
  }

  // A vertex coordinate or normal component: a float or double scalar.
  void checkRealProperty(const Property& p) const {
    if (p.isList || isInteger(p.type)) {
      failLine(p.line, "vertex property '" + p.name + "' is " +
                           (p.isList ? "a list" : "'" + typeName(p.type) + "'") +
                           " (it must be float or double)");
    }
  }

  // Vertex normals: nx, ny and nz all or none. One or two of them alone is more likely a
  // writer's mistake than some other meaning of the names, so it is an error rather than
  // a mesh silently shaded flat.
  void checkNormalProperties(Element& e) const {
    std::array<std::size_t, 3> j{};
    std::vector<std::size_t> present;
    std::vector<std::size_t> missing;
    for (std::size_t c = 0; c < 3; ++c) {
      j[c] = findProperty(e, {kNormalNames[c]});
      (j[c] == std::string::npos ? missing : present).push_back(c);
    }
    if (present.empty()) return;
    if (!missing.empty()) {
      auto names = [](const std::vector<std::size_t>& cs) {
        std::string list;
        for (std::size_t k = 0; k < cs.size(); ++k) {
          list += std::string(k == 0 ? "" : " and ") + "'" + std::string(kNormalNames[cs[k]]) + "'";
        }
        return list;
      };
      // The line of the first normal property in the header.
      std::size_t first = present[0];
      for (std::size_t c : present) first = j[c] < j[first] ? c : first;
      failLine(e.properties[j[first]].line,
               std::string(present.size() == 1 ? "vertex property " : "vertex properties ") +
                   names(present) + " without " + names(missing) +
                   " (a vertex normal needs all of 'nx', 'ny' and 'nz')");
    }
    for (std::size_t c = 0; c < 3; ++c) checkRealProperty(e.properties[j[c]]);
    e.normals = j;
    e.hasNormals = true;
  }

  // Texture coordinates: the first of kUvNames' pairs that the vertex element has both of.
  // Without a whole pair, one name of a pair alone is an error, as for the normals.
  void checkUvProperties(Element& e) const {
    auto has = [&](std::string_view name) {
      return std::any_of(e.properties.begin(), e.properties.end(),
                         [&](const Property& p) { return p.name == name; });
    };
    for (const std::array<std::string_view, 2>& pair : kUvNames) {
      if (!has(pair[0]) || !has(pair[1])) continue;
      for (std::size_t c = 0; c < 2; ++c) {
        e.uvs[c] = findProperty(e, {pair[c]});
        checkRealProperty(e.properties[e.uvs[c]]);
      }
      e.hasUvs = true;
      return;
    }
    for (const Property& p : e.properties) {
      for (const std::array<std::string_view, 2>& pair : kUvNames) {
        for (std::size_t c = 0; c < 2; ++c) {
          if (p.name != pair[c]) continue;
          failLine(p.line, "vertex property '" + p.name + "' without '" + std::string(pair[1 - c]) +
                               "' (texture coordinates need both '" + std::string(pair[0]) +
                               "' and '" + std::string(pair[1]) + "')");
        }
      }
    }
  }

  static bool hasList(const Element& e) {
    return std::any_of(e.properties.begin(), e.properties.end(),
                       [](const Property& p) { return p.isList; });
  }

  // The fewest bytes an entry of `e` can take: all lists empty; in ascii, one character per
  // value and a blank or line break after it.
  std::uint64_t minEntryBytes(const Element& e) const {
    std::uint64_t bytes = 0;
    for (const Property& p : e.properties) {
      bytes += format_ == Format::kAscii ? 2 : sizeOf(p.isList ? p.countType : p.type);
    }
    return bytes;
  }

  // How many entries of `e` to reserve memory for: its count, but no more than the data
  // left could hold.
  std::size_t reserveFor(const Element& e, std::size_t pos) const {
    const std::uint64_t minBytes = std::max<std::uint64_t>(1, minEntryBytes(e));
    return static_cast<std::size_t>(
        std::min<std::uint64_t>(e.count, (bytes_.size() - pos) / minBytes + 1));
  }

  // ---- Faces, strips and vertices, shared by both encodings ----

  std::uint32_t checkedIndex(const Element& e, std::uint64_t entry, std::int64_t index,
                             std::size_t line) const {
    if (index < 0) {
      failEntry(
          e, entry,
          "negative vertex index " + std::to_string(index) +
              (e.role == Role::kTristrips ? " (only -1, which restarts a strip, is allowed)" : ""),
          line);
    }
    if (static_cast<std::uint64_t>(index) >= vertexCount_) {
      failEntry(e, entry,
                "vertex index " + std::to_string(index) + " out of range (file has " +
                    std::to_string(vertexCount_) + (vertexCount_ == 1 ? " vertex)" : " vertices)"),
                line);
    }
    return static_cast<std::uint32_t>(index);
  }

  // A polygon of n vertices, fanned as (0, i, i + 1); next() yields its indices in order.
  template <typename Next>
  void addPolygon(const Element& e, std::uint64_t entry, std::uint64_t n, std::size_t line,
                  Next&& next) {
    if (n < 3) {
      failEntry(e, entry,
                "face has " + std::to_string(n) + (n == 1 ? " vertex" : " vertices") +
                    " (need at least 3)",
                line);
    }
    const std::uint32_t first = checkedIndex(e, entry, next(), line);
    std::uint32_t previous = checkedIndex(e, entry, next(), line);
    for (std::uint64_t k = 2; k < n; ++k) {
      const std::uint32_t current = checkedIndex(e, entry, next(), line);
      tris_.push_back({first, previous, current});
      previous = current;
    }
  }

  // Triangle strips, -1 starting a new one: triangle k of a strip is (v_k, v_k+1, v_k+2),
  // the first two swapped for odd k so that all keep the winding of the first.
  template <typename Next>
  void addStrips(const Element& e, std::uint64_t entry, std::uint64_t n, std::size_t line,
                 Next&& next) {
    std::uint32_t a = 0;
    std::uint32_t b = 0;
    std::uint64_t inStrip = 0;
    for (std::uint64_t k = 0; k < n; ++k) {
      const std::int64_t index = next();
      if (index == -1) {
        inStrip = 0;
        continue;
      }
      const std::uint32_t c = checkedIndex(e, entry, index, line);
      // A repeated vertex is how strips are stitched or turned, not geometry: such
      // triangles are skipped here (the parity still counts them).
      if (inStrip >= 2 && a != b && b != c && a != c) {
        if ((inStrip - 2) % 2 == 0) {
          tris_.push_back({a, b, c});
        } else {
          tris_.push_back({b, a, c});
        }
      }
      a = b;
      b = c;
      ++inStrip;
    }
  }

  // Coordinates must be finite and, like every vertex the renderer sees, fit a float.
  // Normals too: the renderer keeps them as floats, and a finite double beyond that range
  // would leave little room for the scene's transform before it overflowed.
  void checkVector(const Element& e, std::uint64_t entry, const glm::dvec3& p,
                   const VectorKind& kind, std::size_t line) const {
    for (int c = 0; c < 3; ++c) {
      const double v = p[c];
      if (std::fabs(v) <= std::numeric_limits<float>::max()) continue;
      const std::string name(kind.names[static_cast<std::size_t>(c)]);
      if (!std::isfinite(v)) {
        failEntry(e, entry,
                  std::string(kind.what) + " is not finite (" + name + " = " +
                      (std::isnan(v) ? "nan" : "inf") + ")",
                  line);
      }
      failEntry(e, entry,
                std::string(kind.what) + " is too large for a 32-bit float (" + name + " = " +
                    formatNumber(v) + ")",
                line);
    }
  }

  // Texture coordinates must be finite and fit a float, as they are kept.
  void checkUv(const Element& e, std::uint64_t entry, const glm::dvec2& uv,
               std::size_t line) const {
    for (std::size_t c = 0; c < 2; ++c) {
      const double v = uv[static_cast<int>(c)];
      if (std::fabs(v) <= std::numeric_limits<float>::max()) continue;
      const std::string& name = e.properties[e.uvs[c]].name;
      if (!std::isfinite(v)) {
        failEntry(e, entry,
                  "texture coordinate is not finite (" + name + " = " +
                      (std::isnan(v) ? "nan" : "inf") + ")",
                  line);
      }
      failEntry(e, entry,
                "texture coordinate is too large for a 32-bit float (" + name + " = " +
                    formatNumber(v) + ")",
                line);
    }
  }

  // One decoded vertex, with its normal and texture coordinates where the file has them.
  void addVertex(const Element& e, std::uint64_t entry, const glm::dvec3& point,
                 const glm::dvec3& normal, const glm::dvec2& uv, std::size_t line) {
    checkVector(e, entry, point, kCoordinate, line);
    if (e.hasUvs) checkUv(e, entry, uv, line);
    vertices_.push_back(point);
    if (e.hasUvs) uvs_.push_back(glm::vec2(uv));
    if (!e.hasNormals) return;
    if (!std::isfinite(normal.x) || !std::isfinite(normal.y) || !std::isfinite(normal.z)) {
      ++nonFiniteNormals_;
      normals_.push_back(glm::dvec3(0.0));
      return;
    }
    checkVector(e, entry, normal, kNormal, line);
    normals_.push_back(normal);
  }

  // ---- Binary ----

  [[noreturn]] void failTruncated(const Element& e, std::uint64_t entry,
                                  const std::string& note = "") const {
    failEntry(
        e, entry,
        "truncated binary data (file ends at byte " + std::to_string(bytes_.size()) + note + ")");
  }

  void readBinary() {
    const bool fileLittle = format_ == Format::kBinaryLittleEndian;
    const bool swap = fileLittle != (std::endian::native == std::endian::little);
    std::size_t pos = dataStart_;
    for (const Element& e : elements_) pos = readBinaryElement(e, pos, swap);
    if (pos != bytes_.size()) {
      fail("byte " + std::to_string(pos),
           std::to_string(bytes_.size() - pos) +
               " bytes of data after the last element (do the header's counts match the data?)");
    }
  }

  // Decodes the entries of `e` from byte `pos`; returns where the next element starts.
  std::size_t readBinaryElement(const Element& e, std::size_t pos, bool swap) {
    if (e.properties.empty() || e.count == 0) return pos;
    const std::size_t size = bytes_.size();
    if (!hasList(e)) {
      // Entries of one size: the whole element is bounds-checked at once.
      const std::size_t stride = minEntryBytes(e);
      if (e.count > (size - pos) / stride) {
        failTruncated(e, (size - pos) / stride,
                      "; the header declares " + std::to_string(e.count) + " entries of " +
                          std::to_string(stride) + " bytes from byte " + std::to_string(pos));
      }
      if (e.role == Role::kVertex) readFixedVertices(e, data_ + pos, stride, swap);
      return pos + static_cast<std::size_t>(e.count) * stride;
    }

    reserveVertices(e, pos);
    if (e.role == Role::kFace) tris_.reserve(tris_.size() + reserveFor(e, pos));
    for (std::uint64_t i = 0; i < e.count; ++i) {
      glm::dvec3 point(0.0);
      glm::dvec3 normal(0.0);
      glm::dvec2 uv(0.0);
      for (std::size_t j = 0; j < e.properties.size(); ++j) {
        const Property& p = e.properties[j];
        if (!p.isList) {
          const std::size_t bytes = sizeOf(p.type);
          if (size - pos < bytes) failTruncated(e, i);
          if (e.role == Role::kVertex) {
            for (std::size_t c = 0; c < 3; ++c) {
              if (e.coords[c] == j) point[c] = loadReal(data_ + pos, p.type, swap);
              if (e.hasNormals && e.normals[c] == j) {
                normal[c] = loadReal(data_ + pos, p.type, swap);
              }
              if (c < 2 && e.hasUvs && e.uvs[c] == j) uv[c] = loadReal(data_ + pos, p.type, swap);
            }
          }
          pos += bytes;
          continue;
        }
        const std::size_t countBytes = sizeOf(p.countType);
        if (size - pos < countBytes) failTruncated(e, i);
        const std::int64_t n = loadInteger(data_ + pos, p.countType, swap);
        pos += countBytes;
        if (n < 0) {
          failEntry(e, i, "list '" + p.name + "' has a negative count (" + std::to_string(n) + ")");
        }
        const std::size_t itemBytes = sizeOf(p.type);
        if (static_cast<std::uint64_t>(n) > (size - pos) / itemBytes) {
          // A count that fits the data after the header is taken for a cut file; one that
          // does not is a wrong count.
          if (static_cast<std::uint64_t>(n) <= (size - dataStart_) / itemBytes) {
            failTruncated(e, i);
          }
          failEntry(e, i,
                    "list '" + p.name + "' count " + std::to_string(n) +
                        " is more than the rest of the file can hold (" +
                        std::to_string(size - pos) + " bytes left, " + std::to_string(itemBytes) +
                        " per item)");
        }
        const unsigned char* items = data_ + pos;
        pos += static_cast<std::size_t>(n) * itemBytes;
        if (j != e.indexList || e.role == Role::kOther || e.role == Role::kVertex) continue;
        auto next = [&, k = std::size_t{0}]() mutable {
          return loadInteger(items + itemBytes * k++, p.type, swap);
        };
        if (e.role == Role::kFace) {
          addPolygon(e, i, static_cast<std::uint64_t>(n), 0, next);
        } else {
          addStrips(e, i, static_cast<std::uint64_t>(n), 0, next);
        }
      }
      if (e.role == Role::kVertex) addVertex(e, i, point, normal, uv, 0);
    }
    return pos;
  }

  void reserveVertices(const Element& e, std::size_t pos) {
    if (e.role != Role::kVertex) return;
    vertices_.reserve(reserveFor(e, pos));
    if (e.hasNormals) normals_.reserve(reserveFor(e, pos));
    if (e.hasUvs) uvs_.reserve(reserveFor(e, pos));
  }

  void readFixedVertices(const Element& e, const unsigned char* base, std::size_t stride,
                         bool swap) {
    // Byte offsets and types of x, y, z, then nx, ny, nz, then u, v within an entry.
    std::array<std::size_t, 8> offset{};
    std::array<Type, 8> type{};
    for (std::size_t c = 0; c < 8; ++c) {
      if (c >= 3 && c < 6 && !e.hasNormals) continue;
      if (c >= 6 && !e.hasUvs) continue;
      const std::size_t property = c < 3 ? e.coords[c] : c < 6 ? e.normals[c - 3] : e.uvs[c - 6];
      for (std::size_t j = 0; j < property; ++j) offset[c] += sizeOf(e.properties[j].type);
      type[c] = e.properties[property].type;
    }
    auto vector = [&](const unsigned char* entry, std::size_t first) {
      return glm::dvec3(loadReal(entry + offset[first], type[first], swap),
                        loadReal(entry + offset[first + 1], type[first + 1], swap),
                        loadReal(entry + offset[first + 2], type[first + 2], swap));
    };
    auto uv = [&](const unsigned char* entry) {
      return glm::dvec2(loadReal(entry + offset[6], type[6], swap),
                        loadReal(entry + offset[7], type[7], swap));
    };
    const std::size_t count = static_cast<std::size_t>(e.count);
    vertices_.reserve(count);
    if (e.hasNormals) normals_.reserve(count);
    if (e.hasUvs) uvs_.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
      const unsigned char* entry = base + i * stride;
      addVertex(e, i, vector(entry, 0), e.hasNormals ? vector(entry, 3) : glm::dvec3(0.0),
                e.hasUvs ? uv(entry) : glm::dvec2(0.0), 0);
    }
  }

  // ---- Ascii: one entry per line ----

  // The next line holding anything but blanks (blank lines are tolerated anywhere); false
  // at the end of the file. line_ is its line number.
  bool nextLine(std::string_view* out) {
    const std::string_view text(bytes_);
    while (pos_ < text.size()) {
      const std::size_t end = std::min(text.find('\n', pos_), text.size());
      std::string_view line = text.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      std::string_view rest = line;
      if (!nextToken(rest).empty()) {
        *out = line;
        return true;
      }
    }
    return false;
  }

  void readAscii() {
    pos_ = dataStart_;
    line_ = headerLines_;
    for (const Element& e : elements_) readAsciiElement(e);
    std::string_view line;
    if (nextLine(&line)) {
      failLine(line_, "data after the last element (do the header's counts match the data?)");
    }
  }

  void readAsciiElement(const Element& e) {
    if (e.properties.empty() || e.count == 0) return;
    reserveVertices(e, pos_);
    if (e.role == Role::kFace) tris_.reserve(tris_.size() + reserveFor(e, pos_));
    const std::size_t propertyCount = e.properties.size();
    // Whether a list follows each property: then a short line's value count is a minimum.
    std::vector<bool> listAfter(propertyCount, false);
    for (std::size_t j = propertyCount; j-- > 1;) {
      listAfter[j - 1] = listAfter[j] || e.properties[j].isList;
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      std::string_view line;
      if (!nextLine(&line)) {
        failEntry(e, i,
                  "the file ends before this entry (the header declares " +
                      std::to_string(e.count) + " '" + e.name + "' entries)",
                  line_ + 1);
      }
      std::string_view rest = line;
      std::size_t consumed = 0;
      // The next value; `needed` is how many values at least, this one included, the
      // rest of the entry still needs (for the message when the line is too short).
      auto value = [&](std::uint64_t needed, bool exact) {
        const std::string_view token = nextToken(rest);
        if (token.empty()) {
          const std::size_t found = countTokens(line);
          failEntry(e, i,
                    "the line has " + std::to_string(found) + (found == 1 ? " value" : " values") +
                        ", expected " + (exact ? "" : "at least ") +
                        std::to_string(consumed + needed),
                    line_);
        }
        ++consumed;
        return token;
      };
      glm::dvec3 point(0.0);
      glm::dvec3 normal(0.0);
      glm::dvec2 uv(0.0);
      for (std::size_t j = 0; j < propertyCount; ++j) {
        const Property& p = e.properties[j];
        const std::size_t after = propertyCount - j - 1;
        if (!p.isList) {
          const std::string_view token = value(1 + after, !listAfter[j]);
          // Other properties are only counted: their values do not matter here.
          if (e.role != Role::kVertex) continue;
          for (std::size_t c = 0; c < 3; ++c) {
            if (e.coords[c] == j) point[c] = asciiReal(e, i, token, kCoordinate, c, p.type);
            if (e.hasNormals && e.normals[c] == j) {
              normal[c] = asciiReal(e, i, token, kNormal, c, p.type);
            }
            if (c < 2 && e.hasUvs && e.uvs[c] == j) {
              uv[static_cast<int>(c)] = asciiReal(e, i, token, "texture coordinate", p.name, p.type,
                                                  /*keepNonFinite=*/false);
            }
          }
          continue;
        }
        const std::string_view countToken = value(1 + after, false);
        const std::int64_t n = asciiInteger(e, i, countToken, p.countType, &p);
        if (n < 0) {
          failEntry(e, i, "list '" + p.name + "' has a negative count (" + std::to_string(n) + ")",
                    line_);
        }
        const std::uint64_t count = static_cast<std::uint64_t>(n);
        std::uint64_t k = 0;
        auto nextIndex = [&]() {
          const std::string_view token = value(count - k + after, !listAfter[j]);
          ++k;
          return asciiInteger(e, i, token, p.type, nullptr);
        };
        if (j == e.indexList && e.role == Role::kFace) {
          addPolygon(e, i, count, line_, nextIndex);
        } else if (j == e.indexList && e.role == Role::kTristrips) {
          addStrips(e, i, count, line_, nextIndex);
        } else {
          for (; k < count; ++k) value(count - k + after, !listAfter[j]);
        }
      }
      if (!nextToken(rest).empty()) {
        const std::size_t found = countTokens(line);
        failEntry(e, i,
                  "the line has " + std::to_string(found) + " values, expected " +
                      std::to_string(consumed),
                  line_);
      }
      if (e.role == Role::kVertex) addVertex(e, i, point, normal, uv, line_);
    }
  }

  // A list count (of `list`) or, with no list, a vertex index.
  std::int64_t asciiInteger(const Element& e, std::uint64_t entry, std::string_view token,
                            Type type, const Property* list) const {
    std::int64_t value = 0;
    const Parse result = parseInteger(token, &value);
    if (result == Parse::kOk && value >= minOf(type) && value <= maxOf(type)) return value;
    const std::string what = list ? "list '" + list->name + "' count" : "vertex index";
    if (result == Parse::kNotNumber) {
      failEntry(e, entry, what + " " + singleQuoted(token) + " is not an integer", line_);
    }
    failEntry(
        e, entry,
        what + " " + singleQuoted(token) + " is out of range for its type '" + typeName(type) + "'",
        line_);
  }

  // Component c of a coordinate or a normal.
  double asciiReal(const Element& e, std::uint64_t entry, std::string_view token,
                   const VectorKind& kind, std::size_t c, Type type) const {
    // A normal that is not finite is kept as such, for addVertex to count and replace.
    return asciiReal(e, entry, token, kind.what, kind.names[c], type, &kind == &kNormal);
  }

  // The value of property `name`, one component of a `what`.
  double asciiReal(const Element& e, std::uint64_t entry, std::string_view token,
                   const std::string& what, std::string_view propertyName, Type type,
                   bool keepNonFinite) const {
    const std::string name(propertyName);
    // Parsed at the property's own precision: a float property rounds once, straight from
    // the decimal text, exactly as a binary file of the same mesh would hold it.
    double value = 0.0;
    bool ok = false;
    if (type == Type::kFloat32) {
      float f = 0.0f;
      ok = parsePlyReal(token, &f);
      value = f;
    } else {
      ok = parsePlyReal(token, &value);
    }
    if (!ok) {
      failEntry(e, entry, what + " " + name + " " + singleQuoted(token) + " is not a number",
                line_);
    }
    if (std::fabs(value) <= std::numeric_limits<float>::max()) return value;
    // Too large or really infinite: the text as a double tells which (a float property's
    // overflow has already become an infinity).
    double asDouble = value;
    parsePlyReal(token, &asDouble);
    if (keepNonFinite && !std::isfinite(asDouble)) return asDouble;
    failEntry(
        e, entry,
        what + (std::isfinite(asDouble) ? " is too large for a 32-bit float" : " is not finite") +
            " (" + name + " = " + singleQuoted(token) + ")",
        line_);
  }

  const std::string& bytes_;
  const unsigned char* data_;
  const std::string& file_;
  const std::string& context_;

  Format format_ = Format::kAscii;
  std::vector<Element> elements_;
  std::size_t headerLines_ = 0;
  std::size_t dataStart_ = 0;
  std::uint64_t vertexCount_ = 0;

  std::size_t pos_ = 0;   // ascii: start of the next line
  std::size_t line_ = 0;  // ascii: number of the line last read

  std::vector<glm::dvec3> vertices_;
  std::vector<glm::dvec3> normals_;   // parallel to vertices_, or empty: the file has none
  std::vector<glm::vec2> uvs_;        // parallel to vertices_, or empty: the file has none
  std::size_t nonFiniteNormals_ = 0;  // normals read as 0 0 0 because they were not finite
  std::vector<IndexTri> tris_;
};

}  // namespace

PlyMesh loadPlyMesh(const std::string& bytes, const std::string& file, const std::string& context) {
  return PlyReader(bytes, file, context).load();
}

}  // namespace pt::scene_detail
