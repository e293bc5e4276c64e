#include <gtest/gtest.h>

#include <string>

#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"

using namespace mcslam;

namespace {

// The "billion laughs": nine levels of ten aliases each, 10^9 leaves when expanded.
std::string aliasBomb() {
  std::string text = "l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (char level = '1'; level <= '9'; ++level) {
    const std::string name(1, level), prev(1, static_cast<char>(level - 1));
    text.append("l").append(name).append(": &l").append(name).append(" [");
    for (int i = 0; i < 10; ++i) text.append(i ? ", *l" : "*l").append(prev);
    text.append("]\n");
  }
  return text;
}

std::string errorOf(const std::string& text) {
  try {
    parseYamlText(text, "f.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ParseYamlText, AliasesAreCheckedOnceNotExpanded) {
  const YAML::Node root = parseYamlText(aliasBomb(), "bomb.yaml");
  EXPECT_EQ(root["l9"].size(), 10u);
  // A duplicate key behind an alias is still found.
  EXPECT_NE(errorOf("a: &a {k: 1, k: 2}\nb: *a\n").find("a.k: appears twice"), std::string::npos);
}

TEST(ParseYamlText, AnAliasInsideItsOwnAnchorIsALoopError) {
  const std::string error = errorOf("top:\n  a: &a [x, *a]\n");
  EXPECT_NE(error.find("f.yaml: line 2: top.a"), std::string::npos) << error;
  EXPECT_NE(error.find("loop"), std::string::npos) << error;
  EXPECT_NE(errorOf("m: &m {self: *m}\n").find("loop"), std::string::npos);
}

TEST(ParseYamlText, ADuplicateKeyNamesBothLines) {
  EXPECT_NE(errorOf("x: 1\ny: {a: 1}\nx: 2\n").find("f.yaml: line 3: x: appears twice in one map (first at line 1)"),
            std::string::npos);
}

// Readers take keys as words (as<std::string>()): a list or map as a key is refused where the file is parsed.
TEST(ParseYamlText, AKeyThatIsAListOrMapIsAnError) {
  EXPECT_NE(errorOf("cam0:\n  ? [a, b]\n  : 1\n").find("f.yaml: line 2: cam0: a key must be a word, got a list"),
            std::string::npos)
      << errorOf("cam0:\n  ? [a, b]\n  : 1\n");
  EXPECT_NE(errorOf("{x: 1}: 2\n").find("a key must be a word, got a map"), std::string::npos);
}
