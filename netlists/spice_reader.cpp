#include "netlists/spice_reader.h"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <deque>
#include <filesystem>
#include <memory>
#include <numbers>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "base/file_io.h"
#include "base/si_number.h"
#include "netlists/expression.h"
#include "netlists/lexer.h"
#include "solver/elements/element.h"

namespace isolink {
namespace {

namespace fs = std::filesystem;

// .include chains and subcircuit instances nest at most this deep (a 10,000-deep chain would
// otherwise overflow the stack).
constexpr size_t kMaxIncludeDepth = 64;
constexpr size_t kMaxSubcktDepth = 64;
using spice::LogicalLine;
using spice::lower;
using spice::Token;
using spice::TokenKind;

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
bool is_ident_start(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool is_ident_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}
bool is_identifier(std::string_view s) {
  if (s.empty() || !is_ident_start(s[0])) return false;
  for (char c : s)
    if (!is_ident_char(c)) return false;
  return true;
}

std::string trim(std::string_view s) {
  std::size_t a = 0, b = s.size();
  while (a < b && is_blank(s[a])) ++a;
  while (b > a && is_blank(s[b - 1])) --b;
  return std::string(s.substr(a, b - a));
}

std::string describe(const Token& t) {
  if (t.kind == TokenKind::Expr) return "{" + std::string(t.text) + "}";
  return std::string(t.text);
}

// A logical line with its tokens; lives in a deque so the token views stay valid.
struct Line {
  LogicalLine ll;
  std::vector<Token> toks;

  SourceLoc at(std::size_t k) const { return ll.loc(toks[k].offset); }
  // Just past the last token (where a missing token was expected).
  SourceLoc end() const { return ll.loc(toks.empty() ? 0 : toks.back().end()); }
  SourceLoc at_or_end(std::size_t k) const { return k < toks.size() ? at(k) : end(); }
  bool word(std::size_t k) const { return k < toks.size() && toks[k].kind == TokenKind::Word; }
  bool kind(std::size_t k, TokenKind kd) const { return k < toks.size() && toks[k].kind == kd; }
  // key=value starts at k
  bool assignment(std::size_t k) const { return word(k) && kind(k + 1, TokenKind::Equals); }
  std::string key() const { return toks.empty() ? std::string() : lower(toks[0].text); }
};

struct SubcktDef {
  std::string name;
  SourceLoc loc;       // the name token
  SourceLoc card_loc;  // the .subckt keyword
  const Line* header = nullptr;
  std::vector<std::string> ports;
  std::vector<std::pair<std::string, std::size_t>> params;  // key, value token index in header
  std::vector<const Line*> body;
};

struct Scope {
  std::unordered_map<std::string, double> values;
  std::unordered_map<std::string, spice::UserFunction> funcs;  // .func
  // .model cards (a subcircuit's are local to it, as in ngspice)
  std::unordered_map<std::string, std::shared_ptr<const CardModel>> models;
  const Scope* parent = nullptr;
  std::shared_ptr<const CardModel> find_model(const std::string& name) const {
    for (const Scope* s = this; s; s = s->parent) {
      auto it = s->models.find(name);
      if (it != s->models.end()) return it->second;
    }
    return nullptr;
  }
  std::optional<double> find(const std::string& name) const {
    for (const Scope* s = this; s; s = s->parent) {
      auto it = s->values.find(name);
      if (it != s->values.end()) return it->second;
    }
    return std::nullopt;
  }
  const spice::UserFunction* find_func(const std::string& name) const {
    for (const Scope* s = this; s; s = s->parent) {
      auto it = s->funcs.find(name);
      if (it != s->funcs.end()) return &it->second;
    }
    return nullptr;
  }
};

// Expression text evaluated in a scope (its parameters and .func functions).
// condition: a .if / .elseif condition, where a single '=' is equality (as in ngspice).
StatusOr<double> eval_in(const Scope& scope, std::string_view text, const spice::OffsetLoc& where,
                         bool condition = false) {
  return spice::evaluate_expression(
      text, [&](const std::string& name) { return scope.find(name); }, where,
      [&](const std::string& name) { return scope.find_func(name); }, condition);
}

// Element letters isolink refuses, with the feature's name and what to do instead.
struct RefusedLetter {
  char letter;
  const char* feature;
  const char* hint;
};
constexpr const char* kSemiconductor =
    "isolink simulates passive links with diodes; model an isolator or transceiver pin by its "
    "R/C/L network and clamp diodes, as the part library does";
constexpr const char* kLine =
    "for the cable, write a link spec: its 'cable:' key (length, material, gauge) builds the "
    "RLGC ladder; see the README section on link specs";
constexpr RefusedLetter kRefusedLetters[] = {
    {'a', "XSPICE code model ('a' device)", "isolink has no XSPICE code models"},
    {'b', "behavioural source (B)",
     "write the waveform as PULSE, PWL, SIN or EXP on a V or I source"},
    {'e', "voltage-controlled voltage source (E)", "controlled sources are out of scope"},
    {'f', "current-controlled current source (F)", "controlled sources are out of scope"},
    {'h', "current-controlled voltage source (H)", "controlled sources are out of scope"},
    {'j', "JFET (J)", kSemiconductor},
    {'m', "MOSFET (M)", kSemiconductor},
    {'n', "OSDI / Verilog-A device (N)", kSemiconductor},
    {'o', "lossy transmission line (O)", kLine},
    {'p', "coupled multiconductor line (P)", kLine},
    {'q', "bipolar transistor (Q)", kSemiconductor},
    {'t', "transmission line (T)", kLine},
    {'u', "uniform RC line (U)", kLine},
    {'w', "current-controlled switch (W)", "use a voltage-controlled switch (S)"},
    {'y', "transmission line (Y, TXL)", kLine},
    {'z', "MESFET (Z)", kSemiconductor},
};

// Dot cards skipped with one warning: they ask for output or analyses isolink does not run, and
// leave the transient of a linear circuit unchanged. Any other unknown dot card is an error.
constexpr const char* kIgnoredCards[] = {
    ".print", ".plot", ".save",  ".probe",   ".meas",     ".measure", ".op",
    ".ac",    ".dc",   ".noise", ".four",    ".width",    ".disto",   ".sens",
    ".pz",    ".tf",   ".title", ".csparam", ".backanno", ".nodeset",
};

// .model parameters that only document a part (PSpice's data-sheet fields in vendor models):
// dropped with a warning, as they change nothing in a simulation.
constexpr const char* kDocumentationModelKeys[] = {"iave", "vpk", "mfg", "type"};

// Source functions that may be written without parentheses: "SIN 0 1 1K".
bool is_source_function(const std::string& w) {
  return w == "pulse" || w == "sin" || w == "pwl" || w == "exp" || w == "sffm" || w == "am" ||
         w == "trnoise" || w == "trrandom";
}

struct Ctx {
  std::string prefix;                                                   // "" or "x1.x2."
  const std::unordered_map<std::string, std::string>* ports = nullptr;  // port -> outer node
  Scope* scope = nullptr;
  std::vector<const SubcktDef*> stack;
};

std::string canonical_key(const std::string& path) {
  std::error_code ec;
  fs::path c = fs::weakly_canonical(fs::path(path), ec);
  return ec ? fs::path(path).lexically_normal().string() : c.string();
}

class Reader {
 public:
  Status read(const std::shared_ptr<const SourceFile>& top) {
    Status s = read_all(top);
    if (s.ok() || out_.warnings.empty()) return s;
    // Warnings first: a card skipped with a warning may be why the error happened.
    std::string text;
    for (const std::string& w : out_.warnings) text += w + "\n";
    return Status::Error(text + s.message());
  }
  Netlist take() { return std::move(out_); }

