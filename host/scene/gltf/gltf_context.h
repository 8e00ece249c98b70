// What every part of the glTF reader shares: the file's name for messages, the warnings said so
// far, and whether warnings are errors (--strict). Every message names the file and the JSON
// path of the field ("meshes[3].primitives[0].attributes.NORMAL: accessor 12 out of range").
#pragma once

#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "scene/json_reader.h"

namespace pt::gltf {

class Context {
 public:
  Context(std::string file, bool strict, std::vector<std::string>& warnings)
      : file_(std::move(file)), strict_(strict), warnings_(&warnings) {}

  const std::string& file() const { return file_; }

  // Throws InputError "<file>: <where>: <problem>".
  [[noreturn]] void fail(std::string_view where, std::string_view problem) const {
    scene_detail::throwInputError(file_, where, problem);
  }

  // A warning once per `key`, "<file>: <where>: <message>": something read but not simulated,
  // or rendered otherwise than the specification says. With --strict it is an error instead.
  void warnOnce(const std::string& key, std::string_view where, const std::string& message) {
    if (strict_) fail(where, message + " (an error with --strict)");
    if (warned_.insert(key).second) {
      warnings_->push_back(file_ + ": " + std::string(where) + ": " + message);
    }
  }

 private:
  std::string file_;
  bool strict_;
  std::vector<std::string>* warnings_;
  std::set<std::string> warned_;
};

// "meshes[3]" from ("meshes", 3).
inline std::string indexed(std::string_view array, std::size_t index) {
  return std::string(array) + "[" + std::to_string(index) + "]";
}

}  // namespace pt::gltf
