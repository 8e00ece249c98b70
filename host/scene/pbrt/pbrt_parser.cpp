// The pbrt-v4 tokenizer and directive parser: pbrt-v4's syntax (its parser.cpp is the
// definition), strict about what it does not understand, every error naming file:line:column.
#include "scene/pbrt/pbrt_parser.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <system_error>
#include <utility>

#include "common/check.h"
#include "scene/json_reader.h"

namespace pt::pbrt {

namespace fs = std::filesystem;
using scene_detail::singleQuoted;

std::string Location::toString() const {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string Location::fileLine() const {
  return file + ":" + std::to_string(line);
}

void fail(const Location& location, std::string_view message) {
  scene_detail::throwInputError(location.toString(), "", message);
}

const char* paramTypeName(ParamType type) {
  switch (type) {
    case ParamType::kInteger:
      return "integer";
    case ParamType::kFloat:
      return "float";
    case ParamType::kPoint2:
      return "point2";
    case ParamType::kVector2:
      return "vector2";
    case ParamType::kPoint3:
      return "point3";
    case ParamType::kVector3:
      return "vector3";
    case ParamType::kNormal:
      return "normal";
    case ParamType::kRgb:
      return "rgb";
    case ParamType::kSpectrum:
      return "spectrum";
    case ParamType::kBlackbody:
      return "blackbody";
    case ParamType::kBool:
      return "bool";
    case ParamType::kString:
      return "string";
    case ParamType::kTexture:
      return "texture";
  }
  PT_CHECK(false, "unknown parameter type");
  return "";
}

fs::path resolvePath(const std::string& name, const Location& from, const fs::path& mainFile) {
  const fs::path given(name);
  if (given.is_absolute()) return given;
  const fs::path local = fs::path(from.file).parent_path() / given;
  std::error_code ec;
  if (fs::exists(local, ec)) return local;
  const fs::path main = mainFile.parent_path() / given;
  if (main != local && fs::exists(main, ec)) return main;
  return local;
}

namespace {

// ---- tokens -------------------------------------------------------------------------------

struct Token {
  enum class Kind { kWord, kString, kOpen, kClose, kEnd };
  Kind kind = Kind::kEnd;
  std::string_view word;  // kWord: as written (a view into the file's text)
  std::string string;     // kString: the content, escapes decoded
  int line = 0;
  int column = 0;
};

// What a token is, for messages: "'1.5'", "the string 'abc'", "the end of the file".
std::string describe(const Token& t) {
  switch (t.kind) {
    case Token::Kind::kWord:
      return singleQuoted(t.word);
    case Token::Kind::kString:
      return "the string " + singleQuoted(t.string);
    case Token::Kind::kOpen:
      return "'['";
    case Token::Kind::kClose:
      return "']'";
    case Token::Kind::kEnd:
      return "the end of the file";
  }
  return "";
}

// Splits one file's text into tokens: bare words (directives, numbers, true/false), quoted
// strings, brackets. Comments run from '#' to the end of the line.
class Tokenizer {
 public:
  Tokenizer(std::string text, std::string file) : text_(std::move(text)), file_(std::move(file)) {
    // pbrt-v4 reads UTF-8 only; a UTF-8 byte-order mark is skipped.
    if (text_.size() >= 2 && ((static_cast<unsigned char>(text_[0]) == 0xfe &&
                               static_cast<unsigned char>(text_[1]) == 0xff) ||
                              (static_cast<unsigned char>(text_[0]) == 0xff &&
                               static_cast<unsigned char>(text_[1]) == 0xfe))) {
      fail(Location{file_, 1, 1}, "the file is UTF-16 encoded; pbrt files are UTF-8");
    }
    if (text_.compare(0, 3, "\xef\xbb\xbf") == 0) pos_ = 3;
  }

  const std::string& file() const { return file_; }
  Location location(const Token& t) const { return Location{file_, t.line, t.column}; }

  Token next() {
    skipSpaceAndComments();
    Token t;
    t.line = line_;
    t.column = column_;
    if (pos_ >= text_.size()) return t;  // kEnd, at the end of the file
    const char c = text_[pos_];
    if (c == '[' || c == ']') {
      advance();
      t.kind = c == '[' ? Token::Kind::kOpen : Token::Kind::kClose;
      return t;
    }
    if (c == '"') return readString(t);
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !isDelimiter(text_[pos_])) advance();
    t.kind = Token::Kind::kWord;
    t.word = std::string_view(text_).substr(start, pos_ - start);
    return t;
  }

 private:
  static bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
  }
  static bool isDelimiter(char c) {
    return isSpace(c) || c == '"' || c == '[' || c == ']' || c == '#';
  }

  // Moves past one byte, keeping the line and the column (in UTF-8 characters) of the next.
  void advance() {
    const char c = text_[pos_++];
    if (c == '\n') {
      ++line_;
      column_ = 1;
    } else if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) {
      ++column_;  // continuation bytes (10xxxxxx) do not start a character
    }
  }

