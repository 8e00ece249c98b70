// Strict JSON access for the scene loader: parsing with line/column errors, duplicate-key
// detection, typed getters that name the field path, and did-you-mean suggestions.
#include "scene/json_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>

#include "common/check.h"
#include "common/read_file.h"

namespace pt::scene_detail {

using nlohmann::json;

namespace {

// Appends `s` with control characters escaped (\n, \t, \xNN) so messages stay one line.
void appendEscaped(std::string& out, std::string_view s) {
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      out += buf;
    } else {
      out += c;
    }
  }
}

// 1-based line and column (in UTF-8 code points) of the byte at `index` (0-based).
std::pair<std::size_t, std::size_t> lineAndColumn(const std::string& text, std::size_t index) {
  index = std::min(index, text.size());
  std::size_t line = 1;
  std::size_t lineStart = 0;
  for (std::size_t i = 0; i < index; ++i) {
    if (text[i] == '\n') {
      ++line;
      lineStart = i + 1;
    }
  }
  std::size_t column = 1;
  for (std::size_t i = lineStart; i < index; ++i) {
    // UTF-8 continuation bytes (10xxxxxx) do not start a new character.
    if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) ++column;
  }
  return {line, column};
}

bool isWordChar(char c) {
  return c != '\0' && std::strchr(" \t\r\n{}[],:\"", c) == nullptr;
}

// Where to point for a syntax error whose offending byte is `p`: nlohmann reports the last
// byte it read, i.e. the end of an unexpected token or the byte that broke a literal, but
// the start of the token is what a reader looks for.
std::size_t errorTokenStart(const std::string& text, std::size_t p, const std::string& what) {
  if (p >= text.size()) return p;
  if (what.find("invalid string") != std::string::npos) return p;  // the bad byte itself
  const bool brokenWord = what.find("invalid literal") != std::string::npos ||
                          what.find("invalid number") != std::string::npos;
  if (brokenWord || isWordChar(text[p])) {
    // A literal or number: walk back over its characters.
    std::size_t i = p;
    while (i > 0 && isWordChar(text[i - 1])) --i;
    return i;
  }
  if (text[p] == '"') {
    // The closing quote of an unexpected string: the text before it is valid JSON so far,
    // so a forward scan over strings (honouring escapes) finds the opening quote.
    std::size_t open = std::string::npos;
    for (std::size_t i = 0; i < p; ++i) {
      if (open == std::string::npos) {
        if (text[i] == '"') open = i;
      } else if (text[i] == '\\') {
        ++i;
      } else if (text[i] == '"') {
        open = std::string::npos;
      }
    }
    if (open != std::string::npos) return open;
  }
  return p;
}

// Turns nlohmann's "[json.exception.parse_error.101] parse error at line 1, column 10:
// syntax error while parsing value - invalid literal; last read: 'tru}'" into
// "syntax error: invalid literal; last read: 'tru}' (while parsing value)"; the position
// is reported separately from our own count.
std::string describeSyntaxError(const std::string& what) {
  std::string rest = what;
  const std::size_t column = rest.find("column ");
  if (column != std::string::npos) {
    const std::size_t colon = rest.find(": ", column);
    if (colon != std::string::npos) rest = rest.substr(colon + 2);
  }
  const std::string prefix = "syntax error while parsing ";
  if (rest.rfind(prefix, 0) == 0) {
    const std::size_t dash = rest.find(" - ", prefix.size());
    if (dash != std::string::npos) {
      const std::string context = rest.substr(prefix.size(), dash - prefix.size());
      return "syntax error: " + rest.substr(dash + 3) + " (while parsing " + context + ")";
    }
  }
  if (rest.rfind("syntax error", 0) == 0) return rest;
  return "syntax error: " + rest;
}