 private:
  Status read_all(const std::shared_ptr<const SourceFile>& top) {
    if (!top->lines.empty()) out_.title = trim(top->lines[0]);
    if (top->path != "<string>") include_stack_.push_back(canonical_key(top->path));
    for (const std::string& l : top->lines) total_bytes_ += l.size() + 1;
    if (Status s = collect(top, 2, nullptr); !s.ok()) return s;
    if (!open_.empty())
      return error_at(open_.back()->card_loc,
                      "missing '.ends' for subcircuit '" + open_.back()->name + "'");
    Ctx ctx;
    ctx.scope = &globals_;
    if (Status s = elaborate(top_, ctx); !s.ok()) return s;
    return apply_temperature();
  }

  // ---- pass 1: lines, includes, libraries, subcircuit bodies ----
  // `section`: read only the lines inside `.lib SECTION` ... `.endl` (a call `.lib FILE
  // SECTION`); otherwise the lines inside `.lib NAME` ... `.endl` blocks are skipped.
  Status collect(const std::shared_ptr<const SourceFile>& file, int first_line,
                 const std::string* section) {
    auto lines = spice::join_lines(file, first_line);
    if (!lines) return lines.status();
    std::optional<std::string> block;  // the .lib NAME block we are in
    SourceLoc block_loc;
    bool found_section = false;
    for (LogicalLine& ll : *lines) {
      // A NUL byte would end up inside a node or element name (a binary file, a bad editor).
      if (const size_t nul = ll.text.find('\0'); nul != std::string::npos)
        return error_at(ll.loc(nul), "a NUL byte in the netlist (is this a text file?)");
      std::size_t a = 0;
      while (a < ll.text.size() && is_blank(ll.text[a])) ++a;
      std::size_t b = a;
      while (b < ll.text.size() && !is_blank(ll.text[b])) ++b;
      const std::string key = lower(std::string_view(ll.text).substr(a, b - a));
      if (in_control_) {
        if (key == ".endc") in_control_ = false;
        continue;
      }
      if (key == ".endl") {
        if (!block) return error_at(ll.loc(a), "'.endl' without '.lib SECTION' before it");
        block.reset();
        continue;
      }
      if (key == ".lib") {
        const auto words = spice_words(ll, b);
        if (words.size() == 1) {  // a section definition starts
          if (block)
            return error_at(ll.loc(a), "'.lib " + words[0].first + "' inside section '" + *block +
                                           "' (missing '.endl')");
          block = lower(words[0].first);
          block_loc = ll.loc(a);
          found_section = found_section || (section && *block == *section);
          continue;
        }
        if (!(section ? (block && *block == *section) : !block)) continue;
        if (words.size() != 2)
          return error_at(ll.loc(a), "expected '.lib FILE SECTION', or '.lib SECTION' ... '.endl'");
        const std::string wanted = lower(words[1].first);
        if (Status s = include(ll, words[0], &wanted); !s.ok()) return s;
        continue;
      }
      if (section ? !(block && *block == *section) : block.has_value()) continue;
      if (key == ".control") {
        warn_once(".control", ll.loc(a), "'.control' ... '.endc' block ignored");
        in_control_ = true;
        continue;
      }
      if (key == ".end") break;
      if (key == ".include" || key == ".inc") {
        const auto words = spice_words(ll, b);
        if (words.empty()) return error_at(ll.loc(b), "expected a file name after .include");
        if (Status s = include(ll, words[0], nullptr); !s.ok()) return s;
        continue;
      }
      Line& line = lines_.emplace_back();
      line.ll = std::move(ll);
      auto toks = spice::tokenize(line.ll);
      if (!toks) return toks.status();
      line.toks = std::move(*toks);
      if (key == ".subckt") {
        if (Status s = define_subckt(line); !s.ok()) return s;
      } else if (key == ".ends") {
        if (open_.empty()) return error_at(line.at(0), "'.ends' without '.subckt'");
        open_.pop_back();
      } else if (key == ".global") {
        for (std::size_t k = 1; k < line.toks.size(); ++k) {
          if (!line.word(k))
            return error_at(line.at(k), "expected node names after .global, got '" +
                                            describe(line.toks[k]) + "'");
          global_nodes_.insert(lower(line.toks[k].text));
        }
      } else {
        (open_.empty() ? top_ : open_.back()->body).push_back(&line);
      }
    }
    if (block && !section) return error_at(block_loc, "missing '.endl' for '.lib " + *block + "'");
    if (section && !found_section)
      return error_at(section_call_loc_,
                      "library '" + file->path + "' has no section '" + *section + "'");
    return Status::Ok();
  }

  // The blank-separated words after offset `from` ("..." and '...' quote a word), with offsets.
  static std::vector<std::pair<std::string, std::size_t>> spice_words(const LogicalLine& ll,
                                                                      std::size_t from) {
    std::vector<std::pair<std::string, std::size_t>> out;
    std::size_t a = from;
    const std::string& t = ll.text;
    while (true) {
      while (a < t.size() && is_blank(t[a])) ++a;
      if (a >= t.size()) break;
      if (t[a] == '"' || t[a] == '\'') {
        const std::size_t e = t.find(t[a], a + 1);
        const std::size_t end = e == std::string::npos ? t.size() : e;
        out.emplace_back(t.substr(a + 1, end - a - 1), a);
        a = e == std::string::npos ? t.size() : e + 1;
      } else {
        std::size_t e = a;
        while (e < t.size() && !is_blank(t[e])) ++e;
        out.emplace_back(t.substr(a, e - a), a);
        a = e;
      }
    }
    return out;
  }