  void skipSpaceAndComments() {
    while (pos_ < text_.size()) {
      if (isSpace(text_[pos_])) {
        advance();
      } else if (text_[pos_] == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') advance();
      } else {
        return;
      }
    }
  }

  Token& readString(Token& t) {
    const Location start{file_, t.line, t.column};
    advance();  // the opening quote
    while (true) {
      if (pos_ >= text_.size()) fail(start, "unterminated string (the file ends inside it)");
      const char c = text_[pos_];
      if (c == '"') {
        advance();
        break;
      }
      if (c == '\n') fail(start, "unterminated string (a string must end on its line)");
      if (c == '\\') {
        const Location escape{file_, line_, column_};
        advance();
        if (pos_ >= text_.size()) fail(start, "unterminated string (the file ends inside it)");
        const char e = text_[pos_];
        const char* decoded = nullptr;
        switch (e) {
          case 'b':
            decoded = "\b";
            break;
          case 'f':
            decoded = "\f";
            break;
          case 'n':
            decoded = "\n";
            break;
          case 'r':
            decoded = "\r";
            break;
          case 't':
            decoded = "\t";
            break;
          case '\\':
            decoded = "\\";
            break;
          case '\'':
            decoded = "'";
            break;
          case '"':
            decoded = "\"";
            break;
          default:
            fail(escape, "unknown escape sequence '\\" + std::string(1, e) +
                             "' in a string (pbrt knows \\b \\f \\n \\r \\t \\\\ \\' \\\")");
        }
        t.string += decoded;
        advance();
        continue;
      }
      t.string += c;
      advance();
    }
    t.kind = Token::Kind::kString;
    return t;
  }

  std::string text_;
  std::string file_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
};

// ---- numbers ------------------------------------------------------------------------------

enum class NumberResult { kOk, kNotANumber, kOutOfRange };

// A decimal number as pbrt writes them: an optional sign, digits with an optional point, an
// optional exponent. No inf, nan or hexadecimal. Underflow gives the nearest double (0 or a
// denormal), overflow is out of range.
NumberResult parseNumber(std::string_view s, double* out) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (i >= s.size()) return NumberResult::kNotANumber;
  if (!((s[i] >= '0' && s[i] <= '9') || s[i] == '.')) return NumberResult::kNotANumber;
  const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(begin, end, *out, std::chars_format::general);
  if (ptr != end) return NumberResult::kNotANumber;
  if (ec == std::errc::result_out_of_range) {
    // from_chars reports underflow as out of range too: strtod tells the two apart.
    const std::string copy(s);
    const double v = std::strtod(copy.c_str(), nullptr);
    if (!std::isfinite(v)) return NumberResult::kOutOfRange;
    *out = v;
    return NumberResult::kOk;
  }
  return ec == std::errc{} ? NumberResult::kOk : NumberResult::kNotANumber;
}