// SAX pass over the text that builds no document: it reports parse errors with our own
// line/column and catches duplicate keys, tracking the field path as it goes.
class CheckingSax : public nlohmann::json_sax<json> {
 public:
  CheckingSax(const std::string& text, const std::string& file) : text_(text), file_(file) {}

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }

  bool start_object(std::size_t) override {
    value();
    frames_.push_back(Frame{false, 0, {}, {}});
    return true;
  }
  bool key(string_t& key) override {
    Frame& frame = frames_.back();
    frame.key = key;
    if (!frame.keys.insert(key).second) {
      throwInputError(file_, path(false), "duplicate key (it appears more than once here)");
    }
    return true;
  }
  bool end_object() override {
    frames_.pop_back();
    return true;
  }
  bool start_array(std::size_t) override {
    value();
    frames_.push_back(Frame{true, 0, {}, {}});
    return true;
  }
  bool end_array() override {
    frames_.pop_back();
    return true;
  }

  bool parse_error(std::size_t position, const std::string& lastToken,
                   const nlohmann::detail::exception& ex) override {
    if (ex.id == 406) {
      // Number overflow ("1e999"): `position` is the number's last byte (1-based). Name
      // the field and point at the start of the number.
      const std::size_t start = position >= lastToken.size() ? position - lastToken.size() : 0;
      const auto [line, column] = lineAndColumn(text_, start);
      const std::string where = frames_.empty() ? "top level" : path(true);
      throwInputError(file_, where,
                      "number " + lastToken + " is out of range (line " + std::to_string(line) +
                          ", column " + std::to_string(column) + ")");
    }
    // `position` is the 1-based index of the last byte read.
    const std::size_t start = errorTokenStart(text_, position > 0 ? position - 1 : 0, ex.what());
    const auto [line, column] = lineAndColumn(text_, start);
    throwInputError(file_, "line " + std::to_string(line) + ", column " + std::to_string(column),
                    describeSyntaxError(ex.what()));
  }

 private:
  struct Frame {
    bool isArray;
    std::size_t count;  // arrays: elements started so far
    std::string key;    // objects: the key whose value is being read
    std::set<std::string> keys;
  };

  // Counts an element of the enclosing array, if any.
  bool value() {
    if (!frames_.empty() && frames_.back().isArray) ++frames_.back().count;
    return true;
  }

  // Field path of the value being read. `pending`: the innermost array's element has not
  // been counted yet (a number that failed to parse).
  std::string path(bool pending) const {
    std::string out;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      if (f.isArray) {
        const bool innermost = i + 1 == frames_.size();
        const std::size_t index = innermost && pending ? f.count : (f.count > 0 ? f.count - 1 : 0);
        out += "[" + std::to_string(index) + "]";
      } else {
        if (!out.empty()) out += ".";
        out += f.key;
      }
    }
    return out;
  }

  const std::string& text_;
  const std::string& file_;
  std::vector<Frame> frames_;
};

const char* article(const json& j) {
  switch (j.type()) {
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::null:
      return "null";
    case json::value_t::binary:
      return "binary data";
    case json::value_t::discarded:
      return "nothing";
    default:
      return "a number";
  }
}

}  // namespace

void throwInputError(std::string_view file, std::string_view where, std::string_view problem) {
  std::string message;
  appendEscaped(message, file);
  message += ": ";
  if (!where.empty()) {
    appendEscaped(message, where);
    message += ": ";
  }
  appendEscaped(message, problem);
  throw InputError(message);
}

bool readTextFile(const std::filesystem::path& path, std::string* text, std::string* why) {
  // Only regular files: a directory cannot be read and a device such as /dev/zero never ends.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::is_directory(status)) {
    *why = "is a directory";
    return false;
  }
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    *why = "not a regular file";
    return false;
  }
  const FileReadResult read = readFile(path, *text);
  if (read.step == FileReadResult::kOpenFailed) {
    *why = std::strerror(read.error);
    return false;
  }
  if (read.step == FileReadResult::kReadFailed) {
    *why = "read error";
    return false;
  }
  return true;
}

json parseJson(const std::string& text, const std::string& file) {
  // First pass: errors with positions and duplicate keys (throws InputError).
  CheckingSax checker(text, file);
  const bool ok = json::sax_parse(text, &checker);
  if (!ok) throwInputError(file, "", "cannot parse JSON");  // not reached: checker throws
  // Second pass builds the document; it cannot fail where the first one succeeded, but
  // never let a library exception escape as anything but InputError.
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throwInputError(file, "", e.what());
  }
}

std::size_t editDistance(std::string_view a, std::string_view b) {
  const auto lower = [](char c) { return std::tolower(static_cast<unsigned char>(c)); };
  // d[i][j]: distance between the first i characters of a and the first j of b.
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1])) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);  // swapped neighbours: "widht"
      }
    }
  }
  return d[a.size()][b.size()];
}

std::string closestMatch(std::string_view word, const std::vector<std::string_view>& candidates) {
  // Long user strings cannot be typos of our short names; skip the quadratic work.
  if (word.size() > 64) return {};
  std::string best;
  std::size_t bestDistance = std::numeric_limits<std::size_t>::max();
  for (std::string_view c : candidates) {
    const std::size_t d = editDistance(word, c);
    // Plausible typo: at most 2 edits (more for long names), and not a rewrite of the whole
    // name (so "x" does not suggest "up").
    const std::size_t allowed = std::max<std::size_t>(2, std::max(c.size(), word.size()) / 3);
    if (d <= allowed && d < std::max(c.size(), word.size()) && d < bestDistance) {
      bestDistance = d;
      best = std::string(c);
    }
  }
  return best;
}

std::string didYouMean(std::string_view word, const std::vector<std::string_view>& candidates) {
  const std::string match = closestMatch(word, candidates);
  return match.empty() ? std::string{} : " (did you mean '" + match + "'?)";
}

std::string singleQuoted(std::string_view s) {
  // Keep messages readable when the offending value is a whole paragraph; cut on a UTF-8
  // character boundary.
  constexpr std::size_t kMaxShown = 80;
  bool cut = false;
  if (s.size() > kMaxShown) {
    std::size_t end = kMaxShown;
    while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
    s = s.substr(0, end);
    cut = true;
  }
  std::string out = "'";
  appendEscaped(out, s);
  return out + (cut ? "...'" : "'");
}

