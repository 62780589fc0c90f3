#include "netlists/lexer.h"

#include <gtest/gtest.h>

namespace isolink::spice {
namespace {

TEST(JoinLines, CommentsAndContinuations) {
  auto file = SourceFile::FromText("t.cir",
                                   "title\n"
                                   "* a comment\n"
                                   "R1 a b 1k ; inline comment\n"
                                   "V1 a 0 PWL(0 0\n"
                                   "* comment between continuation lines\n"
                                   "\n"
                                   "+ 1n 5 $ dollar comment\n"
                                   "  + 2n 0)\n"
                                   "C1 a$b 0 1p\n");
  auto lines = join_lines(file, 2);
  ASSERT_TRUE(lines) << lines.status().message();
  ASSERT_EQ(lines->size(), 3u);
  EXPECT_EQ((*lines)[0].text, "R1 a b 1k ");
  EXPECT_EQ((*lines)[1].text, "V1 a 0 PWL(0 0  1n 5   2n 0)");
  EXPECT_EQ((*lines)[2].text, "C1 a$b 0 1p");  // '$' inside a word is not a comment
  // Offsets map back to the physical lines: "1n" is on line 7, column 3.
  const LogicalLine& pwl = (*lines)[1];
  const std::size_t at = pwl.text.find("1n");
  SourceLoc loc = pwl.loc(at);
  EXPECT_EQ(loc.line, 7);
  EXPECT_EQ(loc.col, 3);
  loc = pwl.loc(pwl.text.find("2n"));
  EXPECT_EQ(loc.line, 8);
  EXPECT_EQ(loc.col, 5);
  loc = pwl.loc(pwl.text.find("PWL"));
  EXPECT_EQ(loc.line, 4);
  EXPECT_EQ(loc.col, 8);
}

TEST(JoinLines, ContinuationWithoutCard) {
  auto file = SourceFile::FromText("t.cir", "title\n  + 1 2\n");
  auto lines = join_lines(file, 2);
  ASSERT_FALSE(lines);
  EXPECT_EQ(lines.status().message().rfind("t.cir:2:3: error: continuation line", 0), 0u)
      << lines.status().message();
}

TEST(Tokenize, Kinds) {
  auto file = SourceFile::FromText("t.cir", "V1 p 0 PULSE (0, 5) ic={a*2} 'b+1'");
  auto lines = join_lines(file, 1);
  ASSERT_TRUE(lines);
  auto toks = tokenize((*lines)[0]);
  ASSERT_TRUE(toks) << toks.status().message();
  ASSERT_EQ(toks->size(), 13u);
  const auto& t = *toks;
  EXPECT_EQ(t[3].text, "PULSE");
  EXPECT_EQ(t[4].kind, TokenKind::LParen);
  EXPECT_EQ(t[6].kind, TokenKind::Comma);
  EXPECT_EQ(t[8].kind, TokenKind::RParen);
  EXPECT_EQ(t[9].text, "ic");
  EXPECT_EQ(t[10].kind, TokenKind::Equals);
  EXPECT_EQ(t[11].kind, TokenKind::Expr);
  EXPECT_EQ(t[11].text, "a*2");
  EXPECT_EQ(t[11].offset, 23u);
  EXPECT_EQ(t[11].end(), 28u);  // just past the closing brace
  EXPECT_EQ(t[12].kind, TokenKind::Expr);
  EXPECT_EQ(t[12].text, "b+1");
}

std::string tokenize_error(const char* text) {
  auto file = SourceFile::FromText("t.cir", text);
  auto lines = join_lines(file, 1);
  EXPECT_TRUE(lines);
  auto toks = tokenize((*lines)[0]);
  EXPECT_FALSE(toks);
  return toks ? "" : toks.status().message();
}

TEST(Tokenize, Unbalanced) {
  EXPECT_EQ(tokenize_error("V1 a 0 PULSE(0 5 1n").substr(0, 50),
            "t.cir:1:13: error: unbalanced '(': missing ')'\n V1");
  EXPECT_EQ(tokenize_error("R1 a b 1k)").rfind("t.cir:1:10: error: unbalanced ')'", 0), 0u);
  EXPECT_EQ(tokenize_error("R1 a b {1k").rfind("t.cir:1:8: error: unbalanced '{'", 0), 0u);
  EXPECT_EQ(tokenize_error("R1 a b 1k}").rfind("t.cir:1:10: error: unbalanced '}'", 0), 0u);
  EXPECT_EQ(tokenize_error("R1 a b '1k").rfind("t.cir:1:8: error: unterminated", 0), 0u);
}

}  // namespace
}  // namespace isolink::spice