// An integer as pbrt-v4 reads them: an optional sign and digits, within 32 bits.
NumberResult parseInteger(std::string_view s, double* out) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (i >= s.size()) return NumberResult::kNotANumber;
  for (std::size_t k = i; k < s.size(); ++k) {
    if (s[k] < '0' || s[k] > '9') return NumberResult::kNotANumber;
  }
  long long value = 0;
  const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(begin, s.data() + s.size(), value);
  if (ec == std::errc::result_out_of_range || value > std::numeric_limits<int>::max() ||
      value < std::numeric_limits<int>::min()) {
    return NumberResult::kOutOfRange;
  }
  if (ec != std::errc{} || ptr != s.data() + s.size()) return NumberResult::kNotANumber;
  *out = static_cast<double>(value);
  return NumberResult::kOk;
}

// ---- directives ---------------------------------------------------------------------------

// What follows a directive's name.
enum class Form {
  kNone,             // nothing
  kName,             // one quoted string
  kNameParams,       // one quoted string and a parameter list
  kTexture,          // three quoted strings and a parameter list
  kNumbers,          // `count` bare numbers
  kMatrix,           // [ 16 numbers ]
  kMediumInterface,  // one or two quoted strings
  kOption,           // a quoted name and one value
  kActiveTransform,  // All, StartTime or EndTime
  kInclude,          // a quoted file name, read in place
};

struct DirectiveSpec {
  std::string_view name;
  Form form;
  int count = 0;  // kNumbers: how many
};

// Every directive of pbrt-v4 (parser.cpp), alphabetically. WorldEnd is pbrt-v3's, accepted
// (and ignored) so that files upgraded from v3 that still end with it read as they are.
constexpr DirectiveSpec kDirectives[] = {
    {"Accelerator", Form::kNameParams},
    {"ActiveTransform", Form::kActiveTransform},
    {"AreaLightSource", Form::kNameParams},
    {"Attribute", Form::kNameParams},
    {"AttributeBegin", Form::kNone},
    {"AttributeEnd", Form::kNone},
    {"Camera", Form::kNameParams},
    {"ColorSpace", Form::kName},
    {"ConcatTransform", Form::kMatrix},
    {"CoordSysTransform", Form::kName},
    {"CoordinateSystem", Form::kName},
    {"Film", Form::kNameParams},
    {"Identity", Form::kNone},
    {"Import", Form::kInclude},
    {"Include", Form::kInclude},
    {"Integrator", Form::kNameParams},
    {"LightSource", Form::kNameParams},
    {"LookAt", Form::kNumbers, 9},
    {"MakeNamedMaterial", Form::kNameParams},
    {"MakeNamedMedium", Form::kNameParams},
    {"Material", Form::kNameParams},
    {"MediumInterface", Form::kMediumInterface},
    {"NamedMaterial", Form::kName},
    {"ObjectBegin", Form::kName},
    {"ObjectEnd", Form::kNone},
    {"ObjectInstance", Form::kName},
    {"Option", Form::kOption},
    {"PixelFilter", Form::kNameParams},
    {"ReverseOrientation", Form::kNone},
    {"Rotate", Form::kNumbers, 4},
    {"Sampler", Form::kNameParams},
    {"Scale", Form::kNumbers, 3},
    {"Shape", Form::kNameParams},
    {"Texture", Form::kTexture},
    {"Transform", Form::kMatrix},
    {"TransformBegin", Form::kNone},
    {"TransformEnd", Form::kNone},
    {"TransformTimes", Form::kNumbers, 2},
    {"Translate", Form::kNumbers, 3},
    {"WorldBegin", Form::kNone},
    {"WorldEnd", Form::kNone},
};

const DirectiveSpec* findDirective(std::string_view name) {
  for (const DirectiveSpec& d : kDirectives) {
    if (d.name == name) return &d;
  }
  return nullptr;
}

struct TypeName {
  std::string_view name;
  ParamType type;
};

