// Strict, path-tracking access to a parsed JSON document for the scene loader: every
// failure becomes a one-line InputError "<file>: <field path>: <problem>".
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

namespace pt::scene_detail {

// Throws InputError with "<file>: <where>: <problem>", control characters escaped so that
// the message stays on one line whatever the user put in keys or strings.
[[noreturn]] void throwInputError(std::string_view file, std::string_view where,
                                  std::string_view problem);

// Reads a whole file as bytes. On failure returns false and sets *why to a short reason
// ("No such file or directory", "is a directory").
bool readTextFile(const std::filesystem::path& path, std::string* text, std::string* why);

// Parses JSON text. Syntax errors and out-of-range numbers become InputErrors naming the
// line and column; duplicate keys (which nlohmann::json would silently collapse) become
// InputErrors naming the field.
nlohmann::json parseJson(const std::string& text, const std::string& file);

// Edit distance with adjacent transpositions (optimal string alignment), case-insensitive.
std::size_t editDistance(std::string_view a, std::string_view b);

// The candidate closest to `word` if it is close enough to be a plausible typo, else empty.
std::string closestMatch(std::string_view word, const std::vector<std::string_view>& candidates);

// " (did you mean 'x'?)" or "" for use at the end of an error message.
std::string didYouMean(std::string_view word, const std::vector<std::string_view>& candidates);

// Quotes a user string for a message: 'abc', with control characters escaped and anything
// past 80 bytes cut to "...".
std::string singleQuoted(std::string_view s);

// A file path in single quotes, escaped like singleQuoted but never cut: its end is the
// file name, the part a reader needs most.
std::string quotedPath(std::string_view path);

// A number for a message, to 9 significant digits ("1.5", "1e+39").
std::string formatNumber(double value);

// One value in the document together with its field path ("materials[2].reflectance") and
// the file name, so that every check can report exactly where it failed.
class JsonNode {
 public:
  JsonNode(const nlohmann::json& value, std::string path, const std::string& file)
      : value_(&value), path_(std::move(path)), file_(&file) {}

  const nlohmann::json& json() const { return *value_; }
  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }

  [[noreturn]] void fail(std::string_view problem) const;

  // "a string", "an array of 2 elements", "the number 1.5", ...
  std::string describe() const;

  // Objects. checkKeys() fails on a non-object or on any key not in `allowed` (with a
  // did-you-mean suggestion, else the list of allowed keys).
  void expectObject() const;
  void checkKeys(const std::vector<std::string_view>& allowed) const;
  std::optional<JsonNode> find(std::string_view key) const;
  JsonNode require(std::string_view key) const;

  // Arrays.
  void expectArray() const;
  std::size_t size() const;  // of an array
  JsonNode operator[](std::size_t index) const;

  // Scalars. number() is any finite JSON number; floatNumber() must also fit a float;
  // integer() also takes integral floats such as 64.0.
  double number() const;
  double floatNumber() const;
  std::int64_t integer(std::int64_t min, std::int64_t max) const;
  bool boolean() const;
  std::string string() const;

  // An array of exactly 3 numbers that fit a float.
  glm::dvec3 vec3() const;

 private:
  JsonNode child(std::string_view key, const nlohmann::json& value) const;

  const nlohmann::json* value_;
  std::string path_;
  const std::string* file_;
};

}  // namespace pt::scene_detail