  // .include FILE, or .lib FILE SECTION (section != nullptr).
  Status include(const LogicalLine& ll, const std::pair<std::string, std::size_t>& word,
                 const std::string* section) {
    const std::string& name = word.first;
    const SourceLoc where = ll.loc(word.second);
    if (word.second < ll.text.size() &&
        (ll.text[word.second] == '"' || ll.text[word.second] == '\'') &&
        ll.text.find(ll.text[word.second], word.second + 1) == std::string::npos)
      return error_at(
          where, std::string("unterminated file name: missing closing ") + ll.text[word.second]);
    fs::path p(name);
    if (p.is_relative()) {
      const std::string& from = ll.file->path;
      const fs::path base =
          from.empty() || from[0] == '<' ? fs::path() : fs::path(from).parent_path();
      p = (base / p).lexically_normal();
    }
    const std::string key = canonical_key(p.string()) + (section ? "#" + *section : "");
    for (std::size_t k = 0; k < include_stack_.size(); ++k) {
      if (include_stack_[k] != key) continue;
      return error_at(where, "recursive include of '" + p.string() + "'");
    }
    if (include_stack_.size() >= kMaxIncludeDepth)
      return error_at(
          where, fmt::format("includes nest deeper than the limit of {} files", kMaxIncludeDepth));
    // The error_code forms: a name past NAME_MAX or PATH_MAX gets its reason below, not an
    // exception (found by tests/fuzz).
    std::error_code ec;
    if (fs::is_directory(p, ec))
      return error_at(where, std::string(section ? "library file '" : "include file '") + name +
                                 "' is a folder ('" + p.string() + "')");
    auto text = read_input_file(p.string());
    if (!text) {
      if (!fs::exists(p, ec) && !ec)  // with ec set (a name too long), the reader's reason
        return error_at(where, std::string(section ? "cannot open library file '"
                                                   : "cannot open include file '") +
                                   name + "' (looked for '" + p.string() + "')");
      const std::string& m = text.status().message();  // "PATH: error: REASON"
      const size_t at = m.find(": error: ");
      return error_at(where, std::string(section ? "library file '" : "include file '") + name +
                                 "': " + (at == std::string::npos ? m : m.substr(at + 9)));
    }
    total_bytes_ += text->size();
    if (total_bytes_ > kMaxInputFileBytes)
      return error_at(where,
                      fmt::format("include file '{}' takes the netlist and its includes past "
                                  "the {} MiB limit",
                                  name, kMaxInputFileBytes >> 20));
    auto file = SourceFile::FromText(p.string(), *text, std::make_shared<const SourceLoc>(where));
    include_stack_.push_back(key);
    const SourceLoc saved = section_call_loc_;
    section_call_loc_ = where;
    Status s = collect(file, 1, section);
    section_call_loc_ = saved;
    include_stack_.pop_back();
    return s;
  }

  Status define_subckt(const Line& line) {
    if (!line.word(1))
      return error_at(line.at_or_end(1), "expected a subcircuit name after .subckt");
    auto def = std::make_unique<SubcktDef>();
    def->name = lower(line.toks[1].text);
    def->loc = line.at(1);
    def->card_loc = line.at(0);
    def->header = &line;
    std::size_t i = 2;
    const std::size_t n = line.toks.size();
    for (; i < n; ++i) {
      if (line.assignment(i)) break;
      if (!line.word(i))
        return error_at(line.at(i), "unexpected '" + describe(line.toks[i]) + "' in .subckt ports");
      const std::string w = lower(line.toks[i].text);
      if (w == "params:") {
        ++i;
        break;
      }
      def->ports.push_back(w);
    }
    for (; i < n; i += 3) {
      if (!line.assignment(i))
        return error_at(line.at(i), "expected NAME=VALUE in .subckt parameters, got '" +
                                        describe(line.toks[i]) + "'");
      if (i + 2 >= n ||
          (line.toks[i + 2].kind != TokenKind::Word && line.toks[i + 2].kind != TokenKind::Expr))
        return error_at(line.at_or_end(i + 2), "missing value for subcircuit parameter '" +
                                                   lower(line.toks[i].text) + "'");
      def->params.emplace_back(lower(line.toks[i].text), i + 2);
    }
    if (subckts_.count(def->name))
      return error_at(def->loc, "subcircuit '" + def->name + "' defined twice (first at " +
                                    subckts_[def->name]->loc.str() + ")");
    open_.push_back(def.get());
    subckts_[def->name] = std::move(def);
    return Status::Ok();
  }

  // ---- values ----
  StatusOr<double> number(const Line& line, const Token& t, const Scope& scope) {
    if (t.kind == TokenKind::Expr) {
      const std::size_t base = t.offset + 1;
      return eval_in(scope, t.text, [&](std::size_t o) { return line.ll.loc(base + o); });
    }
    if (t.kind != TokenKind::Word)
      return error_at(line.ll.loc(t.offset), "expected a number, got '" + describe(t) + "'");
    double v = 0;
    if (parse_si_number(t.text, v)) return v;
    std::string_view body = t.text;
    if (!body.empty() && (body[0] == '+' || body[0] == '-')) body.remove_prefix(1);
    if (body.empty() || std::isdigit(static_cast<unsigned char>(body[0])) || body[0] == '.')
      return error_at(line.ll.loc(t.offset), "malformed number '" + std::string(t.text) + "'");
    if (is_identifier(t.text)) {
      const std::string name = lower(t.text);
      if (auto p = scope.find(name)) return *p;
      if (name == "pi") return std::numbers::pi;
      return error_at(line.ll.loc(t.offset), "expected a number, got '" + std::string(t.text) +
                                                 "' (no parameter of that name is defined)");
    }
    return eval_in(scope, t.text, [&](std::size_t o) { return line.ll.loc(t.offset + o); });
  }