// pbrt-v4's types, then the spellings it upgrades (pbrt-v3's) and "normal3".
constexpr TypeName kTypeNames[] = {
    {"integer", ParamType::kInteger},   {"float", ParamType::kFloat},
    {"point2", ParamType::kPoint2},     {"vector2", ParamType::kVector2},
    {"point3", ParamType::kPoint3},     {"vector3", ParamType::kVector3},
    {"normal", ParamType::kNormal},     {"rgb", ParamType::kRgb},
    {"spectrum", ParamType::kSpectrum}, {"blackbody", ParamType::kBlackbody},
    {"bool", ParamType::kBool},         {"string", ParamType::kString},
    {"texture", ParamType::kTexture},   {"normal3", ParamType::kNormal},
    {"point", ParamType::kPoint3},      {"vector", ParamType::kVector3},
    {"color", ParamType::kRgb},
};

bool isNumeric(ParamType t) {
  return t != ParamType::kBool && t != ParamType::kString && t != ParamType::kTexture &&
         t != ParamType::kSpectrum;
}

// How many numbers make one value of a numeric type.
std::size_t numbersPerValue(ParamType t) {
  switch (t) {
    case ParamType::kPoint2:
    case ParamType::kVector2:
      return 2;
    case ParamType::kPoint3:
    case ParamType::kVector3:
    case ParamType::kNormal:
    case ParamType::kRgb:
      return 3;
    default:
      return 1;
  }
}

class Parser {
 public:
  Parser(const StatementHandler& handler, fs::path mainFile)
      : handler_(handler), mainFile_(std::move(mainFile)) {}

  void parse(std::string text, const std::string& file) {
    std::error_code ec;
    open_.push_back(fs::weakly_canonical(fs::path(file), ec));
    Tokenizer tokenizer(std::move(text), file);
    std::optional<Token> peeked;
    Reader reader{tokenizer, peeked};
    while (true) {
      Token t = reader.take();
      if (t.kind == Token::Kind::kEnd) break;
      statement(reader, t);
    }
    open_.pop_back();
  }

 private:
  // One file's tokens with one token of lookahead.
  struct Reader {
    Tokenizer& tokenizer;
    std::optional<Token>& peeked;
    Token take() {
      if (peeked) {
        Token t = std::move(*peeked);
        peeked.reset();
        return t;
      }
      return tokenizer.next();
    }
    const Token& peek() {
      if (!peeked) peeked = tokenizer.next();
      return *peeked;
    }
    Location location(const Token& t) const { return tokenizer.location(t); }
  };

