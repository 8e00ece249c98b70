// The pbrt-v4 tokenizer and directive parser (host/scene/pbrt/pbrt_parser.h): every directive
// and parameter type, pbrt-v3's spellings, Include paths, and every syntax error's exact
// message with its file:line:column. What the statements mean: pbrt_scene_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "common/check.h"
#include "scene/pbrt/pbrt_parser.h"
#include "test_util.h"

namespace pt {
namespace {

namespace fs = std::filesystem;
using pbrt::Param;
using pbrt::ParamType;
using pbrt::Statement;

std::vector<Statement> parse(const std::string& text, const fs::path& path = "scene.pbrt") {
  std::vector<Statement> statements;
  pbrt::parseText(text, path, [&](Statement& s) { statements.push_back(s); });
  return statements;
}

// The message of the InputError that parsing `text` throws, or "no error".
std::string parseErrorOf(const std::string& text, const fs::path& path = "scene.pbrt") {
  try {
    parse(text, path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(PbrtParser, EveryDirectiveWithItsArguments) {
  const std::string text = R"(# a comment
Option "disablepixeljitter" true
ColorSpace "srgb"
Film "rgb" "integer xresolution" 64
PixelFilter "box"
Sampler "zsobol" "integer pixelsamples" [ 8 ]
Integrator "volpath" "integer maxdepth" [ 3 ]
Accelerator "bvh"
TransformTimes 0 1
ActiveTransform StartTime
Identity
Translate 1 2 3
Scale -1 1 1
Rotate 90 0 0 1
LookAt 0 0 -5  0 0 0  0 1 0   # eye, look, up
Transform [ 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 ]
ConcatTransform [ 1 0 0 0 0 1 0 0 0 0 1 0 4 5 6 1 ]
CoordinateSystem "mine"
CoordSysTransform "mine"
Camera "perspective" "float fov" 45
WorldBegin
AttributeBegin
Attribute "shape" "float radius" 2
AttributeEnd
TransformBegin
TransformEnd
ReverseOrientation
MakeNamedMedium "fog" "string type" "homogeneous"
MediumInterface "fog"
MediumInterface "" "fog"
Texture "checks" "spectrum" "checkerboard" "rgb tex1" [1 1 1]
MakeNamedMaterial "white" "string type" "diffuse"
NamedMaterial "white"
Material "conductor"
AreaLightSource "diffuse" "rgb L" [1 2 3]
LightSource "point"
ObjectBegin "thing"
Shape "sphere"
ObjectEnd
ObjectInstance "thing"
WorldEnd
)";
  const std::vector<Statement> s = parse(text);
  std::vector<std::string> names;
  for (const Statement& st : s) names.push_back(st.directive);
  const std::vector<std::string> expected = {"Option",
                                             "ColorSpace",
                                             "Film",
                                             "PixelFilter",
                                             "Sampler",
                                             "Integrator",
                                             "Accelerator",
                                             "TransformTimes",
                                             "ActiveTransform",
                                             "Identity",
                                             "Translate",
                                             "Scale",
                                             "Rotate",
                                             "LookAt",
                                             "Transform",
                                             "ConcatTransform",
                                             "CoordinateSystem",
                                             "CoordSysTransform",
                                             "Camera",
                                             "WorldBegin",
                                             "AttributeBegin",
                                             "Attribute",
                                             "AttributeEnd",
                                             "TransformBegin",
                                             "TransformEnd",
                                             "ReverseOrientation",
                                             "MakeNamedMedium",
                                             "MediumInterface",
                                             "MediumInterface",
                                             "Texture",
                                             "MakeNamedMaterial",
                                             "NamedMaterial",
                                             "Material",
                                             "AreaLightSource",
                                             "LightSource",
                                             "ObjectBegin",
                                             "Shape",
                                             "ObjectEnd",
                                             "ObjectInstance",
                                             "WorldEnd"};
  ASSERT_EQ(names, expected);
  // The arguments each form takes.
  EXPECT_EQ(s[0].strings, (std::vector<std::string>{"disablepixeljitter", "true"}));
  EXPECT_EQ(s[1].strings, (std::vector<std::string>{"srgb"}));
  EXPECT_EQ(s[7].numbers, (std::vector<double>{0, 1}));
  EXPECT_EQ(s[8].strings, (std::vector<std::string>{"StartTime"}));
  EXPECT_EQ(s[10].numbers, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(s[12].numbers, (std::vector<double>{90, 0, 0, 1}));
  EXPECT_EQ(s[13].numbers, (std::vector<double>{0, 0, -5, 0, 0, 0, 0, 1, 0}));
  ASSERT_EQ(s[15].numbers.size(), 16u);
  EXPECT_EQ(s[15].numbers[12], 4.0);
  EXPECT_EQ(s[16].strings, (std::vector<std::string>{"mine"}));
  EXPECT_EQ(s[27].strings, (std::vector<std::string>{"fog"}));
  EXPECT_EQ(s[28].strings, (std::vector<std::string>{"", "fog"}));
  EXPECT_EQ(s[29].strings, (std::vector<std::string>{"checks", "spectrum", "checkerboard"}));
  ASSERT_EQ(s[29].params.size(), 1u);
  EXPECT_EQ(s[33].strings, (std::vector<std::string>{"diffuse"}));
  // Locations: the directive's first character; a comment after LookAt is skipped.
  EXPECT_EQ(s[13].location.toString(), "scene.pbrt:15:1");
  EXPECT_EQ(s[2].params[0].location.toString(), "scene.pbrt:4:12");
  EXPECT_EQ(s[2].stringLocations[0].toString(), "scene.pbrt:4:6");
}

TEST(PbrtParser, EveryParameterTypeAndPbrtV3Spellings) {
  const std::string text = R"(Shape "x"
  "integer a" [ 1 -2 +3 ]
  "float b" 2.5
  "point2 c" [ 1 2 ]
  "vector2 d" [ 3 4 ]
  "point3 e" [ 1 2 3 4 5 6 ]
  "vector3 f" [ 0 0 1 ]
  "normal g" [ 0 1 0 ]
  "normal3 h" [ 1 0 0 ]
  "rgb i" [ .5 1e-1 2E0 ]
  "spectrum j" "metal-Cu-eta"
  "spectrum k" [ 400 0.5 700 0.25 ]
  "blackbody l" 6500
  "bool m" true
  "bool n" [ "false" ]
  "string o" [ "a \"quoted\" \\ name" "two" ]
  "texture p" "checks"
  "point q" [ 7 8 9 ]
  "vector r" [ 1 1 1 ]
  "color s" [ 0.1 0.2 0.3 ]
  "float	tabbed" 1
)";
  const std::vector<Statement> s = parse(text);
  ASSERT_EQ(s.size(), 1u);
  const std::vector<Param>& p = s[0].params;
  ASSERT_EQ(p.size(), 20u);
  const ParamType types[] = {
      ParamType::kInteger, ParamType::kFloat,    ParamType::kPoint2,   ParamType::kVector2,
      ParamType::kPoint3,  ParamType::kVector3,  ParamType::kNormal,   ParamType::kNormal,
      ParamType::kRgb,     ParamType::kSpectrum, ParamType::kSpectrum, ParamType::kBlackbody,
      ParamType::kBool,    ParamType::kBool,     ParamType::kString,   ParamType::kTexture,
      ParamType::kPoint3,  ParamType::kVector3,  ParamType::kRgb,      ParamType::kFloat};
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_EQ(p[i].type, types[i]) << p[i].name;
  EXPECT_EQ(p[0].numbers, (std::vector<double>{1, -2, 3}));
  EXPECT_EQ(p[1].numbers, (std::vector<double>{2.5}));
  EXPECT_EQ(p[4].numbers.size(), 6u);
  EXPECT_EQ(p[8].numbers, (std::vector<double>{0.5, 0.1, 2.0}));
  EXPECT_EQ(p[9].strings, (std::vector<std::string>{"metal-Cu-eta"}));
  EXPECT_EQ(p[10].numbers, (std::vector<double>{400, 0.5, 700, 0.25}));
  EXPECT_EQ(p[11].numbers, (std::vector<double>{6500}));
  EXPECT_EQ(p[12].bools, (std::vector<bool>{true}));
  EXPECT_EQ(p[13].bools, (std::vector<bool>{false}));
  EXPECT_EQ(p[14].strings, (std::vector<std::string>{"a \"quoted\" \\ name", "two"}));
  EXPECT_EQ(p[15].strings, (std::vector<std::string>{"checks"}));
  EXPECT_EQ(p[16].typeWritten, "point");
  EXPECT_EQ(p[18].typeWritten, "color");
  EXPECT_EQ(p[18].declaration(), "color s");
  EXPECT_EQ(p[19].name, "tabbed");
  EXPECT_EQ(p[3].location.toString(), "scene.pbrt:5:3");
}

TEST(PbrtParser, ColumnsCountCharactersAndCrLfIsSpace) {
  // "é" is two bytes, one column; a byte-order mark is skipped.
  const std::vector<Statement> s =
      parse("\xef\xbb\xbfShape \"caf\xc3\xa9\" \"float r\" 1\r\nWorldBegin\r\n");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].location.toString(), "scene.pbrt:1:1");
  EXPECT_EQ(s[0].params[0].location.toString(), "scene.pbrt:1:14");
  EXPECT_EQ(s[1].location.toString(), "scene.pbrt:2:1");
}

TEST(PbrtParser, IncludeAndImportAreRelativeToTheIncludingFile) {
  test::TempDir dir;
  dir.write("sub/b.pbrt", "Include \"c.pbrt\"\nImport \"d.pbrt\"\nShape \"b\"\n");
  dir.write("sub/c.pbrt", "Shape \"c\"\n");
  dir.write("d.pbrt", "Shape \"d\"\n");  // not beside b.pbrt: the main file's directory
  const fs::path main =
      dir.write("main.pbrt", "Shape \"a\"\nInclude \"sub/b.pbrt\"\nShape \"e\"\n");
  std::vector<Statement> s;
  pbrt::parseFile(main, [&](Statement& st) { s.push_back(st); });
  ASSERT_EQ(s.size(), 5u);
  std::string order;
  for (const Statement& st : s) order += st.strings[0];
  EXPECT_EQ(order, "acdbe");
  EXPECT_EQ(s[1].location.toString(), (dir.path() / "sub" / "c.pbrt").string() + ":1:1");
  EXPECT_EQ(s[2].location.toString(), (dir.path() / "d.pbrt").string() + ":1:1");
  EXPECT_EQ(s[3].location.toString(), (dir.path() / "sub" / "b.pbrt").string() + ":3:1");
}

TEST(PbrtParser, IncludeErrors) {
  test::TempDir dir;
  const std::string d = dir.path().string();
  dir.write("self.pbrt", "WorldBegin\nInclude \"self.pbrt\"\n");
  dir.write("a.pbrt", "Include \"b.pbrt\"\n");
  dir.write("b.pbrt", "\n  Include \"a.pbrt\"\n");
  std::string message;
  try {
    pbrt::parseFile(dir / "self.pbrt", [](Statement&) {});
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, d + "/self.pbrt:2:9: Include cycle: '" + d +
                         "/self.pbrt' is already being read (it includes itself, directly or "
                         "through others)");
  try {
    pbrt::parseFile(dir / "a.pbrt", [](Statement&) {});
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, d + "/b.pbrt:2:11: Include cycle: '" + d +
                         "/a.pbrt' is already being read (it includes itself, directly or "
                         "through others)");
  EXPECT_EQ(parseErrorOf("Include \"missing.pbrt\"", dir / "m.pbrt"),
            d + "/m.pbrt:1:9: cannot open 'missing.pbrt' (looked for '" + d +
                "/missing.pbrt': No such file or directory)");
  EXPECT_EQ(parseErrorOf("Import \"\""),
            "scene.pbrt:1:8: Import takes a file name, got an empty string");
  EXPECT_EQ(parseErrorOf("Include sub.pbrt"),
            "scene.pbrt:1:9: Include takes a quoted file name, got 'sub.pbrt'");
  try {
    pbrt::parseFile(dir / "nothing.pbrt", [](Statement&) {});
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, d + "/nothing.pbrt: cannot open scene file (No such file or directory)");
}

TEST(PbrtParser, IncludeDepthIsBounded) {
  // A chain through distinct names: no file is open twice, but the depth ends it.
  test::TempDir dir;
  for (int i = 0; i < 40; ++i) {
    dir.write("f" + std::to_string(i) + ".pbrt",
              "Include \"f" + std::to_string(i + 1) + ".pbrt\"\n");
  }
  std::string message;
  try {
    pbrt::parseFile(dir / "f0.pbrt", [](Statement&) {});
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, (dir / "f31.pbrt").string() +
                         ":1:1: Include nested more than 32 files deep (an include cycle?)");
}

TEST(PbrtParser, SyntaxErrorsNameFileLineAndColumn) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"Shap \"sphere\"", "scene.pbrt:1:1: unknown directive 'Shap' (did you mean 'Shape'?)"},
      {"WorldBegin\n  Frobnicate", "scene.pbrt:2:3: unknown directive 'Frobnicate'"},
      {"Translate 1 2 3 4",
       "scene.pbrt:1:17: expected a directive, got the number '4' (too many "
       "numbers for the directive before it?)"},
      {"\"float fov\" 4",
       "scene.pbrt:1:1: expected a directive, got the string 'float fov' (a "
       "parameter without a directive?)"},
      {"[ 1 ]", "scene.pbrt:1:1: expected a directive, got '['"},
      {"Shape \"sphere\n\"", "scene.pbrt:1:7: unterminated string (a string must end on its line)"},
      {"Shape \"sphere", "scene.pbrt:1:7: unterminated string (the file ends inside it)"},
      {"Shape \"a\\qb\"",
       "scene.pbrt:1:9: unknown escape sequence '\\q' in a string (pbrt knows "
       "\\b \\f \\n \\r \\t \\\\ \\' \\\")"},
      {"Shape \"trianglemesh\" \"point3 P\" [ 0 0 0\n  1 0 0",
       "scene.pbrt:1:33: unterminated '[' (the file ends before its ']')"},
      {"Shape \"trianglemesh\" \"point3 P\" [ 0 0 0\nShape \"sphere\"",
       "scene.pbrt:1:33: unterminated '[' (the directive 'Shape' at line 2, column 1 comes "
       "before its ']')"},
      {"Shape \"a\" \"float r\" [ [ 1 ] ]", "scene.pbrt:1:23: '[' inside brackets"},
      {"Shape \"a\" \"float r\" ]", "scene.pbrt:1:21: ']' without a '['"},
      {"Shape \"a\" \"flot r\" 1",
       "scene.pbrt:1:11: unknown parameter type 'flot' in 'flot r' (did you mean 'float'?)"},
      {"Shape \"a\" \"float\" 1",
       "scene.pbrt:1:11: expected a parameter declaration \"type name\", got 'float' (no name)"},
      {"Shape \"a\" \"radius\" 1",
       "scene.pbrt:1:11: expected a parameter declaration \"type name\", got 'radius'"},
      {"Shape \"a\" \"float r s\" 1",
       "scene.pbrt:1:11: expected a parameter declaration \"type name\", got 'float r s'"},
      {"Shape \"a\" \"float r\"",
       "scene.pbrt:1:11: parameter 'float r' has no value (got the end "
       "of the file)"},
      {"Shape \"a\" \"float r\"\nWorldBegin",
       "scene.pbrt:1:11: parameter 'float r' has no value (got 'WorldBegin')"},
      {"Shape \"a\" \"float r\" [ ]", "scene.pbrt:1:11: parameter 'float r' has no values"},
      {"Shape \"a\" \"float r\" \"one\"",
       "scene.pbrt:1:21: expected a number in 'float r', got the string 'one'"},
      {"Shape \"a\" \"float r\" [ 1 x ]",
       "scene.pbrt:1:25: expected a number in 'float r', got 'x'"},
      {"Shape \"a\" \"float r\" inf", "scene.pbrt:1:21: expected a number in 'float r', got 'inf'"},
      {"Shape \"a\" \"float r\" 1e999",
       "scene.pbrt:1:21: number '1e999' in 'float r' is out of range"},
      {"Shape \"a\" \"integer n\" 1.5",
       "scene.pbrt:1:23: expected an integer in 'integer n', got '1.5'"},
      {"Shape \"a\" \"integer n\" 3000000000",
       "scene.pbrt:1:23: integer '3000000000' in 'integer n' is out of range (32 bits)"},
      {"Shape \"a\" \"bool b\" yes",
       "scene.pbrt:1:20: expected true or false in 'bool b', got 'yes'"},
      {"Shape \"a\" \"string s\" name",
       "scene.pbrt:1:22: expected a quoted string in 'string s', got 'name'"},
      {"Shape \"a\" \"point3 P\" [ 1 2 ]",
       "scene.pbrt:1:11: parameter 'point3 P' takes a multiple of 3 numbers, got 2"},
      {"Shape \"a\" \"point2 uv\" [ 1 2 3 ]",
       "scene.pbrt:1:11: parameter 'point2 uv' takes a multiple of 2 numbers, got 3"},
      {"Shape \"a\" \"color c\" [ 1 2 ]",
       "scene.pbrt:1:11: parameter 'color c' takes a multiple of 3 numbers, got 2"},
      {"Shape \"a\" \"spectrum s\" [ 400 1 500 ]",
       "scene.pbrt:1:11: parameter 'spectrum s' takes wavelength-value pairs, got an odd number "
       "of numbers (3)"},
      {"Shape \"a\" \"spectrum s\" [ \"a\" \"b\" ]",
       "scene.pbrt:1:30: a spectrum is one name or a list of wavelength-value pairs in 'spectrum "
       "s', got the string 'b'"},
      {"Shape 1", "scene.pbrt:1:7: Shape takes a quoted name, got '1'"},
      {"Shape", "scene.pbrt:1:1: Shape takes a quoted name, got the end of the file"},
      {"Texture \"t\" \"float\"",
       "scene.pbrt:1:1: Texture takes a quoted name, got the end of the "
       "file"},
      {"Translate 1 2 Shape", "scene.pbrt:1:15: Translate takes 3 numbers, got 'Shape' after 2"},
      {"LookAt 0 0 0", "scene.pbrt:1:1: LookAt takes 9 numbers, got the end of the file after 3"},
      {"Rotate 1e400 0 0 1", "scene.pbrt:1:8: number '1e400' is out of range"},
      {"Transform 1 0 0 0", "scene.pbrt:1:11: Transform takes 16 numbers in brackets, got '1'"},
      {"ConcatTransform [ 1 0 0 0 ]", "scene.pbrt:1:17: ConcatTransform takes 16 numbers, got 4"},
      {"Transform [ 1 0 0 0", "scene.pbrt:1:11: unterminated '[' (the file ends before its ']')"},
      {"Transform [ 1 0 0 a ]", "scene.pbrt:1:19: Transform takes 16 numbers, got 'a'"},
      {"ActiveTransform Sometimes",
       "scene.pbrt:1:17: ActiveTransform takes All, StartTime or EndTime, got 'Sometimes'"},
      {"Option \"seed\"",
       "scene.pbrt:1:1: Option takes a name and a value, got the end of the "
       "file for the value"},
      {"\xff\xfeS\0h\0", "scene.pbrt:1:1: the file is UTF-16 encoded; pbrt files are UTF-8"},
  };
  for (const auto& [text, message] : cases) {
    EXPECT_EQ(parseErrorOf(text), message) << text;
  }
}

TEST(PbrtParser, NumbersAsPbrtWritesThem) {
  const std::vector<Statement> s =
      parse("Shape \"a\" \"float v\" [ 1 -1 +1 .5 -.5 5. 1e3 1E-3 -0 1e-400 ]");
  EXPECT_EQ(s[0].params[0].numbers,
            (std::vector<double>{1, -1, 1, 0.5, -0.5, 5, 1000, 0.001, 0, 0}));
  for (const char* bad : {"0x10", "nan", "--1", "1.2.3", "+", "1e", "1,5"}) {
    EXPECT_NE(parseErrorOf(std::string("Shape \"a\" \"float v\" ") + bad).find("expected a number"),
              std::string::npos)
        << bad;
  }
}

TEST(PbrtParser, MessagesStayOnOneLine) {
  const std::string m = parseErrorOf("Shape \"a\" \"float \x01r\" one");
  EXPECT_EQ(m.find('\n'), std::string::npos);
  EXPECT_NE(m.find("\\x01"), std::string::npos) << m;
}

}  // namespace
}  // namespace pt
