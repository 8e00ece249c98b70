// pbrt-v4 scene files, first stage: the tokenizer and the directive parser. Turns the text of
// a file (and of the files it includes) into statements, one per directive, with their
// arguments and typed parameter lists; what the statements mean is pbrt_scene.h's business.
// Every syntax error is an InputError "file:line:column: message" (docs/pbrt-format.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace pt::pbrt {

// Where a token starts: 1-based line and column (columns count UTF-8 characters).
struct Location {
  std::string file;  // the scene's path as given, or an included file's resolved path
  int line = 0;
  int column = 0;
  std::string toString() const;  // "file:line:column"
  std::string fileLine() const;  // "file:line", for warnings
};

// Throws InputError "file:line:column: message", control characters escaped so that the
// message stays on one line.
[[noreturn]] void fail(const Location& location, std::string_view message);

// The parameter types of pbrt-v4, after its aliases: pbrt-v3's "point", "vector", "normal"
// and "color" are read as point3, vector3, normal and rgb, and "normal3" as normal.
enum class ParamType {
  kInteger,
  kFloat,
  kPoint2,
  kVector2,
  kPoint3,
  kVector3,
  kNormal,
  kRgb,
  kSpectrum,
  kBlackbody,
  kBool,
  kString,
  kTexture,
};

// pbrt-v4's name of the type ("point3", "rgb", ...).
const char* paramTypeName(ParamType type);

// One `"type name" value` or `"type name" [ values ]` of a parameter list.
struct Param {
  ParamType type = ParamType::kFloat;
  std::string typeWritten;  // as in the file ("color" for an rgb), for messages
  std::string name;
  Location location;  // of the declaration string
  // Integer, float, point, vector, normal, rgb and blackbody values, and a spectrum's
  // wavelength-value pairs (integers are exact in a double).
  std::vector<double> numbers;
  std::vector<std::string> strings;  // string and texture values, a spectrum's name or file
  std::vector<bool> bools;
  // Set when the scene builder has read the parameter: the rest are reported as ignored.
  mutable bool used = false;

  // The number of values as written, whatever their kind.
  std::size_t valueCount() const { return numbers.size() + strings.size() + bools.size(); }
  std::string declaration() const { return typeWritten + " " + name; }  // "float fov"
};

// One directive with what follows it. Which fields a directive fills:
//  - `strings`: its quoted arguments (Shape "sphere": {"sphere"}; Texture: name, type and
//    class; MediumInterface: one or two names; Option: the name, then the value token as
//    written, quotes included; ActiveTransform: All, StartTime or EndTime);
//  - `numbers`: Translate, Scale (3), Rotate (4), LookAt (9), Transform and ConcatTransform
//    (16, in the file's order), TransformTimes (2);
//  - `params`: the parameter list of the directives that take one.
// Include and Import never reach the handler: their files' statements do, in place.
struct Statement {
  std::string directive;
  Location location;  // of the directive's name
  std::vector<std::string> strings;
  std::vector<Location> stringLocations;  // parallel to `strings`
  std::vector<double> numbers;
  std::vector<Param> params;
};

using StatementHandler = std::function<void(Statement&)>;

// The most files open at once through Include and Import: deeper nesting is an error, which
// also ends any include cycle that the path check does not recognize (links, /proc paths).
inline constexpr int kMaxIncludeDepth = 32;

// Parses the file `path`, calling `handler` for each statement in order. A relative Include
// or Import path is resolved against the directory of the file that names it, and, when no
// such file exists there, against the directory of `path` (pbrt-v4 resolves every path
// against the latter).
void parseFile(const std::filesystem::path& path, const StatementHandler& handler);

// The same for `text` given as the content of the file `path` (which need not exist).
void parseText(std::string text, const std::filesystem::path& path,
               const StatementHandler& handler);

// The directives of pbrt-v4 that the parser knows, in alphabetical order.
const std::vector<std::string_view>& directiveNames();

// The file a relative path in a statement at `from` names: relative to the directory of
// `from`'s file when it exists there, else relative to the main scene file's directory.
std::filesystem::path resolvePath(const std::string& name, const Location& from,
                                  const std::filesystem::path& mainFile);

}  // namespace pt::pbrt