  void statement(Reader& r, const Token& t) {
    const Location where = r.location(t);
    if (t.kind != Token::Kind::kWord) {
      fail(where,
           "expected a directive, got " + describe(t) +
               (t.kind == Token::Kind::kString ? " (a parameter without a directive?)" : ""));
    }
    const DirectiveSpec* spec = findDirective(t.word);
    if (spec == nullptr) {
      double ignored = 0.0;
      if (parseNumber(t.word, &ignored) == NumberResult::kOk) {
        fail(where, "expected a directive, got the number " + singleQuoted(t.word) +
                        " (too many numbers for the directive before it?)");
      }
      fail(where, "unknown directive " + singleQuoted(t.word) +
                      scene_detail::didYouMean(t.word, directiveNames()));
    }
    Statement s;
    s.directive = std::string(spec->name);
    s.location = where;
    switch (spec->form) {
      case Form::kNone:
        break;
      case Form::kName:
        readName(r, s);
        break;
      case Form::kNameParams:
        readName(r, s);
        readParams(r, s);
        break;
      case Form::kTexture:
        for (int i = 0; i < 3; ++i) readName(r, s);
        readParams(r, s);
        break;
      case Form::kNumbers:
        for (int i = 0; i < spec->count; ++i) {
          const Token n = r.take();
          double value = 0.0;
          const NumberResult result = n.kind == Token::Kind::kWord ? parseNumber(n.word, &value)
                                                                   : NumberResult::kNotANumber;
          if (result == NumberResult::kOutOfRange) {
            fail(r.location(n), "number " + singleQuoted(n.word) + " is out of range");
          }
          if (result != NumberResult::kOk) {
            fail(n.kind == Token::Kind::kEnd ? where : r.location(n),
                 s.directive + " takes " + std::to_string(spec->count) + " numbers, got " +
                     describe(n) + (i == 0 ? std::string() : " after " + std::to_string(i)));
          }
          s.numbers.push_back(value);
        }
        break;
      case Form::kMatrix:
        readMatrix(r, s);
        break;
      case Form::kMediumInterface:
        readName(r, s);
        if (r.peek().kind == Token::Kind::kString) readName(r, s);
        break;
      case Form::kOption: {
        readName(r, s);
        const Token v = r.take();
        if (v.kind == Token::Kind::kWord && !findDirective(v.word)) {
          s.strings.emplace_back(v.word);
        } else if (v.kind == Token::Kind::kString) {
          s.strings.push_back("\"" + v.string + "\"");
        } else {
          fail(v.kind == Token::Kind::kEnd ? where : r.location(v),
               "Option takes a name and a value, got " + describe(v) + " for the value");
        }
        s.stringLocations.push_back(r.location(v));
        break;
      }
      case Form::kActiveTransform: {
        const Token v = r.take();
        if (v.kind != Token::Kind::kWord ||
            (v.word != "All" && v.word != "StartTime" && v.word != "EndTime")) {
          fail(v.kind == Token::Kind::kEnd ? where : r.location(v),
               "ActiveTransform takes All, StartTime or EndTime, got " + describe(v));
        }
        s.strings.emplace_back(v.word);
        s.stringLocations.push_back(r.location(v));
        break;
      }
      case Form::kInclude:
        readName(r, s);
        include(s);
        return;
    }
    handler_(s);
  }

  // A directive's quoted argument.
  void readName(Reader& r, Statement& s) {
    const Token n = r.take();
    if (n.kind != Token::Kind::kString) {
      fail(n.kind == Token::Kind::kEnd ? s.location : r.location(n),
           s.directive + " takes a quoted " +
               (s.directive == "Include" || s.directive == "Import" ? "file name" : "name") +
               ", got " + describe(n));
    }
    s.strings.push_back(n.string);
    s.stringLocations.push_back(r.location(n));
  }

  void readMatrix(Reader& r, Statement& s) {
    const Token open = r.take();
    if (open.kind != Token::Kind::kOpen) {
      fail(open.kind == Token::Kind::kEnd ? s.location : r.location(open),
           s.directive + " takes 16 numbers in brackets, got " + describe(open));
    }
    const Location openAt = r.location(open);
    while (true) {
      const Token n = r.take();
      if (n.kind == Token::Kind::kClose) break;
      checkUnterminated(r, n, openAt);
      double value = 0.0;
      const NumberResult result =
          n.kind == Token::Kind::kWord ? parseNumber(n.word, &value) : NumberResult::kNotANumber;
      if (result == NumberResult::kOutOfRange) {
        fail(r.location(n), "number " + singleQuoted(n.word) + " is out of range");
      }
      if (result != NumberResult::kOk) {
        fail(r.location(n), s.directive + " takes 16 numbers, got " + describe(n));
      }
      s.numbers.push_back(value);
    }
    if (s.numbers.size() != 16) {
      fail(openAt, s.directive + " takes 16 numbers, got " + std::to_string(s.numbers.size()));
    }
  }