  // NAME ( values... ) starting at toks[i] (NAME), toks[i+1] == '('. Advances i past ')'.
  StatusOr<CardArg> call(const Line& line, std::size_t& i, const Scope& scope) {
    CardArg arg;
    arg.kind = CardArg::Kind::Call;
    arg.word = lower(line.toks[i].text);
    arg.loc = line.at(i);
    std::size_t j = i + 2;
    const std::size_t n = line.toks.size();
    for (; j < n; ++j) {
      const Token& t = line.toks[j];
      if (t.kind == TokenKind::RParen) break;
      if (t.kind == TokenKind::Comma) continue;
      if (t.kind == TokenKind::LParen || t.kind == TokenKind::Equals)
        return error_at(line.at(j), "unexpected '" + describe(t) + "' inside " + arg.word +
                                        "(...); write expressions in {braces}");
      if (t.kind == TokenKind::Word && line.kind(j + 1, TokenKind::LParen))
        return error_at(line.at(j), "unexpected call '" + std::string(t.text) + "(' inside " +
                                        arg.word + "(...); write expressions in {braces}");
      auto v = number(line, t, scope);
      if (!v) return v.status();
      arg.call.push_back(*v);
    }
    i = j + 1;  // the tokenizer guarantees the ')'
    return arg;
  }

  // One value token (or NAME(...)) at toks[i]; advances i.
  StatusOr<CardArg> value(const Line& line, std::size_t& i, const Scope& scope, bool allow_word) {
    const Token& t = line.toks[i];
    if (t.kind == TokenKind::Word && line.kind(i + 1, TokenKind::LParen))
      return call(line, i, scope);
    CardArg arg;
    arg.loc = line.at(i);
    if (allow_word && t.kind == TokenKind::Word && is_identifier(t.text)) {
      const std::string w = lower(t.text);
      if (!scope.find(w) && w != "pi") {
        arg.kind = CardArg::Kind::Word;
        arg.word = w;
        ++i;
        return arg;
      }
    }
    auto v = number(line, t, scope);
    if (!v) return v.status();
    arg.number = *v;
    ++i;
    return arg;
  }

  // ---- pass 2: parameters, elements, instances, analysis cards ----
  Status elaborate(const std::vector<const Line*>& body, Ctx& ctx) {
    auto active = prepare(body, *ctx.scope);
    if (!active) return active.status();
    for (const Line* l : *active) {
      const std::string key = l->key();
      if (key.empty()) continue;
      if (!l->word(0))
        return error_at(
            l->at(0), "expected an element name or a dot card, got '" + describe(l->toks[0]) + "'");
      Status s = Status::Ok();
      if (key[0] == '.')
        s = dot_card(*l, key, ctx);
      else if (key[0] == 'x')
        s = instance(*l, ctx);
      else
        s = element(*l, ctx);
      if (!s.ok()) return s;
    }
    return Status::Ok();
  }

  // The lines of `body` that .if/.elseif/.else/.endif leave active, without the .param and
  // .func cards, which are applied to `scope` in file order (all before any element is built,
  // so an element may use a parameter defined below it). Conditions see the parameters
  // defined above them.
  StatusOr<std::vector<const Line*>> prepare(const std::vector<const Line*>& body, Scope& scope) {
    struct Cond {
      bool parent_active, taken, active, seen_else;
      SourceLoc loc;
    };
    std::vector<Cond> stack;
    std::vector<const Line*> out;
    std::vector<const Line*> models;  // read once the body's .param cards are all applied
    auto condition = [&](const Line& l) -> StatusOr<bool> {
      if (l.toks.size() < 2) return error_at(l.end(), "expected a condition after " + l.key());
      const std::size_t from = l.toks[1].offset;
      auto v = eval_in(
          scope, std::string_view(l.ll.text).substr(from),
          [&](std::size_t o) { return l.ll.loc(from + o); }, true);
      if (!v) return v.status();
      return *v != 0.0;
    };
    for (const Line* l : body) {
      const std::string key = l->key();
      const bool active = stack.empty() || stack.back().active;
      if (key == ".if") {
        bool c = false;
        if (active) {
          auto v = condition(*l);
          if (!v) return v.status();
          c = *v;
        }
        stack.push_back({active, c, active && c, false, l->at(0)});
        continue;
      }
      if (key == ".elseif" || key == ".else" || key == ".endif") {
        if (stack.empty()) return error_at(l->at(0), "'" + key + "' without '.if' before it");
        Cond& c = stack.back();
        if (key == ".endif") {
          stack.pop_back();
          continue;
        }
        if (c.seen_else) return error_at(l->at(0), "'" + key + "' after '.else'");
        if (key == ".else") {
          c.active = c.parent_active && !c.taken;
          c.taken = c.seen_else = true;
          continue;
        }
        c.active = false;
        if (c.parent_active && !c.taken) {
          auto v = condition(*l);
          if (!v) return v.status();
          c.active = c.taken = *v;
        }
        continue;
      }
      if (!active) continue;
      if (key == ".param") {
        if (Status s = param_card(*l, scope); !s.ok()) return s;
      } else if (key == ".func") {
        if (Status s = func_card(*l, scope); !s.ok()) return s;
      } else if (key == ".model") {
        models.push_back(l);
      } else {
        out.push_back(l);
      }
    }
    if (!stack.empty()) return error_at(stack.back().loc, "missing '.endif' for this '.if'");
    for (const Line* l : models)
      if (Status s = model_card(*l, scope); !s.ok()) return s;
    return out;
  }

  // .model NAME TYPE(KEY=VALUE ...), the parentheses optional, commas allowed. A type no element
  // kind takes (NPN, NMOS, ...) is kept out with a warning: no card can name it (their letters
  // are refused).
  Status model_card(const Line& line, Scope& scope) {
    if (!line.word(1) || !line.word(2) || line.kind(2, TokenKind::Equals))
      return error_at(line.at_or_end(1), "expected .model NAME TYPE(KEY=VALUE ...)");
    auto model = std::make_shared<CardModel>();
    model->name = lower(line.toks[1].text);
    model->type = lower(line.toks[2].text);
    model->loc = line.at(1);
    if (scope.models.count(model->name))
      return error_at(line.at(1), "model '" + model->name + "' defined twice (first at " +
                                      scope.models[model->name]->loc.str() + ")");
    bool known_type = false;
    for (const ElementKind& k : element_kinds())
      known_type = known_type || (k.model_type && model->type == k.model_type);
    if (!known_type) {  // kept (for the duplicate check and a clear error), parameters unread
      warn_once(".model " + model->type, line.at(2),
                "model type '" + model->type + "' ignored (isolink's models: d)");
      scope.models[model->name] = std::move(model);
      return Status::Ok();
    }
    std::size_t i = 3;
    const std::size_t n = line.toks.size();
    const bool paren = line.kind(i, TokenKind::LParen);
    if (paren) ++i;
    while (i < n && !line.kind(i, TokenKind::RParen)) {
      if (line.kind(i, TokenKind::Comma)) {
        ++i;
        continue;
      }
      if (!line.assignment(i))
        return error_at(line.at(i), "expected KEY=VALUE in .model " + model->name + ", got '" +
                                        describe(line.toks[i]) + "'");
      const std::string key = lower(line.toks[i].text);
      const SourceLoc key_loc = line.at(i);
      i += 2;
      if (i >= n || (line.toks[i].kind != TokenKind::Word && line.toks[i].kind != TokenKind::Expr))
        return error_at(line.at_or_end(i), "missing value for '" + key + "'");
      const bool documentation =
          std::find(std::begin(kDocumentationModelKeys), std::end(kDocumentationModelKeys), key) !=
          std::end(kDocumentationModelKeys);
      auto v = value(line, i, scope, documentation);
      if (!v) return v.status();
      if (documentation) {
        warn_once(".model doc", key_loc,
                  "'" + key + "' in .model " + model->name +
                      " ignored (it documents the part and changes nothing in a simulation)");
        continue;
      }
      v->loc = key_loc;
      model->params.emplace_back(key, std::move(*v));
    }
    if (paren && i >= n) return error_at(line.end(), "missing ')' in .model " + model->name);
    if (i + 1 < n)
      return error_at(line.at(i + 1), "unexpected '" + describe(line.toks[i + 1]) +
                                          "' after .model " + model->name + "(...)");
    scope.models[model->name] = std::move(model);
    return Status::Ok();
  }