std::string quotedPath(std::string_view path) {
  std::string out = "'";
  appendEscaped(out, path);
  return out + "'";
}

std::string formatNumber(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  return buf;
}

// ---- JsonNode ---------------------------------------------------------------------------
// (Inside members, `json` names JsonNode::json(), hence nlohmann::json spelled out.)

void JsonNode::fail(std::string_view problem) const {
  throwInputError(*file_, path_.empty() ? "top level" : path_, problem);
}

std::string JsonNode::describe() const {
  const nlohmann::json& j = *value_;
  if (j.is_array()) {
    return "an array of " + std::to_string(j.size()) + (j.size() == 1 ? " element" : " elements");
  }
  if (j.is_number_integer()) return "the number " + j.dump();  // exact, unlike %g
  if (j.is_number()) return "the number " + formatNumber(j.get<double>());
  if (j.is_boolean()) return j.get<bool>() ? "true" : "false";
  if (j.is_string()) return "the string " + singleQuoted(j.get_ref<const std::string&>());
  return article(j);
}

JsonNode JsonNode::child(std::string_view key, const nlohmann::json& value) const {
  return JsonNode(value, path_.empty() ? std::string(key) : path_ + "." + std::string(key), *file_);
}

void JsonNode::expectObject() const {
  if (!value_->is_object()) fail(std::string("expected an object, got ") + article(*value_));
}

void JsonNode::checkKeys(const std::vector<std::string_view>& allowed) const {
  expectObject();
  for (const auto& [key, value] : value_->items()) {
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string problem = "unknown key";
    const std::string match = closestMatch(key, allowed);
    if (!match.empty()) {
      problem += " (did you mean '" + match + "'?)";
    } else {
      problem += " (expected ";
      for (std::size_t i = 0; i < allowed.size(); ++i) {
        if (i > 0) problem += i + 1 == allowed.size() ? " or " : ", ";
        problem += "'" + std::string(allowed[i]) + "'";
      }
      problem += ")";
    }
    child(key, value).fail(problem);
  }
}

std::optional<JsonNode> JsonNode::find(std::string_view key) const {
  expectObject();
  const auto it = value_->find(key);
  if (it == value_->end()) return std::nullopt;
  return child(key, *it);
}

JsonNode JsonNode::require(std::string_view key) const {
  std::optional<JsonNode> node = find(key);
  if (!node) child(key, *value_).fail("required key is missing");
  return *node;
}

void JsonNode::expectArray() const {
  if (!value_->is_array()) fail(std::string("expected an array, got ") + article(*value_));
}

std::size_t JsonNode::size() const {
  expectArray();
  return value_->size();
}

JsonNode JsonNode::operator[](std::size_t index) const {
  PT_CHECK(value_->is_array() && index < value_->size());
  return JsonNode((*value_)[index], path_ + "[" + std::to_string(index) + "]", *file_);
}

double JsonNode::number() const {
  if (!value_->is_number()) fail(std::string("expected a number, got ") + article(*value_));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail("number is not finite");
  return v;
}

double JsonNode::floatNumber() const {
  const double v = number();
  if (std::fabs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
    fail("number " + formatNumber(v) + " is too large (the renderer uses 32-bit floats)");
  }
  return v;
}

std::int64_t JsonNode::integer(std::int64_t min, std::int64_t max) const {
  const std::string range =
      "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  const nlohmann::json& j = *value_;
  if (!j.is_number()) fail("expected " + range + ", got " + article(j));
  std::int64_t v = 0;
  if (j.is_number_unsigned()) {
    const std::uint64_t u = j.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(max)) fail("expected " + range + ", got " + describe());
    v = static_cast<std::int64_t>(u);
  } else if (j.is_number_integer()) {
    v = j.get<std::int64_t>();
  } else {
    // Accept integral floats such as 64.0 or 1e3; reject 1.5 and anything out of range
    // before converting (the conversion of an out-of-range double is undefined).
    const double d = j.get<double>();
    if (!std::isfinite(d) || d != std::floor(d) || d < static_cast<double>(min) ||
        d > static_cast<double>(max)) {
      fail("expected " + range + ", got " + describe());
    }
    v = static_cast<std::int64_t>(d);
  }
  if (v < min || v > max) fail("expected " + range + ", got " + describe());
  return v;
}

bool JsonNode::boolean() const {
  if (!value_->is_boolean()) fail(std::string("expected true or false, got ") + article(*value_));
  return value_->get<bool>();
}

std::string JsonNode::string() const {
  if (!value_->is_string()) fail(std::string("expected a string, got ") + article(*value_));
  return value_->get<std::string>();
}

glm::dvec3 JsonNode::vec3() const {
  if (!value_->is_array()) {
    fail(std::string("expected an array of 3 numbers, got ") + article(*value_));
  }
  if (value_->size() != 3) fail("expected an array of 3 numbers, got " + describe());
  glm::dvec3 v;
  for (int i = 0; i < 3; ++i) v[i] = (*this)[static_cast<std::size_t>(i)].floatNumber();
  return v;
}

}  // namespace pt::scene_detail
