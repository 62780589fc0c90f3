#include "netlists/lexer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace isolink::spice {
namespace {

double num(const char* s) {
  double v = std::nan("");
  EXPECT_TRUE(parse_number(s, v)) << s;
  return v;
}

TEST(SpiceNumber, SuffixTable) {
  EXPECT_DOUBLE_EQ(num("2.2nF"), 2.2e-9);
  EXPECT_DOUBLE_EQ(num("2.2n"), 2.2e-9);
  EXPECT_DOUBLE_EQ(num("1meg"), 1e6);
  EXPECT_DOUBLE_EQ(num("1MEG"), 1e6);
  EXPECT_DOUBLE_EQ(num("10Meg"), 10e6);
  EXPECT_DOUBLE_EQ(num("1m"), 1e-3);
  EXPECT_DOUBLE_EQ(num("1M"), 1e-3);  // SPICE: M is milli, not mega
  EXPECT_DOUBLE_EQ(num("1ms"), 1e-3);
  EXPECT_DOUBLE_EQ(num("10mil"), 254e-6);
  EXPECT_DOUBLE_EQ(num("1e-9"), 1e-9);
  EXPECT_DOUBLE_EQ(num("1E3"), 1000.0);
  EXPECT_DOUBLE_EQ(num("1e+3"), 1000.0);
  EXPECT_DOUBLE_EQ(num(".5u"), 0.5e-6);
  EXPECT_DOUBLE_EQ(num("5."), 5.0);
  EXPECT_DOUBLE_EQ(num("1kohm"), 1000.0);
  EXPECT_DOUBLE_EQ(num("1k"), 1000.0);
  EXPECT_DOUBLE_EQ(num("4.7K"), 4700.0);
  EXPECT_DOUBLE_EQ(num("3f"), 3e-15);
  EXPECT_DOUBLE_EQ(num("3p"), 3e-12);
  EXPECT_DOUBLE_EQ(num("2g"), 2e9);
  EXPECT_DOUBLE_EQ(num("2t"), 2e12);
  EXPECT_DOUBLE_EQ(num("2.5V"), 2.5);  // unit letters without a scale are ignored
  EXPECT_DOUBLE_EQ(num("1e3k"), 1e6);
  EXPECT_DOUBLE_EQ(num("-47p"), -47e-12);
  EXPECT_DOUBLE_EQ(num("+3"), 3.0);
  EXPECT_DOUBLE_EQ(num("100"), 100.0);
  // Exactly the decimal value, not 2.2 * 1e-9 rounded twice.
  EXPECT_EQ(num("2.2n"), 2.2e-9);
  EXPECT_EQ(num("0.1u"), 0.1e-6);
}

TEST(SpiceNumber, Malformed) {
  double v = 0;
  EXPECT_FALSE(parse_number("1.2.3", v));
  EXPECT_FALSE(parse_number("abc", v));
  EXPECT_FALSE(parse_number("", v));
  EXPECT_FALSE(parse_number("-", v));
  EXPECT_FALSE(parse_number(".", v));
  EXPECT_FALSE(parse_number("1k5.2", v));
  EXPECT_FALSE(parse_number("1.5k2", v));
  EXPECT_FALSE(parse_number("1_0", v));
  // An 'e' with no exponent digits was read as 1 with a unit letter (issue 15).
  EXPECT_FALSE(parse_number("1e", v));
  EXPECT_FALSE(parse_number("1e+", v));
  EXPECT_FALSE(parse_number("2.2E-", v));
  EXPECT_TRUE(parse_number("1e3", v));
  EXPECT_EQ(v, 1000.0);
}

// RKM (IEC 60062): the letter is the decimal point and the scale.
TEST(SpiceNumber, RkmNotation) {
  double v = 0;
  ASSERT_TRUE(parse_number("4K7", v));
  EXPECT_EQ(v, 4.7e3);
  ASSERT_TRUE(parse_number("2R2", v));
  EXPECT_EQ(v, 2.2);
  ASSERT_TRUE(parse_number("1u5", v));
  EXPECT_EQ(v, 1.5e-6);
  ASSERT_TRUE(parse_number("4m7ohm", v));
  EXPECT_EQ(v, 4.7e-3);
  ASSERT_TRUE(parse_number("10k25", v));
  EXPECT_EQ(v, 10.25e3);
  ASSERT_TRUE(parse_number("1meg", v));  // not RKM: no digit after the letter
  EXPECT_EQ(v, 1e6);
}

TEST(SpiceNumber, ScanStopsAfterUnit) {
  auto r = scan_number("2.2nF*3");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->length, 5u);
  EXPECT_DOUBLE_EQ(r->value, 2.2e-9);
  EXPECT_FALSE(scan_number("x1"));
}

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