  // .func NAME(a, b) {body}  (also with '=' before the body, or an unbraced body)
  Status func_card(const Line& line, Scope& scope) {
    const std::size_t n = line.toks.size();
    if (!line.word(1) || !is_identifier(line.toks[1].text) || !line.kind(2, TokenKind::LParen))
      return error_at(line.at_or_end(1), "expected .func NAME(ARG, ...) {EXPRESSION}");
    const std::string name = lower(line.toks[1].text);
    spice::UserFunction f;
    std::size_t i = 3;
    for (; i < n && !line.kind(i, TokenKind::RParen); ++i) {
      if (line.kind(i, TokenKind::Comma)) continue;
      if (!line.word(i) || !is_identifier(line.toks[i].text))
        return error_at(line.at(i), "expected an argument name in .func " + name + "(...), got '" +
                                        describe(line.toks[i]) + "'");
      f.params.push_back(lower(line.toks[i].text));
    }
    ++i;  // ')'
    if (line.kind(i, TokenKind::Equals)) ++i;
    if (i >= n) return error_at(line.end(), "missing body of .func " + name);
    std::size_t from = line.toks[i].offset, to = line.toks[n - 1].end();
    if (i + 1 == n && line.toks[i].kind == TokenKind::Expr) ++from, --to;
    f.body = line.ll.text.substr(from, to - from);
    const Line* lp = &line;
    f.where = [lp, from](std::size_t o) { return lp->ll.loc(from + o); };
    scope.funcs[name] = std::move(f);
    return Status::Ok();
  }

  Status param_card(const Line& line, Scope& scope) {
    const std::size_t n = line.toks.size();
    if (n == 1) return error_at(line.end(), "expected NAME=VALUE after .param");
    std::size_t i = 1;
    while (i < n) {
      if (!line.assignment(i))
        return error_at(line.at(i),
                        "expected NAME=VALUE in .param, got '" + describe(line.toks[i]) + "'");
      const std::string name = lower(line.toks[i].text);
      if (!is_identifier(name))
        return error_at(line.at(i), "invalid parameter name '" + name + "'");
      std::size_t j = i + 2;
      while (j < n && !line.assignment(j)) ++j;
      if (j == i + 2)
        return error_at(line.at_or_end(i + 2), "missing value for parameter '" + name + "'");
      StatusOr<double> v = 0.0;
      if (j == i + 3) {
        v = number(line, line.toks[i + 2], scope);
      } else {  // an unbraced expression spread over several tokens: "a = 2 * b"
        const std::size_t from = line.toks[i + 2].offset, to = line.toks[j - 1].end();
        v = eval_in(scope, std::string_view(line.ll.text).substr(from, to - from),
                    [&](std::size_t o) { return line.ll.loc(from + o); });
      }
      if (!v) return v.status();
      scope.values[name] = *v;
      i = j;
    }
    return Status::Ok();
  }

  std::string node(std::string_view text, const Ctx& ctx) const {
    std::string n = lower(text);
    if (n == "0" || n == "gnd") return "0";
    if (ctx.ports) {
      auto it = ctx.ports->find(n);
      if (it != ctx.ports->end()) return it->second;
    }
    if (global_nodes_.count(n)) return n;  // .global: the same node in every subcircuit
    return ctx.prefix + n;
  }

  Status claim_name(const std::string& name, const SourceLoc& loc) {
    auto [it, fresh] = names_.emplace(name, loc);
    if (!fresh)
      return error_at(
          loc, "duplicate element name '" + name + "' (first defined at " + it->second.str() + ")");
    return Status::Ok();
  }

  // The element kind of the card's first letter; an error for refused and unknown letters.
  StatusOr<const ElementKind*> element_kind(const Line& line, const std::string& local) {
    const char letter = local[0];
    for (const RefusedLetter& r : kRefusedLetters)
      if (r.letter == letter)
        return error_at(line.at(0), std::string(r.feature) + " is not supported ('" + local +
                                        "'; " + r.hint + ")");
    const ElementKind* kind = find_element_kind(letter);
    if (!kind) {
      std::string known;
      for (const ElementKind& k : element_kinds()) known += std::string(1, k.letter) + " ";
      return error_at(line.at(0), "unknown element letter '" + std::string(1, letter) + "' in '" +
                                      local + "' (known: " + known + "x)");
    }
    return kind;
  }

  // The kind's nodes and element names (K's inductors) from token *i on.
  Status read_nodes_and_refs(const Line& line, const Ctx& ctx, const ElementKind& kind,
                             const std::string& local, Card& card, std::size_t* i) {
    auto plain_word = [&](std::size_t k) {
      return line.word(k) && !line.kind(k + 1, TokenKind::Equals) &&
             !line.kind(k + 1, TokenKind::LParen);
    };
    for (int k = 0; k < kind.node_count; ++k, ++*i) {
      if (!plain_word(*i))
        return error_at(line.at_or_end(*i),
                        "too few nodes: " + std::string(kind.name) + " '" + local + "' needs " +
                            std::to_string(kind.node_count) + " nodes (usage: " + kind.usage + ")");
      card.nodes.push_back(node(line.toks[*i].text, ctx));
      card.node_locs.push_back(line.at(*i));
    }
    for (int k = 0; k < kind.ref_count; ++k, ++*i) {
      if (!plain_word(*i))
        return error_at(line.at_or_end(*i), "too few element names: " + std::string(kind.name) +
                                                " '" + local + "' needs " +
                                                std::to_string(kind.ref_count) +
                                                " (usage: " + kind.usage + ")");
      card.refs.push_back(ctx.prefix + unflatten_name(lower(line.toks[*i].text)));
      card.ref_locs.push_back(line.at(*i));
    }
    return Status::Ok();
  }

