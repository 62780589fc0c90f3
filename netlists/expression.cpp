#include "netlists/expression.h"

#include <cctype>
#include <cmath>
#include <numbers>
#include <vector>

#include "base/si_number.h"
#include "netlists/lexer.h"

namespace isolink::spice {
namespace {

bool is_ident_start(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool is_ident_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

struct Function {
  const char* name;
  int arity;
  double (*f)(const double* a);
};

const Function kFunctions[] = {
    {"sqrt", 1, [](const double* a) { return std::sqrt(a[0]); }},
    {"exp", 1, [](const double* a) { return std::exp(a[0]); }},
    {"log", 1, [](const double* a) { return std::log(a[0]); }},
    {"ln", 1, [](const double* a) { return std::log(a[0]); }},
    {"log10", 1, [](const double* a) { return std::log10(a[0]); }},
    {"sin", 1, [](const double* a) { return std::sin(a[0]); }},
    {"cos", 1, [](const double* a) { return std::cos(a[0]); }},
    {"tan", 1, [](const double* a) { return std::tan(a[0]); }},
    {"atan", 1, [](const double* a) { return std::atan(a[0]); }},
    {"sinh", 1, [](const double* a) { return std::sinh(a[0]); }},
    {"cosh", 1, [](const double* a) { return std::cosh(a[0]); }},
    {"tanh", 1, [](const double* a) { return std::tanh(a[0]); }},
    {"abs", 1, [](const double* a) { return std::fabs(a[0]); }},
    {"floor", 1, [](const double* a) { return std::floor(a[0]); }},
    {"ceil", 1, [](const double* a) { return std::ceil(a[0]); }},
    {"min", 2, [](const double* a) { return std::fmin(a[0], a[1]); }},
    {"max", 2, [](const double* a) { return std::fmax(a[0], a[1]); }},
    {"pow", 2, [](const double* a) { return std::pow(a[0], a[1]); }},
};

class Parser {
 public:
  Parser(std::string_view s, const ParamLookup& lookup, const OffsetLoc& where,
         const FunctionLookup& functions, int depth, bool single_equals = false)
      : s_(s),
        lookup_(lookup),
        where_(where),
        functions_(functions),
        depth_(depth),
        single_equals_(single_equals) {}

  StatusOr<double> run() {
    double v = 0;
    skip();
    if (pos_ >= s_.size()) {
      fail(pos_, "empty expression");
    } else if (expr(v)) {
      skip();
      if (pos_ < s_.size()) {
        if (s_[pos_] == ')' || s_[pos_] == '}')
          fail(pos_, std::string("unbalanced '") + s_[pos_] + "' in expression");
        else
          fail(pos_, std::string("unexpected '") + s_[pos_] + "' in expression");
      } else if (!std::isfinite(v)) {
        fail(0, "expression value is not a finite number");
      } else {
        return v;
      }
    }
    return status_;
  }

 private:
  bool fail(std::size_t off, const std::string& msg) {
    status_ = error_at(where_(off), msg);
    return false;
  }
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool peek(char c) {
    skip();
    return pos_ < s_.size() && s_[pos_] == c;
  }

  // Two-character operator at pos_ (after blanks)?
  bool peek2(const char* op) {
    skip();
    return pos_ + 1 < s_.size() && s_[pos_] == op[0] && s_[pos_ + 1] == op[1];
  }

  bool expr(double& v) { return ternary(v); }  // every nesting passes through unary's depth count

  bool ternary(double& v) {
    if (!logical_or(v)) return false;
    if (!peek('?')) return true;
    ++pos_;
    double a = 0, b = 0;
    if (!expr(a)) return false;
    if (!peek(':')) return fail(pos_, "expected ':' in 'cond ? a : b'");
    ++pos_;
    if (!expr(b)) return false;
    v = v != 0.0 ? a : b;
    return true;
  }

  bool logical_or(double& v) {
    if (!logical_and(v)) return false;
    while (peek2("||")) {
      pos_ += 2;
      double r = 0;
      if (!logical_and(r)) return false;
      v = (v != 0.0 || r != 0.0) ? 1.0 : 0.0;
    }
    return true;
  }

  bool logical_and(double& v) {
    if (!compare(v)) return false;
    while (peek2("&&")) {
      pos_ += 2;
      double r = 0;
      if (!compare(r)) return false;
      v = (v != 0.0 && r != 0.0) ? 1.0 : 0.0;
    }
    return true;
  }

  bool compare(double& v) {
    if (!sum(v)) return false;
    while (true) {
      skip();
      if (pos_ >= s_.size()) return true;
      const char c = s_[pos_];
      const bool eq_next = pos_ + 1 < s_.size() && s_[pos_ + 1] == '=';
      int op = 0;  // 1 ==, 2 !=, 3 <, 4 >, 5 <=, 6 >=, 7 = (in a condition)
      if (c == '=' && eq_next)
        op = 1;
      else if (c == '=' && !single_equals_)
        return fail(pos_,
                    "'=' in an expression: equality is '==' (a single '=' means equality only in "
                    "a .if / .elseif condition)");
      else if (c == '=')
        op = 7;  // '=' as equality, as ngspice reads it in a condition
      else if (c == '!' && eq_next)
        op = 2;
      else if (c == '<')
        op = eq_next ? 5 : 3;
      else if (c == '>')
        op = eq_next ? 6 : 4;
      else
        return true;
      pos_ += (op == 3 || op == 4 || op == 7) ? 1 : 2;
      double r = 0;
      if (!sum(r)) return false;
      bool t = false;
      switch (op) {
        case 1:
        case 7:
          t = v == r;
          break;
        case 2:
          t = v != r;
          break;
        case 3:
          t = v < r;
          break;
        case 4:
          t = v > r;
          break;
        case 5:
          t = v <= r;
          break;
        default:
          t = v >= r;
          break;
      }
      v = t ? 1.0 : 0.0;
    }
  }

  bool sum(double& v) {
    if (!term(v)) return false;
    while (true) {
      skip();
      if (pos_ >= s_.size() || (s_[pos_] != '+' && s_[pos_] != '-')) return true;
      const char op = s_[pos_++];
      double r = 0;
      if (!term(r)) return false;
      v = op == '+' ? v + r : v - r;
    }
  }

  bool term(double& v) {
    if (!unary(v)) return false;
    while (true) {
      skip();
      if (pos_ >= s_.size()) return true;
      const char op = s_[pos_];
      if (op != '*' && op != '/') return true;
      if (op == '*' && pos_ + 1 < s_.size() && s_[pos_ + 1] == '*') return true;  // power
      const std::size_t at = pos_++;
      double r = 0;
      if (!unary(r)) return false;
      if (op == '/') {
        if (r == 0.0) {
          fail(at, "division by zero");
          return false;
        }
        v /= r;
      } else {
        v *= r;
      }
    }
  }

  bool unary(double& v) {
    if (++depth_ > kMaxDepth) return fail(pos_, "expression nested too deeply");
    const bool ok = unary_inner(v);
    --depth_;
    return ok;
  }

  bool unary_inner(double& v) {
    skip();
    if (pos_ + 1 < s_.size() && s_[pos_] == '!' && s_[pos_ + 1] != '=') {
      ++pos_;
      if (!unary(v)) return false;
      v = v == 0.0 ? 1.0 : 0.0;
      return true;
    }
    if (pos_ < s_.size() && (s_[pos_] == '-' || s_[pos_] == '+')) {
      const bool neg = s_[pos_++] == '-';
      if (!unary(v)) return false;
      if (neg) v = -v;
      return true;
    }
    return power(v);
  }

  bool power(double& v) {
    if (!primary(v)) return false;
    skip();
    if (pos_ < s_.size() && s_[pos_] == '^') {
      ++pos_;
    } else if (pos_ + 1 < s_.size() && s_[pos_] == '*' && s_[pos_ + 1] == '*') {
      pos_ += 2;
    } else {
      return true;
    }
    double e = 0;
    if (!unary(e)) return false;
    v = std::pow(v, e);
    return true;
  }

  bool primary(double& v) {
    skip();
    if (pos_ >= s_.size()) {
      fail(pos_, "expected a value at the end of the expression");
      return false;
    }
    const std::size_t start = pos_;
    const char c = s_[pos_];
    if (c == '(' || c == '{') {
      const char close = c == '(' ? ')' : '}';
      ++pos_;
      if (!expr(v)) return false;
      if (!peek(close)) {
        fail(start, std::string("unbalanced '") + c + "' in expression: missing '" + close + "'");
        return false;
      }
      ++pos_;
      return true;
    }
    if (auto num = scan_si_number(s_.substr(pos_))) {
      pos_ += num->length;
      if (pos_ < s_.size() &&
          (s_[pos_] == '.' || std::isdigit(static_cast<unsigned char>(s_[pos_])) ||
           s_[pos_] == '_')) {
        fail(start, "malformed number '" +
                        std::string(s_.substr(start, end_of_word(start) - start)) + "'");
        return false;
      }
      v = num->value;
      return true;
    }
    if (is_ident_start(c)) {
      std::size_t j = pos_;
      while (j < s_.size() && is_ident_char(s_[j])) ++j;
      const std::string name = lower(s_.substr(pos_, j - pos_));
      pos_ = j;
      if (peek('(')) return call(name, start, v);
      if (auto p = lookup_(name)) {
        v = *p;
        return true;
      }
      if (name == "pi") {
        v = std::numbers::pi;
        return true;
      }
      fail(start, "undefined parameter '" + name + "'");
      return false;
    }
    if (c == ')' || c == '}') {
      fail(pos_, std::string("unbalanced '") + c + "' in expression");
      return false;
    }
    fail(pos_, std::string("unexpected '") + c + "' in expression, expected a value");
    return false;
  }

  bool call(const std::string& name, std::size_t start, double& v) {
    const UserFunction* user = functions_ ? functions_(name) : nullptr;
    const Function* fn = nullptr;
    if (!user)
      for (const auto& f : kFunctions)
        if (name == f.name) fn = &f;
    if (!fn && !user) {
      fail(start, "unknown function '" + name + "'");
      return false;
    }
    const std::size_t open = pos_++;  // at '('
    std::vector<double> args;
    if (!peek(')')) {
      while (true) {
        double a = 0;
        if (!expr(a)) return false;
        args.push_back(a);
        if (peek(',')) {
          ++pos_;
          continue;
        }
        break;
      }
    }
    if (!peek(')')) {
      fail(open, "unbalanced '(' in expression: missing ')'");
      return false;
    }
    ++pos_;
    const int arity = user ? static_cast<int>(user->params.size()) : fn->arity;
    if (static_cast<int>(args.size()) != arity) {
      fail(start, name + "() takes " + std::to_string(arity) + " argument" +
                      (arity == 1 ? "" : "s") + ", got " + std::to_string(args.size()));
      return false;
    }
    if (user) {
      if (depth_ + 10 > kMaxDepth)
        return fail(start, "function calls nested too deeply in " + name + "()");
      const ParamLookup inner = [&](const std::string& p) -> std::optional<double> {
        for (std::size_t k = 0; k < user->params.size(); ++k)
          if (user->params[k] == p) return args[k];
        return lookup_(p);
      };
      StatusOr<double> r = Parser(user->body, inner, user->where, functions_, depth_ + 10).run();
      if (!r) {
        status_ = Status::Error(r.status().message() + "\n (in a call of " + name + "() at " +
                                where_(start).str() + ")");
        return false;
      }
      v = *r;
      return true;
    }
    v = fn->f(args.data());
    if (!std::isfinite(v)) {
      fail(start, name + "() result is not a finite number");
      return false;
    }
    return true;
  }

  std::size_t end_of_word(std::size_t i) const {
    while (i < s_.size() && (is_ident_char(s_[i]) || s_[i] == '.')) ++i;
    return i;
  }

  std::string_view s_;
  const ParamLookup& lookup_;
  const OffsetLoc& where_;
  const FunctionLookup& functions_;
  std::size_t pos_ = 0;
  int depth_ = 0;
  bool single_equals_ = false;  // '=' is equality (a .if / .elseif condition)
  Status status_;
  static constexpr int kMaxDepth = 200;
};

}  // namespace

StatusOr<double> evaluate_expression(std::string_view text, const ParamLookup& lookup,
                                     const OffsetLoc& where, const FunctionLookup& functions,
                                     bool condition) {
  return Parser(text, lookup, where, functions, 0, condition).run();
}

}  // namespace isolink::spice
