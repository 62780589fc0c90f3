// The README's element reference is the program's own table, not a hand copy.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "solver/elements/element.h"

TEST(Readme, ElementReferenceMatchesTheParameterTables) {
  std::ifstream in(std::string(ISOLINK_SOURCE_DIR) + "/README.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const std::string begin = "<!-- elements:begin -->\n", end = "<!-- elements:end -->";
  const size_t a = text.find(begin), b = text.find(end);
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  EXPECT_EQ(text.substr(a + begin.size(), b - a - begin.size()),
            isolink::element_reference_markdown())
      << "regenerate with: build/cli/isolink elements --markdown";
}