  // The .model a card of a kind with models names at token *i (D1 a k MODEL ...).
  Status read_model_name(const Line& line, const Ctx& ctx, const ElementKind& kind,
                         const std::string& local, Card& card, std::size_t* i) {
    if (!line.word(*i) || line.kind(*i + 1, TokenKind::Equals))
      return error_at(line.at_or_end(*i), "expected a model name after the nodes of " +
                                              std::string(kind.name) + " '" + local +
                                              "' (usage: " + kind.usage + ")");
    const std::string name = lower(line.toks[*i].text);
    std::shared_ptr<const CardModel> model = ctx.scope->find_model(name);
    if (!model)
      return error_at(line.at(*i), "unknown model '" + name + "' (no .model " + name +
                                       " in this netlist or subcircuit)");
    if (model->type != kind.model_type)
      return error_at(line.at(*i), "model '" + name + "' is a '" + model->type + "' model; " +
                                       kind.name + " '" + local + "' needs a '" + kind.model_type +
                                       "' model");
    card.model = std::move(model);
    card.model_loc = line.at(*i);
    ++*i;
    return Status::Ok();
  }

  // A source function without parentheses ("SIN 0 1 1K") from token *i: its numbers up to the
  // next word that is not one.
  Status read_bare_source_call(const Line& line, const Ctx& ctx, const std::string& w, Card& card,
                               std::size_t* i) {
    const std::size_t n = line.toks.size();
    CardArg a;
    a.kind = CardArg::Kind::Call;
    a.word = w;
    a.loc = line.at((*i)++);
    while (*i < n && !line.assignment(*i) &&
           (line.kind(*i, TokenKind::Expr) ||
            (line.word(*i) && !line.kind(*i + 1, TokenKind::LParen) &&
             !is_source_function(lower(line.toks[*i].text)) && lower(line.toks[*i].text) != "dc" &&
             lower(line.toks[*i].text) != "ac"))) {
      auto v = number(line, line.toks[*i], *ctx.scope);
      if (!v) return v.status();
      a.call.push_back(*v);
      ++*i;
    }
    card.args.push_back(std::move(a));
    return Status::Ok();
  }

  // The positional values from token *i up to the key=value parameters. V and I: dc=, ac=
  // (acmag=, acphase=) may stand among them, as in "V1 a 0 dc = 2 AC 1"; dc= reads as DC, the
  // ac ones are dropped as AC is.
  Status read_positional(const Line& line, const Ctx& ctx, Card& card, std::size_t* i) {
    const std::size_t n = line.toks.size();
    const char letter = card.letter;
    auto source_key = [&](std::size_t k) {
      if ((letter != 'v' && letter != 'i') || !line.assignment(k)) return std::string();
      const std::string w = lower(line.toks[k].text);
      return w == "dc" || w == "ac" || w == "acmag" || w == "acphase" ? w : std::string();
    };
    while (*i < n && (!line.assignment(*i) || !source_key(*i).empty())) {
      if (const std::string key = source_key(*i); !key.empty()) {
        if (*i + 2 >= n) return error_at(line.at_or_end(*i + 2), "missing value for '" + key + "'");
        if (key == "dc") {
          CardArg a;
          a.kind = CardArg::Kind::Word;
          a.word = key;
          a.loc = line.at(*i);
          card.args.push_back(std::move(a));
          *i += 2;
          auto v = value(line, *i, *ctx.scope, false);
          if (!v) return v.status();
          card.args.push_back(std::move(*v));
        } else {
          warn_once("ac", line.at(*i),
                    "AC specification ignored (isolink runs transient analyses)");
          *i += 3;
        }
        continue;
      }
      const Token& t = line.toks[*i];
      if (t.kind != TokenKind::Word && t.kind != TokenKind::Expr)
        return error_at(line.at(*i), "unexpected '" + describe(t) + "'");
      if (t.kind == TokenKind::Word && !line.kind(*i + 1, TokenKind::LParen)) {
        const std::string w = lower(t.text);
        if (is_source_function(w) && !ctx.scope->find(w)) {  // "SIN 0 1 1K": no parentheses
          if (Status s = read_bare_source_call(line, ctx, w, card, i); !s.ok()) return s;
          continue;
        }
        if (w == "dc" || (w == "off" && card.model)) {  // DC, or a diode's OFF
          CardArg a;
          a.kind = CardArg::Kind::Word;
          a.word = w;
          a.loc = line.at((*i)++);
          card.args.push_back(std::move(a));
          continue;
        }
        if (w == "ac") {
          warn_once("ac", line.at(*i),
                    "AC specification ignored (isolink runs transient analyses)");
          ++*i;
          for (int k = 0; k < 2 && *i < n && !line.assignment(*i) &&
                          (line.kind(*i, TokenKind::Expr) ||
                           (line.word(*i) && !line.kind(*i + 1, TokenKind::LParen) &&
                            number(line, line.toks[*i], *ctx.scope)));
               ++k)
            ++*i;
          continue;
        }
      }
      auto a = value(line, *i, *ctx.scope, false);
      if (!a) return a.status();
      card.args.push_back(std::move(*a));
    }
    return Status::Ok();
  }

  Status element(const Line& line, const Ctx& ctx) {
    if (!line.word(0))
      return error_at(line.at(0), "expected an element name, got '" + describe(line.toks[0]) + "'");
    std::string local = lower(line.toks[0].text);
    StatusOr<const ElementKind*> kind = element_kind(line, local);
    if (!kind) return kind.status();
    const char letter = local[0];
    local = unflatten_name(local);
    Card card;
    card.letter = letter;
    card.name = ctx.prefix + local;
    card.loc = line.at(0);
    std::size_t i = 1;
    if (Status s = read_nodes_and_refs(line, ctx, **kind, local, card, &i); !s.ok()) return s;
    if ((*kind)->model_type)
      if (Status s = read_model_name(line, ctx, **kind, local, card, &i); !s.ok()) return s;
    if (Status s = read_positional(line, ctx, card, &i); !s.ok()) return s;
    if (Status s = key_values(line, i, *ctx.scope, card.params); !s.ok()) return s;
    if (Status s = claim_name(card.name, card.loc); !s.ok()) return s;
    out_.cards.push_back(std::move(card));
    return Status::Ok();
  }

