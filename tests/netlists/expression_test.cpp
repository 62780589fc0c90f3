#include "netlists/expression.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

namespace isolink::spice {
namespace {

class ExpressionTest : public ::testing::Test {
 protected:
  StatusOr<double> eval(const std::string& text) {
    file_ = SourceFile::FromText("e.cir", "R1 a b {" + text + "}");
    return evaluate_expression(
        text,
        [&](const std::string& n) -> std::optional<double> {
          auto it = params_.find(n);
          if (it == params_.end()) return std::nullopt;
          return it->second;
        },
        [&](std::size_t off) {
          return SourceLoc{file_, 1, 9 + static_cast<int>(off)};
        });
  }
  double value(const std::string& text) {
    auto v = eval(text);
    EXPECT_TRUE(v) << text << ": " << v.status().message();
    return v ? *v : std::nan("");
  }
  std::string error(const std::string& text) {
    auto v = eval(text);
    EXPECT_FALSE(v) << text;
    return v ? "" : v.status().message();
  }
  std::map<std::string, double> params_{{"a", 2.0}, {"rx", 50.0}, {"c_load", 1e-12}};
  std::shared_ptr<const SourceFile> file_;
};

TEST_F(ExpressionTest, Arithmetic) {
  EXPECT_DOUBLE_EQ(value("1+2*3"), 7.0);
  EXPECT_DOUBLE_EQ(value("(1+2)*3"), 9.0);
  EXPECT_DOUBLE_EQ(value("10/4-1"), 1.5);
  EXPECT_DOUBLE_EQ(value("8-2-1"), 5.0);  // left associative
  EXPECT_DOUBLE_EQ(value("16/4/2"), 2.0);
  EXPECT_DOUBLE_EQ(value("2^3^2"), 512.0);  // right associative
  EXPECT_DOUBLE_EQ(value("2**3"), 8.0);
  EXPECT_DOUBLE_EQ(value("-2^2"), -4.0);
  EXPECT_DOUBLE_EQ(value("2^-1"), 0.5);
  EXPECT_DOUBLE_EQ(value("--3"), 3.0);
  EXPECT_DOUBLE_EQ(value("2*-3"), -6.0);
  EXPECT_DOUBLE_EQ(value(" 1k * 2.2n "), 2.2e-6);
  EXPECT_DOUBLE_EQ(value("1meg/1m"), 1e9);
  EXPECT_DOUBLE_EQ(value("1e-9*2"), 2e-9);
}

TEST_F(ExpressionTest, ParamsAndFunctions) {
  EXPECT_DOUBLE_EQ(value("a*rx"), 100.0);
  EXPECT_DOUBLE_EQ(value("A*RX"), 100.0);  // case-insensitive
  EXPECT_DOUBLE_EQ(value("c_load*1e12"), 1.0);
  EXPECT_DOUBLE_EQ(value("sqrt(16)+abs(-3)"), 7.0);
  EXPECT_DOUBLE_EQ(value("exp(0)+ln(1)+log(1)"), 1.0);
  EXPECT_DOUBLE_EQ(value("log10(1000)"), 3.0);
  EXPECT_DOUBLE_EQ(value("log(exp(2))"), 2.0);  // log is natural, as in ngspice
  EXPECT_DOUBLE_EQ(value("min(3, a) + max(3, a)"), 5.0);
  EXPECT_DOUBLE_EQ(value("pow(2, 10)"), 1024.0);
  EXPECT_DOUBLE_EQ(value("floor(2.7)+ceil(2.2)"), 5.0);
  EXPECT_DOUBLE_EQ(value("sin(pi/2)+cos(0)"), 2.0);
  EXPECT_NEAR(value("tan(pi/4)"), 1.0, 1e-15);
  EXPECT_DOUBLE_EQ(value("2*pi*1meg"), 2 * std::numbers::pi * 1e6);
  EXPECT_DOUBLE_EQ(value("1/(2*pi*sqrt(1u*1n))"), 1.0 / (2 * std::numbers::pi * std::sqrt(1e-15)));
  EXPECT_DOUBLE_EQ(value("{a}*3"), 6.0);  // braces group like parentheses
}

// ngspice's comparison, logical and ternary operators: true is 1, false 0.
TEST_F(ExpressionTest, ComparisonLogicalAndTernary) {
  params_["a"] = 2;
  EXPECT_EQ(value("a == 2"), 1.0);
  EXPECT_EQ(value("a != 2"), 0.0);
  EXPECT_EQ(value("a < 3") + value("a > 3") + value("a <= 2") + value("a >= 2.5"), 2.0);
  EXPECT_EQ(value("1 && 0 || 1"), 1.0);  // && binds tighter than ||
  EXPECT_EQ(value("0 || 0 && 1"), 0.0);
  EXPECT_EQ(value("!a"), 0.0);
  EXPECT_EQ(value("!!a"), 1.0);
  EXPECT_EQ(value("a + 1 > 2 * a - 2"), 1.0);  // arithmetic before comparison: 3 > 2
  EXPECT_EQ(value("a > 1 ? 10 : 20"), 10.0);
  EXPECT_EQ(value("a > 5 ? 10 : a > 1 ? 30 : 40"), 30.0);  // right-associative
  EXPECT_EQ(value("(a == 2 ? 1k : 2k) * 2"), 2000.0);
  auto e = eval("a ? 1");
  ASSERT_FALSE(e);
  EXPECT_NE(e.status().message().find("expected ':'"), std::string::npos);
}

TEST_F(ExpressionTest, UserFunctions) {
  params_["g"] = 3;
  file_ = SourceFile::FromText("e.cir", "R1 a b {x}");
  UserFunction par{{"a", "b"}, "a*b/(a+b)", [&](std::size_t o) {
                     return SourceLoc{file_, 1, 1 + static_cast<int>(o)};
                   }};
  UserFunction scaled{{"x"}, "par(x, x) * g", par.where};  // calls par, sees parameter g
  UserFunction rec{{"x"}, "rec(x)", par.where};
  auto funcs = [&](const std::string& n) -> const UserFunction* {
    return n == "par" ? &par : n == "scaled" ? &scaled : n == "rec" ? &rec : nullptr;
  };
  auto eval_f = [&](const std::string& text) {
    return evaluate_expression(
        text,
        [&](const std::string& n) -> std::optional<double> {
          auto it = params_.find(n);
          return it == params_.end() ? std::nullopt : std::optional<double>(it->second);
        },
        par.where, funcs);
  };
  EXPECT_EQ(*eval_f("par(2k, 2k)"), 1000.0);
  EXPECT_EQ(*eval_f("scaled(4)"), 6.0);
  auto bad = eval_f("par(1)");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.status().message().find("par() takes 2 arguments, got 1"), std::string::npos);
  auto deep = eval_f("rec(1)");
  ASSERT_FALSE(deep);
  EXPECT_NE(deep.status().message().find("nested too deeply"), std::string::npos);
}

TEST_F(ExpressionTest, Errors) {
  // Columns: the expression starts at column 9 of "R1 a b {...}".
  EXPECT_EQ(error("a*zz").rfind("e.cir:1:11: error: undefined parameter 'zz'", 0), 0u);
  EXPECT_EQ(error("(1+2").rfind("e.cir:1:9: error: unbalanced '(' in expression", 0), 0u);
  EXPECT_EQ(error("1+2)").rfind("e.cir:1:12: error: unbalanced ')' in expression", 0), 0u);
  EXPECT_EQ(error("1+").rfind("e.cir:1:11: error: expected a value", 0), 0u);
  EXPECT_EQ(error("1/0").rfind("e.cir:1:10: error: division by zero", 0), 0u);
  EXPECT_EQ(error("foo(1)").rfind("e.cir:1:9: error: unknown function 'foo'", 0), 0u);
  EXPECT_EQ(error("1+max(1)").rfind("e.cir:1:11: error: max() takes 2 arguments, got 1", 0), 0u);
  EXPECT_EQ(error("sqrt(-1)").rfind("e.cir:1:9: error: sqrt() result is not a finite", 0), 0u);
  EXPECT_EQ(error("2*1.2.3").rfind("e.cir:1:11: error: malformed number '1.2.3'", 0), 0u);
  // a single '=' is equality only in a .if / .elseif condition: here it is named at its column
  EXPECT_EQ(error("(a = 2)").rfind("e.cir:1:12: error: '=' in an expression: equality is '==' "
                                   "(a single '=' means equality only in a .if / .elseif "
                                   "condition)",
                                   0),
            0u)
      << error("(a = 2)");
  EXPECT_EQ(error("2 $ 3").rfind("e.cir:1:11: error: unexpected '$'", 0), 0u);
  EXPECT_EQ(error("").rfind("e.cir:1:9: error: empty expression", 0), 0u);
  // Deep nesting is an error, not a stack overflow.
  EXPECT_DOUBLE_EQ(value(std::string(150, '(') + "1" + std::string(150, ')')), 1.0);
  EXPECT_EQ(error(std::string(100000, '(') + "1" + std::string(100000, ')'))
                .rfind("e.cir:1:209: error: expression nested too deeply", 0),  // 201st level
            0u);
}

}  // namespace
}  // namespace isolink::spice
