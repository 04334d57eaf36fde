// The GLSL copies of the model (shaders/reflectance_model.glsl, shaders/reflectance_fit.comp) against the C++
// model (core/model/): every constant a shader names at file scope has its C++ value, each shader
// names it once, and no shader writes one of those values as a bare literal elsewhere, so that a
// change of the model's constant cannot leave a shader behind.
#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "model/lobe.h"
#include "model/vertex_model.h"
#include "samples/samples.h"

using namespace vbrdf;

namespace {

std::string read_shader(const std::string &name) {
  std::ifstream in(std::string(VBRDF_SOURCE_DIR) + "/shaders/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The code without its comments (// to the end of the line, /* ... */).
std::string without_comments(const std::string &source) {
  std::string out;
  for (size_t i = 0; i < source.size();) {
    if (source.compare(i, 2, "//") == 0) {
      i = source.find('\n', i);
      if (i == std::string::npos) break;
    } else if (source.compare(i, 2, "/*") == 0) {
      const size_t end = source.find("*/", i + 2);
      i = end == std::string::npos ? source.size() : end + 2;
      out += ' ';
    } else {
      out += source[i++];
    }
  }
  return out;
}

// The C++ value of each constant the shaders may name.
const std::map<std::string, double> &model_constants() {
  static const std::map<std::string, double> table = {
      {"kMaxFootprintVariance", kMaxFootprintVariance},
      {"kLobeLogFloor", kLobeLogFloor},
      {"kUnusable", double(kNotSeen | kShadowed | kSaturated | kMixedPixel)},
      {"kStatusDiffuseOnly", double(kFitDiffuseOnly)},
      {"kStatusFull", double(kFitFull)},
  };
  return table;
}

// A GLSL number ("0.18", "-80.0", "0x13Fu", "2u") as a double.
double glsl_number(std::string text) {
  if (!text.empty() && (text.back() == 'u' || text.back() == 'U')) text.pop_back();
  return text.find("0x") == 0 ? double(std::stoul(text, nullptr, 16)) : std::stod(text);
}

// Every file-scope `const <type> kName = value[, kName = value];` of the code: name -> values.
std::multimap<std::string, std::string> named_constants(const std::string &code) {
  std::multimap<std::string, std::string> out;
  const std::regex declaration(R"((^|\n)const\s+(float|int|uint)\s+([^;]*);)");
  const std::regex entry(R"(\s*(k\w+)\s*=\s*([-+0-9.xXa-fA-FuU]+)\s*)");
  for (std::sregex_iterator d(code.begin(), code.end(), declaration), end; d != end; ++d) {
    std::stringstream list((*d)[3].str());
    for (std::string item; std::getline(list, item, ',');) {
      std::smatch m;
      if (std::regex_match(item, m, entry)) out.emplace(m[1].str(), m[2].str());
      else out.emplace(item, "");  // not a plain named number: fails below
    }
  }
  return out;
}

// How often the literal `value` (as written in the declaration) stands as a number token in `code`.
int literal_count(const std::string &code, const std::string &value) {
  std::string digits = value;
  if (!digits.empty() && (digits[0] == '-' || digits[0] == '+')) digits.erase(0, 1);
  const std::regex token("(^|[^\\w.])" + std::regex_replace(digits, std::regex(R"([.])"), R"(\.)") + R"((?![\w.]))");
  return int(std::distance(std::sregex_iterator(code.begin(), code.end(), token), std::sregex_iterator()));
}

void check_shader(const std::string &name, const std::vector<std::string> &required) {
  const std::string source = read_shader(name);
  ASSERT_FALSE(source.empty()) << "cannot read shaders/" << name;
  const std::string code = without_comments(source);
  const std::multimap<std::string, std::string> named = named_constants(code);
  for (const auto &c : named) {
    const auto known = model_constants().find(c.first);
    ASSERT_NE(known, model_constants().end()) << name << ": '" << c.first << "' is no constant of the C++ model";
    EXPECT_EQ(named.count(c.first), 1u) << name << " names " << c.first << " more than once";
    EXPECT_EQ(float(glsl_number(c.second)), float(known->second)) << name << ": " << c.first << " = " << c.second;
    // The model's real numbers (flag and status codes are small integers found everywhere).
    if (c.second.find('.') != std::string::npos)
      EXPECT_EQ(literal_count(code, c.second), 1) << name << " writes " << c.first << "'s value " << c.second
                                                  << " as a bare literal besides its declaration";
  }
  for (const std::string &r : required) EXPECT_EQ(named.count(r), 1u) << name << " does not name " << r;
}

} // namespace

TEST(ModelConstants, TheRelightModelShaderNamesTheModelsConstants) {
  check_shader("reflectance_model.glsl", {"kMaxFootprintVariance", "kLobeLogFloor"});
}

TEST(ModelConstants, TheFitShaderNamesTheModelsConstants) {
  check_shader("reflectance_fit.comp", {"kMaxFootprintVariance", "kLobeLogFloor", "kUnusable", "kStatusDiffuseOnly",
                                  "kStatusFull"});
}

// The checker itself: a bare copy of a named value, or a constant the model does not know, is caught.
TEST(ModelConstants, TheCheckFindsABareCopyOfANamedValue) {
  const std::string code = without_comments("const float kMaxFootprintVariance = 0.18;  // 0.18\n"
                                            "float f(float v) { return min(v, 0.18) + 10.18 + 0.180; }\n");
  const auto named = named_constants(code);
  ASSERT_EQ(named.count("kMaxFootprintVariance"), 1u);
  EXPECT_EQ(literal_count(code, "0.18"), 2);  // the declaration and one bare copy (not 10.18, 0.180)
  EXPECT_EQ(literal_count(code, "-80.0"), 0);
  EXPECT_EQ(named_constants("const float kUnknown = 1.0;\n").count("kUnknown"), 1u);
  EXPECT_EQ(model_constants().count("kUnknown"), 0u);
}