  Status key_values(const Line& line, std::size_t i, const Scope& scope,
                    std::vector<std::pair<std::string, CardArg>>& out) {
    const std::size_t n = line.toks.size();
    while (i < n) {
      if (!line.assignment(i))
        return error_at(line.at(i),
                        "unexpected '" + describe(line.toks[i]) + "' after key=value parameters");
      const std::string key = lower(line.toks[i].text);
      i += 2;
      if (i >= n || (line.toks[i].kind != TokenKind::Word && line.toks[i].kind != TokenKind::Expr))
        return error_at(line.at_or_end(i), "missing value for '" + key + "'");
      auto a = value(line, i, scope, false);
      if (!a) return a.status();
      out.emplace_back(key, std::move(*a));
    }
    return Status::Ok();
  }

  Status instance(const Line& line, Ctx& ctx) {
    const std::string local = lower(line.toks[0].text);
    const std::string full = ctx.prefix + local;
    const std::size_t n = line.toks.size();
    std::size_t i = 1;
    std::vector<std::size_t> words;
    while (i < n && line.word(i) && !line.assignment(i) && lower(line.toks[i].text) != "params:")
      words.push_back(i++);
    if (i < n && !line.word(i))
      return error_at(line.at(i),
                      "unexpected '" + describe(line.toks[i]) + "' in instance '" + local + "'");
    if (words.empty())
      return error_at(line.at_or_end(1),
                      "expected nodes and a subcircuit name after '" + local + "'");
    const std::size_t name_tok = words.back();
    words.pop_back();
    const std::string sub = lower(line.toks[name_tok].text);
    auto it = subckts_.find(sub);
    if (it == subckts_.end())
      return error_at(line.at(name_tok), "unknown subcircuit '" + sub + "'");
    const SubcktDef* def = it->second.get();
    if (ctx.stack.size() >= kMaxSubcktDepth)
      return error_at(line.at(name_tok), fmt::format("subcircuits nest deeper than the limit of {} "
                                                     "levels",
                                                     kMaxSubcktDepth));
    for (const SubcktDef* d : ctx.stack) {
      if (d != def) continue;
      std::string chain;
      for (const SubcktDef* e : ctx.stack) chain += e->name + " -> ";
      return error_at(line.at(name_tok), "recursive subcircuit: " + chain + sub);
    }
    if (words.size() != def->ports.size()) {
      std::string ports;
      for (const auto& p : def->ports) ports += (ports.empty() ? "" : " ") + p;
      const std::string msg = "'" + local + "': subcircuit '" + sub + "' has " +
                              std::to_string(def->ports.size()) + " ports (" + ports + "), " +
                              std::to_string(words.size()) + " nodes given";
      return error_at(
          line.at(words.size() > def->ports.size() ? words[def->ports.size()] : name_tok), msg);
    }
    if (i < n && lower(line.toks[i].text) == "params:") ++i;
    std::vector<std::pair<std::string, CardArg>> overrides;
    const std::size_t first_override = i;
    if (Status s = key_values(line, i, *ctx.scope, overrides); !s.ok()) return s;
    for (std::size_t k = 0; k < overrides.size(); ++k) {
      if (overrides[k].second.kind != CardArg::Kind::Number)
        return error_at(overrides[k].second.loc,
                        "subcircuit parameter '" + overrides[k].first + "' needs a number");
      bool known = false;
      for (const auto& p : def->params) known = known || p.first == overrides[k].first;
      if (!known)
        return error_at(line.at(first_override + 3 * k),
                        "subcircuit '" + sub + "' has no parameter '" + overrides[k].first + "'");
    }
    if (Status s = claim_name(full, line.at(0)); !s.ok()) return s;

    Scope scope;
    scope.parent = ctx.scope;
    for (const auto& [key, tok] : def->params) {
      bool set = false;
      for (const auto& [k, v] : overrides)
        if (k == key) scope.values[key] = v.number, set = true;
      if (set) continue;
      auto v = number(*def->header, def->header->toks[tok], scope);
      if (!v) return v.status();
      scope.values[key] = *v;
    }
    std::unordered_map<std::string, std::string> ports;
    for (std::size_t k = 0; k < words.size(); ++k)
      ports[def->ports[k]] = node(line.toks[words[k]].text, ctx);
    Ctx inner;
    inner.prefix = full + ".";
    inner.ports = &ports;
    inner.scope = &scope;
    inner.stack = ctx.stack;
    inner.stack.push_back(def);
    Status s = elaborate(def->body, inner);
    if (!s.ok())
      return Status::Error(s.message() + "\n (in subcircuit instance '" + full + "' of '" + sub +
                           "' at " + line.at(0).str() + ")");
    return Status::Ok();
  }

  Status dot_card(const Line& line, const std::string& key, Ctx& ctx) {
    if (key == ".tran") return tran(line, *ctx.scope);
    if (key == ".options" || key == ".option" || key == ".opt" || key == ".opts")
      return options(line, *ctx.scope);
    if (key == ".temp") {
      if (line.toks.size() != 2) return error_at(line.at_or_end(1), "expected .temp DEGREES");
      auto v = number(line, line.toks[1], *ctx.scope);
      if (!v) return v.status();
      temp_ = *v;
      return Status::Ok();
    }
    if (key == ".ic") return initial_conditions(line, ctx);
    for (const char* c : kIgnoredCards) {
      if (key != c) continue;
      warn_once(key, line.at(0),
                key == ".nodeset"
                    ? "'.nodeset' ignored: a linear circuit has one DC operating point"
                    : "unsupported card '" + key + "' ignored");
      return Status::Ok();
    }
    return error_at(line.at(0), "'" + key +
                                    "' is not supported (it could change the answer, so "
                                    "isolink stops rather than skip it)");
  }