  // Inside brackets: the end of the file, or a directive, means the ']' is missing.
  static void checkUnterminated(Reader& r, const Token& t, const Location& openAt) {
    if (t.kind == Token::Kind::kEnd) {
      fail(openAt, "unterminated '[' (the file ends before its ']')");
    }
    if (t.kind == Token::Kind::kWord && findDirective(t.word)) {
      const Location at = r.location(t);
      fail(openAt, "unterminated '[' (the directive " + singleQuoted(t.word) + " at line " +
                       std::to_string(at.line) + ", column " + std::to_string(at.column) +
                       " comes before its ']')");
    }
    if (t.kind == Token::Kind::kOpen) fail(r.location(t), "'[' inside brackets");
  }

  // A parameter list: `"type name" value` or `"type name" [ values ]`, as long as the next
  // token is a quoted string.
  void readParams(Reader& r, Statement& s) {
    while (r.peek().kind == Token::Kind::kString) {
      const Token decl = r.take();
      Param p;
      p.location = r.location(decl);
      declaration(decl.string, p);
      const Token v = r.take();
      if (v.kind == Token::Kind::kOpen) {
        const Location openAt = r.location(v);
        while (true) {
          const Token e = r.take();
          if (e.kind == Token::Kind::kClose) break;
          checkUnterminated(r, e, openAt);
          value(r, e, p);
        }
      } else if (v.kind == Token::Kind::kEnd ||
                 (v.kind == Token::Kind::kWord && findDirective(v.word))) {
        fail(p.location, "parameter " + singleQuoted(p.declaration()) + " has no value (got " +
                             describe(v) + ")");
      } else if (v.kind == Token::Kind::kClose) {
        fail(r.location(v), "']' without a '['");
      } else {
        value(r, v, p);
      }
      checkCounts(p);
      s.params.push_back(std::move(p));
    }
  }

  // "type name": the type (with pbrt-v3's spellings) and the name.
  static void declaration(const std::string& text, Param& p) {
    std::vector<std::string> words;
    std::size_t i = 0;
    while (i < text.size()) {
      while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
      if (i > start) words.push_back(text.substr(start, i - start));
    }
    std::vector<std::string_view> typeNames;
    for (const TypeName& t : kTypeNames) typeNames.push_back(t.name);
    if (words.size() != 2) {
      const bool typeOnly = words.size() == 1 && std::find(typeNames.begin(), typeNames.end(),
                                                           words[0]) != typeNames.end();
      fail(p.location, "expected a parameter declaration \"type name\", got " + singleQuoted(text) +
                           (typeOnly ? " (no name)" : ""));
    }
    for (const TypeName& t : kTypeNames) {
      if (t.name == words[0]) {
        p.type = t.type;
        p.typeWritten = words[0];
        p.name = words[1];
        return;
      }
    }
    fail(p.location, "unknown parameter type " + singleQuoted(words[0]) + " in " +
                         singleQuoted(text) + scene_detail::didYouMean(words[0], typeNames));
  }

  // One value of `p`, checked against its type.
  static void value(Reader& r, const Token& t, Param& p) {
    const Location at = r.location(t);
    const std::string in = " in " + singleQuoted(p.declaration());
    if (p.type == ParamType::kBool) {
      const std::string_view text = t.kind == Token::Kind::kWord     ? t.word
                                    : t.kind == Token::Kind::kString ? std::string_view(t.string)
                                                                     : std::string_view();
      if ((t.kind == Token::Kind::kWord || t.kind == Token::Kind::kString) &&
          (text == "true" || text == "false")) {
        p.bools.push_back(text == "true");
        return;
      }
      fail(at, "expected true or false" + in + ", got " + describe(t));
    }
    if (p.type == ParamType::kString || p.type == ParamType::kTexture) {
      if (t.kind != Token::Kind::kString) {
        fail(at, "expected a quoted string" + in + ", got " + describe(t));
      }
      p.strings.push_back(t.string);
      return;
    }
    if (p.type == ParamType::kSpectrum && t.kind == Token::Kind::kString) {
      if (!p.numbers.empty() || !p.strings.empty()) {
        fail(at, "a spectrum is one name or a list of wavelength-value pairs" + in + ", got " +
                     describe(t));
      }
      p.strings.push_back(t.string);
      return;
    }
    if (t.kind != Token::Kind::kWord) fail(at, "expected a number" + in + ", got " + describe(t));
    if (p.type == ParamType::kSpectrum && !p.strings.empty()) {
      fail(at, "a spectrum is one name or a list of wavelength-value pairs" + in + ", got " +
                   describe(t));
    }
    double number = 0.0;
    if (p.type == ParamType::kInteger) {
      const NumberResult result = parseInteger(t.word, &number);
      if (result == NumberResult::kOutOfRange) {
        fail(at, "integer " + singleQuoted(t.word) + in + " is out of range (32 bits)");
      }
      if (result != NumberResult::kOk) {
        fail(at, "expected an integer" + in + ", got " + describe(t));
      }
    } else {
      const NumberResult result = parseNumber(t.word, &number);
      if (result == NumberResult::kOutOfRange) {
        fail(at, "number " + singleQuoted(t.word) + in + " is out of range");
      }
      if (result != NumberResult::kOk) fail(at, "expected a number" + in + ", got " + describe(t));
    }
    p.numbers.push_back(number);
  }

