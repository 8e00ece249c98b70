#include "scene/json_textures.h"

#include <cmath>
#include <vector>

#include "common/check.h"

namespace pt::scene_detail {

namespace {

constexpr std::string_view kClasses[] = {"imagemap", "checkerboard", "constant", "scale", "mix"};

std::vector<std::string_view> classKeys(std::string_view c) {
  std::vector<std::string_view> keys = {"name", "type"};
  const std::initializer_list<std::string_view> mapping = {"uscale", "vscale", "udelta", "vdelta"};
  if (c == "imagemap") {
    keys.insert(keys.end(),
                {"filename", "encoding", "wrap", "filter", "maxanisotropy", "scale", "invert"});
    keys.insert(keys.end(), mapping);
  } else if (c == "checkerboard") {
    keys.insert(keys.end(), {"tex1", "tex2", "dimension"});
    keys.insert(keys.end(), mapping);
  } else if (c == "constant") {
    keys.push_back("value");
  } else if (c == "scale") {
    keys.insert(keys.end(), {"tex", "scale"});
  } else if (c == "mix") {
    keys.insert(keys.end(), {"tex1", "tex2", "amount"});
  }
  return keys;
}

float finiteFloat(const JsonNode& n) {
  return static_cast<float>(n.floatNumber());
}

vec4 readMapping(const JsonNode& def) {
  vec4 m(1.0f, 1.0f, 0.0f, 0.0f);
  const char* keys[] = {"uscale", "vscale", "udelta", "vdelta"};
  for (int i = 0; i < 4; ++i) {
    if (auto n = def.find(keys[i])) m[i] = finiteFloat(*n);
  }
  return m;
}

}  // namespace

void JsonTextures::read(const JsonNode& node) {
  node.expectArray();
  for (std::size_t i = 0; i < node.size(); ++i) {
    const JsonNode def = node[i];
    def.expectObject();
    const JsonNode typeNode = def.require("type");
    const std::string type = typeNode.string();
    bool known = false;
    for (std::string_view c : kClasses) known = known || c == type;
    if (!known) {
      const std::vector<std::string_view> names(std::begin(kClasses), std::end(kClasses));
      const std::string hint = didYouMean(type, names);
      typeNode.fail("unknown texture type " + singleQuoted(type) +
                    (hint.empty()
                         ? " (expected 'imagemap', 'checkerboard', 'constant', 'scale' or 'mix')"
                         : hint));
    }
    def.checkKeys(classKeys(type));
    const JsonNode nameNode = def.require("name");
    const std::string name = nameNode.string();
    if (name.empty()) nameNode.fail("must not be empty");
    if (!defs_.emplace(name, def).second) {
      nameNode.fail("duplicate texture name " + singleQuoted(name) + " (also used by " +
                    defs_.at(name).path() + ")");
    }
    if (type == "imagemap") def.require("filename").string();
    if (auto n = def.find("dimension")) {
      if (n->integer(2, 3) != 2) n->fail("only 2D checkerboards are supported (\"dimension\": 2)");
    }
  }
}

uint JsonTextures::use(const JsonNode& value, bool isFloat) {
  return named(value, isFloat, 0);
}

uint JsonTextures::named(const JsonNode& value, bool isFloat, int depth) {
  const std::string name = value.string();
  const auto def = defs_.find(name);
  if (def == defs_.end()) {
    std::vector<std::string_view> names;
    for (const auto& [n, d] : defs_) names.push_back(n);
    const std::string hint = didYouMean(name, names);
    value.fail("unknown texture " + singleQuoted(name) +
               (hint.empty() ? " (a string names one of the scene's \"textures\"; a value is a "
                               "number or an array of 3 numbers)"
                             : hint));
  }
  const auto key = std::make_pair(name, isFloat);
  if (auto found = built_.find(key); found != built_.end()) return found->second;
  // A texture that names itself, directly or not, would never end.
  if (depth > 16) value.fail("textures nested more than 16 deep (a cycle?)");
  const uint texture = build(def->second, isFloat, depth + 1);
  built_.emplace(key, texture);
  return texture;
}

uint JsonTextures::operand(const JsonNode& def, std::string_view key, bool isFloat, vec3 fallback,
                           int depth) {
  const std::optional<JsonNode> n = def.find(key);
  if (!n) return builder_.constant(fallback);
  if (n->json().is_string()) return named(*n, isFloat, depth);
  if (n->json().is_number()) return builder_.constant(vec3(finiteFloat(*n)));
  if (isFloat) n->fail("expected a number or a texture's name, got " + n->describe());
  return builder_.constant(vec3(n->vec3()));
}

uint JsonTextures::build(const JsonNode& def, bool isFloat, int depth) {
  const std::string type = def.require("type").string();
  // Errors from the builder (an image, nesting) name the texture's entry.
  try {
    if (type == "constant") return operand(def, "value", isFloat, vec3(1.0f), depth);
    if (type == "scale") {
      const uint tex = operand(def, "tex", isFloat, vec3(1.0f), depth);
      return builder_.scale(tex, operand(def, "scale", true, vec3(1.0f), depth));
    }
    if (type == "mix") {
      const uint a = operand(def, "tex1", isFloat, vec3(0.0f), depth);
      const uint b = operand(def, "tex2", isFloat, vec3(1.0f), depth);
      return builder_.mix(a, b, operand(def, "amount", true, vec3(0.5f), depth));
    }
    if (type == "checkerboard") {
      const uint a = operand(def, "tex1", isFloat, vec3(1.0f), depth);
      const uint b = operand(def, "tex2", isFloat, vec3(0.0f), depth);
      return builder_.checkerboard(readMapping(def), a, b);
    }
    PT_CHECK(type == "imagemap", "texture class not checked by read()");
    ImageTextureDesc desc;
    const JsonNode file = def.require("filename");
    desc.filename = directory_ / file.string();
    if (auto n = def.find("encoding")) {
      desc.encoding = n->string();
      double gamma = 0.0;
      if (!parseColorEncoding(desc.encoding, gamma)) {
        n->fail("unknown encoding " + singleQuoted(desc.encoding) +
                " (expected \"sRGB\", \"linear\" or \"gamma <g>\" with g > 0)");
      }
    }
    if (auto n = def.find("wrap")) {
      if (!parseWrapMode(n->string(), desc.wrap)) {
        n->fail("unknown wrap mode " + singleQuoted(n->string()) +
                " (expected 'repeat', 'clamp' or 'black')");
      }
    }
    if (auto n = def.find("filter")) {
      const std::string f = n->string();
      if (!parseTextureFilter(f, desc.filter)) {
        n->fail("unknown filter " + singleQuoted(f) +
                " (expected 'bilinear', 'point', 'trilinear' or 'ewa')");
      }
    }
    if (auto n = def.find("maxanisotropy")) {
      desc.maxAnisotropy = finiteFloat(*n);
      if (!(desc.maxAnisotropy > 0.0f)) n->fail("must be positive");
    }
    if (auto n = def.find("scale")) desc.scale = finiteFloat(*n);
    if (auto n = def.find("invert")) desc.invert = n->boolean();
    desc.mapping = readMapping(def);
    try {
      return builder_.image(desc, isFloat);
    } catch (const InputError& e) {
      file.fail(e.what());
    }
  } catch (const InputError& e) {
    const std::string what = e.what();
    // Already located (a JsonNode's failure starts with the scene file's name).
    if (what.rfind(def.file(), 0) == 0) throw;
    def.fail(what);
  }
}

}  // namespace pt::scene_detail