  // .ic v(n1)=1 v(n2)=0.5
  Status initial_conditions(const Line& line, const Ctx& ctx) {
    const std::size_t n = line.toks.size();
    if (n == 1) return error_at(line.end(), "expected v(NODE)=VALUE after .ic");
    for (std::size_t i = 1; i < n;) {
      if (!(line.word(i) && lower(line.toks[i].text) == "v" &&
            line.kind(i + 1, TokenKind::LParen) && line.word(i + 2) &&
            line.kind(i + 3, TokenKind::RParen) && line.kind(i + 4, TokenKind::Equals) &&
            i + 5 < n))
        return error_at(line.at(i),
                        "expected v(NODE)=VALUE in .ic, got '" + describe(line.toks[i]) + "'");
      auto v = number(line, line.toks[i + 5], *ctx.scope);
      if (!v) return v.status();
      out_.initial_voltages.push_back({node(line.toks[i + 2].text, ctx), *v, line.at(i)});
      i += 6;
    }
    return Status::Ok();
  }

  // .temp, .options temp= / tnom=: given to every resistor with a temperature coefficient and
  // every diode (as its temp= / tnom= unless the card sets them; a diode's model's TNOM wins
  // over the option's). The options are consumed here.
  Status apply_temperature() {
    std::optional<double> tnom;
    for (auto it = out_.options.begin(); it != out_.options.end();) {
      if (it->key != "temp" && it->key != "tnom") {
        ++it;
        continue;
      }
      if (it->value.kind != CardArg::Kind::Number)
        return error_at(it->value.loc, "option " + it->key + " expects degrees Celsius");
      (it->key == "temp" ? temp_ : tnom) = it->value.number;
      it = out_.options.erase(it);
    }
    for (Card& c : out_.cards) {
      const bool diode = c.letter == 'd';
      if (!diode && (c.letter != 'r' || (!c.param("tc1") && !c.param("tc2")))) continue;
      for (auto [key, value] : {std::pair{"temp", temp_}, std::pair{"tnom", tnom}}) {
        if (!value || c.param(key)) continue;
        CardArg a;
        a.number = *value;
        a.loc = c.loc;
        c.params.emplace_back(key, std::move(a));
      }
    }
    return Status::Ok();
  }

  Status tran(const Line& line, const Scope& scope) {
    TranSpec spec;
    spec.loc = line.at(0);
    std::vector<double> v;
    std::vector<std::size_t> at;  // the token of each value, for errors
    const std::size_t n = line.toks.size();
    for (std::size_t i = 1; i < n; ++i) {
      const Token& t = line.toks[i];
      if (t.kind == TokenKind::Word && lower(t.text) == "uic") {
        spec.uic = true;
        continue;
      }
      at.push_back(i);
      if (v.size() == 4)
        return error_at(line.at(i),
                        "too many values: expected .tran TSTEP TSTOP [TSTART [TMAX]] "
                        "[UIC]");
      auto x = number(line, t, scope);
      if (!x) return x.status();
      v.push_back(*x);
    }
    if (v.size() < 2)
      return error_at(line.end(), "expected .tran TSTEP TSTOP [TSTART [TMAX]] [UIC]");
    // Checked here, where the card's position is known (the solver's checks have none).
    const char* what[] = {"TSTEP", "TSTOP", "TSTART", "TMAX"};
    for (std::size_t k = 0; k < v.size(); ++k) {
      // TSTEP 0 (Xyce's habit): the engine picks its own print step (TSTOP / 1000).
      const bool ok = k == 2 ? (v[k] >= 0 && v[k] < v[1]) : k == 0 ? v[k] >= 0 : v[k] > 0;
      if (!ok || !std::isfinite(v[k]))
        return error_at(line.at(at[k]), fmt::format(".tran {} must be {}, got {:g}", what[k],
                                                    k == 2   ? "zero or positive and below TSTOP"
                                                    : k == 0 ? "zero or positive"
                                                             : "positive",
                                                    v[k]));
    }
    spec.tstep = v[0], spec.tstop = v[1];
    if (v.size() > 2) spec.tstart = v[2];
    if (v.size() > 3) spec.tmax = v[3];
    if (out_.tran)
      out_.warnings.push_back(format_diagnostic(
          spec.loc, "warning", "second .tran card replaces the one at " + out_.tran->loc.str()));
    out_.tran = spec;
    return Status::Ok();
  }

  Status options(const Line& line, const Scope& scope) {
    const std::size_t n = line.toks.size();
    std::size_t i = 1;
    while (i < n) {
      const Token& t = line.toks[i];
      if (t.kind == TokenKind::Comma) {
        ++i;
        continue;
      }
      if (t.kind != TokenKind::Word)
        return error_at(line.at(i), "expected an option name, got '" + describe(t) + "'");
      NetlistOption opt;
      opt.key = lower(t.text);
      opt.loc = line.at(i);
      if (line.kind(i + 1, TokenKind::Equals)) {
        i += 2;
        if (i >= n ||
            (line.toks[i].kind != TokenKind::Word && line.toks[i].kind != TokenKind::Expr))
          return error_at(line.at_or_end(i), "missing value for option '" + opt.key + "'");
        auto a = value(line, i, scope, true);
        if (!a) return a.status();
        opt.value = std::move(*a);
      } else {
        opt.value.kind = CardArg::Kind::Word;
        opt.value.loc = opt.loc;
        ++i;
      }
      out_.options.push_back(std::move(opt));
    }
    return Status::Ok();
  }

  void warn_once(const std::string& kind, const SourceLoc& loc, const std::string& msg) {
    if (warned_.insert(kind).second)
      out_.warnings.push_back(format_diagnostic(loc, "warning", msg));
  }

  Netlist out_;
  std::deque<Line> lines_;
  std::vector<const Line*> top_;
  std::unordered_map<std::string, std::unique_ptr<SubcktDef>> subckts_;
  std::vector<SubcktDef*> open_;
  std::vector<std::string> include_stack_;
  size_t total_bytes_ = 0;  // the netlist and its includes, against kMaxInputFileBytes
  bool in_control_ = false;
  std::unordered_set<std::string> warned_;
  std::unordered_map<std::string, SourceLoc> names_;
  std::unordered_set<std::string> global_nodes_;  // .global
  std::optional<double> temp_;                    // .temp
  SourceLoc section_call_loc_;                    // the .lib FILE SECTION being read
  Scope globals_;
};

StatusOr<Netlist> read(const std::shared_ptr<const SourceFile>& file) {
  Reader r;
  if (Status s = r.read(file); !s.ok()) return s;
  return r.take();
}

}  // namespace

StatusOr<Netlist> read_spice_file(const std::string& path) {
  auto text = read_input_file(path);
  if (!text) return text.status();
  return read(SourceFile::FromText(path, *text));
}

StatusOr<Netlist> read_spice_text(const std::string& text, const std::string& name) {
  return read(SourceFile::FromText(name, text));
}

}  // namespace isolink