  static void checkCounts(const Param& p) {
    const std::string decl = singleQuoted(p.declaration());
    if (p.valueCount() == 0) fail(p.location, "parameter " + decl + " has no values");
    if (isNumeric(p.type)) {
      const std::size_t per = numbersPerValue(p.type);
      if (p.numbers.size() % per != 0) {
        fail(p.location, "parameter " + decl + " takes a multiple of " + std::to_string(per) +
                             " numbers, got " + std::to_string(p.numbers.size()));
      }
    }
    if (p.type == ParamType::kSpectrum && p.numbers.size() % 2 != 0) {
      fail(p.location, "parameter " + decl +
                           " takes wavelength-value pairs, got an odd number of numbers (" +
                           std::to_string(p.numbers.size()) + ")");
    }
  }

  void include(const Statement& s) {
    const std::string& name = s.strings[0];
    const Location& at = s.stringLocations[0];
    if (name.empty()) fail(at, s.directive + " takes a file name, got an empty string");
    if (int(open_.size()) >= kMaxIncludeDepth) {
      fail(s.location, s.directive + " nested more than " + std::to_string(kMaxIncludeDepth) +
                           " files deep (an include cycle?)");
    }
    const fs::path path = resolvePath(name, s.location, mainFile_);
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(path, ec);
    if (!ec && std::find(open_.begin(), open_.end(), canonical) != open_.end()) {
      fail(at, s.directive + " cycle: " + scene_detail::quotedPath(path.string()) +
                   " is already being read (it includes itself, directly or through others)");
    }
    std::string text, why;
    if (!scene_detail::readTextFile(path, &text, &why)) {
      const std::string looked =
          path.string() == name ? std::string()
                                : "looked for " + scene_detail::quotedPath(path.string()) + ": ";
      fail(at, "cannot open " + scene_detail::quotedPath(name) + " (" + looked + why + ")");
    }
    parse(std::move(text), path.string());
  }

  const StatementHandler& handler_;
  fs::path mainFile_;
  std::vector<fs::path> open_;  // the files being read, outermost first (canonical)
};

}  // namespace

const std::vector<std::string_view>& directiveNames() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> all;
    for (const DirectiveSpec& d : kDirectives) all.push_back(d.name);
    return all;
  }();
  return names;
}

void parseText(std::string text, const fs::path& path, const StatementHandler& handler) {
  Parser parser(handler, path);
  parser.parse(std::move(text), path.string());
}

void parseFile(const fs::path& path, const StatementHandler& handler) {
  std::string text, why;
  if (!scene_detail::readTextFile(path, &text, &why)) {
    scene_detail::throwInputError(path.string(), "", "cannot open scene file (" + why + ")");
  }
  parseText(std::move(text), path, handler);
}

}  // namespace pt::pbrt
