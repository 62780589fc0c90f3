#include "netlists/touchstone.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <complex>
#include <numbers>

#include "base/file_io.h"
#include "base/source_loc.h"
#include "solver/vector_fit.h"

namespace isolink {

namespace {

using cd = std::complex<double>;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

struct Token {
  std::string text;
  int line = 0, col = 0;
};

std::vector<Token> split(const std::string& line, int line_no, int col0 = 0) {
  std::vector<Token> out;
  size_t i = col0;
  while (i < line.size()) {
    while (i < line.size() && (std::isspace(static_cast<unsigned char>(line[i])) || line[i] == ','))
      ++i;
    const size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i])) && line[i] != ',')
      ++i;
    if (i > start)
      out.push_back({line.substr(start, i - start), line_no, static_cast<int>(start) + 1});
  }
  return out;
}

// The port count from a version 1 name: ".s4p" -> 4; 0 when the name has no such extension.
int ports_from_name(const std::string& name) {
  const std::string n = lower(name);
  const size_t dot = n.rfind('.');
  if (dot == std::string::npos || n.size() < dot + 4 || n[dot + 1] != 's' || n.back() != 'p')
    return 0;
  int v = 0;
  for (size_t i = dot + 2; i + 1 < n.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(n[i])) || v > 1000) return 0;
    v = v * 10 + (n[i] - '0');
  }
  return v;
}

class Reader {
 public:
  Reader(const std::string& text, const std::string& name)
      : file_(SourceFile::FromText(name, text)) {
    out_.source = name;
  }
  StatusOr<Touchstone> read();

 private:
  Status error(int line, int col, const std::string& msg) const {
    return error_at(SourceLoc{file_, line, col}, msg);
  }
  Status error(const Token& t, const std::string& msg) const { return error(t.line, t.col, msg); }
  StatusOr<double> number(const Token& t) const;
  Status option_line(const std::vector<Token>& toks);
  Status keyword(const std::string& line, int line_no);
  Status data_line(const std::vector<Token>& toks);
  Status finish_point();
  Status set_ports(int n, const Token& at);
  int values_per_point() const {
    const int n = out_.ports;
    return 1 + 2 * (matrix_ == "full" ? n * n : n * (n + 1) / 2);
  }

  std::shared_ptr<const SourceFile> file_;
  Touchstone out_;
  double unit_ = 1e9;
  std::string param_ = "s", format_ = "ma";
  double r_ = 50;
  std::vector<double> refs_;  // [Reference], per port
  int refs_wanted_ = 0;       // values still to read for [Reference]
  bool option_seen_ = false, in_info_ = false, in_noise_ = false, network_ = false;
  bool ended_ = false, order_21_12_ = true;
  std::string matrix_ = "full";
  int declared_freqs_ = -1;
  std::vector<Token> point_;  // the values of the point being read
};

StatusOr<double> Reader::number(const Token& t) const {
  const char* b = t.text.data();
  const char* e = b + t.text.size();
  if (b != e && *b == '+') ++b;
  double v = 0;
  const auto [p, ec] = std::from_chars(b, e, v);
  if (ec != std::errc() || p != e) return error(t, fmt::format("'{}' is not a number", t.text));
  if (!std::isfinite(v)) return error(t, fmt::format("'{}' is not a finite number", t.text));
  return v;
}

Status Reader::set_ports(int n, const Token& at) {
  if (n < 1 || n > kMaxTouchstonePorts)
    return error(at, fmt::format("{} ports: isolink reads 1 to {} ports", n, kMaxTouchstonePorts));
  out_.ports = n;
  return Status::Ok();
}

Status Reader::option_line(const std::vector<Token>& toks) {
  if (option_seen_) return Status::Ok();  // later option lines are ignored (the standard)
  option_seen_ = true;
  for (size_t i = 1; i < toks.size(); ++i) {
    const std::string w = lower(toks[i].text);
    if (w == "hz" || w == "khz" || w == "mhz" || w == "ghz") {
      unit_ = w == "hz" ? 1 : w == "khz" ? 1e3 : w == "mhz" ? 1e6 : 1e9;
    } else if (w == "s" || w == "y" || w == "z") {
      param_ = w;
    } else if (w == "h" || w == "g") {
      return error(toks[i],
                   fmt::format("{} parameters are not supported (S, Y or Z)", toks[i].text));
    } else if (w == "db" || w == "ma" || w == "ri") {
      format_ = w;
    } else if (w == "r") {
      if (i + 1 >= toks.size()) return error(toks[i], "R needs a reference impedance after it");
      StatusOr<double> v = number(toks[++i]);
      if (!v) return v.status();
      if (!(*v > 0)) return error(toks[i], "the reference impedance must be > 0");
      r_ = *v;
    } else {
      return error(toks[i], fmt::format("unknown option '{}' (a unit, S/Y/Z, DB/MA/RI or R n)",
                                        toks[i].text));
    }
  }
  return Status::Ok();
}

Status Reader::keyword(const std::string& line, int line_no) {
  const size_t close = line.find(']');
  const int col = static_cast<int>(line.find('[')) + 1;
  if (close == std::string::npos) return error(line_no, col, "a keyword needs its closing ']'");
  const std::string key = lower(line.substr(col, close - col));
  const std::vector<Token> args = split(line, line_no, static_cast<int>(close) + 1);
  if (in_info_) {
    if (key == "end information") in_info_ = false;
    return Status::Ok();
  }
  if (out_.version == 1 && key != "version")
    return error(line_no, col, "a version 2 keyword needs [Version] 2.0 first");
  auto arg = [&](size_t i) -> StatusOr<Token> {
    if (i >= args.size()) return error(line_no, col, fmt::format("[{}] needs a value", key));
    return args[i];
  };
  if (key == "version") {
    StatusOr<Token> a = arg(0);
    if (!a) return a.status();
    if (a->text.rfind("2.", 0) != 0)
      return error(*a, fmt::format("version '{}': isolink reads versions 1.x and 2.x", a->text));
    out_.version = 2;
  } else if (key == "number of ports") {
    StatusOr<Token> a = arg(0);
    if (!a) return a.status();
    // Once: [Reference], the matrix and the data already read are sized by the first.
    if (out_.ports > 0)
      return error(*a,
                   fmt::format("[Number of Ports] again (it was {}): the standard gives it once",
                               out_.ports));
    StatusOr<double> v = number(*a);
    if (!v) return v.status();
    if (Status s = set_ports(std::floor(*v) == *v && *v < 1e6 ? static_cast<int>(*v) : -1, *a);
        !s.ok())
      return s;
  } else if (key == "two-port data order") {
    StatusOr<Token> a = arg(0);
    if (!a) return a.status();
    if (a->text != "12_21" && a->text != "21_12")
      return error(*a, "[Two-Port Data Order] is 12_21 or 21_12");
    order_21_12_ = a->text == "21_12";
  } else if (key == "number of frequencies") {
    StatusOr<Token> a = arg(0);
    if (!a) return a.status();
    StatusOr<double> v = number(*a);
    if (!v) return v.status();
    if (!(*v >= 1 && *v < 1e8 && std::floor(*v) == *v))
      return error(*a, "[Number of Frequencies] must be a positive whole number");
    declared_freqs_ = static_cast<int>(*v);
  } else if (key == "number of noise frequencies") {
  } else if (key == "reference") {
    if (out_.ports == 0) return error(line_no, col, "[Reference] needs [Number of Ports] first");
    refs_.clear();
    refs_wanted_ = out_.ports;
    return data_line(args);
  } else if (key == "matrix format") {
    StatusOr<Token> a = arg(0);
    if (!a) return a.status();
    matrix_ = lower(a->text);
    if (matrix_ != "full" && matrix_ != "lower" && matrix_ != "upper")
      return error(*a, "[Matrix Format] is Full, Lower or Upper");
  } else if (key == "network data") {
    if (out_.ports == 0) return error(line_no, col, "[Network Data] needs [Number of Ports] first");
    if (!option_seen_) return error(line_no, col, "[Network Data] needs the option line first");
    network_ = true;
  } else if (key == "noise data") {
    in_noise_ = true;
  } else if (key == "begin information") {
    in_info_ = true;
  } else if (key == "end") {
    ended_ = true;
  } else if (key == "mixed-mode order") {
    return error(line_no, col,
                 "[Mixed-Mode Order]: mixed-mode data is not supported; give the single-ended "
                 "S-parameters (ports to the chassis reference)");
  } else {
    return error(line_no, col,
                 fmt::format("keyword [{}] is not supported", line.substr(col, close - col)));
  }
  return Status::Ok();
}

Status Reader::data_line(const std::vector<Token>& toks) {
  if (refs_wanted_ > 0) {
    for (const Token& t : toks) {
      if (refs_wanted_ == 0) return error(t, "more [Reference] values than ports");
      StatusOr<double> v = number(t);
      if (!v) return v.status();
      if (!(*v > 0)) return error(t, "a reference impedance must be > 0");
      refs_.push_back(*v);
      --refs_wanted_;
    }
    return Status::Ok();
  }
  if (toks.empty() || in_noise_ || ended_) return Status::Ok();
  if (out_.version == 2 && !network_) return error(toks[0], "data before [Network Data]");
  if (out_.version == 1 && !option_seen_) {
    // The standard lets the option line be absent (its defaults): nothing to do.
    option_seen_ = true;
  }
  if (point_.empty() && out_.ports == 2 && out_.version == 1 && toks.size() == 5 &&
      !out_.freqs.empty()) {
    // A 2-port's noise block starts at a frequency that does not rise.
    StatusOr<double> f = number(toks[0]);
    if (!f) return f.status();
    if (*f * unit_ <= out_.freqs.back()) {
      in_noise_ = true;
      ++out_.noise_lines_skipped;
      return Status::Ok();
    }
  }
  const int want = values_per_point();
  const bool one_line = out_.ports <= 2;
  for (const Token& t : toks) {
    if (static_cast<int>(point_.size()) == want)
      return error(t, fmt::format("{} values on this line past the {} of a point ({}-port: a "
                                  "frequency and {} numbers)",
                                  toks.size(), want, out_.ports, want - 1));
    point_.push_back(t);
  }
  if (static_cast<int>(point_.size()) == want) return finish_point();
  if (one_line)
    return error(toks[0], fmt::format("{} values for {}-port data: a point is a frequency and {} "
                                      "numbers on one line",
                                      toks.size(), out_.ports, want - 1));
  return Status::Ok();
}

Status Reader::finish_point() {
  const int n = out_.ports;
  std::vector<double> v;
  for (const Token& t : point_) {
    StatusOr<double> x = number(t);
    if (!x) return x.status();
    v.push_back(*x);
  }
  const double f = v[0] * unit_;
  if (!(f >= 0)) return error(point_[0], "a frequency must be >= 0");
  if (!out_.freqs.empty() && !(f > out_.freqs.back()))
    return error(point_[0], fmt::format("frequency {:g} Hz does not rise above the previous "
                                        "point's {:g} Hz",
                                        f, out_.freqs.back()));
  Eigen::MatrixXcd m = Eigen::MatrixXcd::Zero(n, n);
  size_t k = 1;
  auto value = [&]() {
    const double a = v[k], b = v[k + 1];
    k += 2;
    const double deg = b * std::numbers::pi / 180;
    if (format_ == "ri") return cd(a, b);
    const double mag = format_ == "ma" ? a : std::pow(10.0, a / 20);
    return std::polar(mag, deg);
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if ((matrix_ == "lower" && j > i) || (matrix_ == "upper" && j < i)) continue;
      const bool swap = n == 2 && (out_.version == 1 || order_21_12_);
      const cd x = value();
      if (swap)
        m(j, i) = x;
      else
        m(i, j) = x;
      if (matrix_ != "full") m(j, i) = m(i, j) = x;
    }
  if (!m.allFinite()) return error(point_[1], "a value overflows to a non-finite number");
  out_.freqs.push_back(f);
  out_.s.push_back(m);
  point_.clear();
  return Status::Ok();
}

StatusOr<Touchstone> Reader::read() {
  const std::string ext_name = out_.source;
  for (size_t i = 0; i < file_->lines.size(); ++i) {
    const int line_no = static_cast<int>(i) + 1;
    std::string line = file_->lines[i];
    if (size_t bang = line.find('!'); bang != std::string::npos) line.resize(bang);
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (line[first] == '[') {
      if (refs_wanted_ > 0) return error(line_no, 1, "[Reference] has fewer values than ports");
      if (Status s = keyword(line, line_no); !s.ok()) return s;
      continue;
    }
    if (in_info_) continue;
    if (line[first] == '#') {
      if (out_.version == 1 && out_.ports == 0) {
        const int n = ports_from_name(ext_name);
        if (n == 0)
          return error(line_no, 1,
                       "a version 1 file's port count comes from its name (.s2p, "
                       ".s4p); this name has none");
        if (Status s = set_ports(n, Token{"", line_no, 1}); !s.ok()) return s;
      }
      if (Status s = option_line(split(line, line_no)); !s.ok()) return s;
      continue;
    }
    if (out_.ports == 0) {
      const int n = ports_from_name(ext_name);
      if (n == 0) return error(line_no, 1, "data before the port count is known");
      if (Status s = set_ports(n, Token{"", line_no, 1}); !s.ok()) return s;
    }
    if (Status s = data_line(split(line, line_no)); !s.ok()) return s;
  }
  const int last = static_cast<int>(file_->lines.size());
  if (refs_wanted_ > 0) return error(last, 1, "[Reference] has fewer values than ports");
  if (!point_.empty())
    return error(point_[0], fmt::format("the point at this frequency has {} of its {} values",
                                        point_.size(), values_per_point()));
  if (out_.freqs.empty()) return error(last, 1, "no network data");
  if (declared_freqs_ >= 0 && declared_freqs_ != static_cast<int>(out_.freqs.size()))
    return error(last, 1,
                 fmt::format("[Number of Frequencies] says {}, the data has {}", declared_freqs_,
                             out_.freqs.size()));
  out_.parameter = param_ == "s" ? "S" : param_ == "y" ? "Y" : "Z";
  out_.format = format_ == "ri" ? "RI" : format_ == "ma" ? "MA" : "DB";
  // To S at one reference. Version 1's Y and Z are normalised to R; version 2's are not.
  const int n = out_.ports;
  Eigen::VectorXd z(n);
  for (int i = 0; i < n; ++i) z[i] = refs_.empty() ? r_ : refs_[i];
  out_.z0 = z[0];
  const double norm = out_.version == 1 ? r_ : 1.0;
  for (size_t k = 0; k < out_.s.size(); ++k) {
    Eigen::MatrixXcd y;
    const Eigen::MatrixXcd& m = out_.s[k];
    const Eigen::MatrixXcd id = Eigen::MatrixXcd::Identity(n, n);
    if (param_ == "y") {
      y = m / norm;
    } else if (param_ == "z") {
      Eigen::FullPivLU<Eigen::MatrixXcd> lu(m * norm);
      if (!lu.isInvertible()) return error(last, 1, "a Z matrix is singular (no admittance)");
      y = lu.inverse();
    } else {
      bool same = (z.array() == z[0]).all();
      if (same) continue;  // already S at z0
      // Per-port references: S' = D^-1 S D with D = diag(1 / (2 sqrt z)); Y = Zr^-1 (I + S')^-1 (I
      // - S').
      Eigen::MatrixXcd sp(n, n);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) sp(i, j) = m(i, j) * std::sqrt(z[i] / z[j]);
      Eigen::FullPivLU<Eigen::MatrixXcd> lu(id + sp);
      if (!lu.isInvertible()) return error(last, 1, "I + S is singular (no admittance)");
      y = z.cwiseInverse().cast<cd>().asDiagonal() * lu.solve(id - sp);
    }
    out_.s[k] = s_from_y(y, out_.z0);
    if (!out_.s[k].allFinite()) return error(last, 1, "the data has no finite S-parameters");
  }
  return std::move(out_);
}

}  // namespace

StatusOr<Touchstone> read_touchstone_text(const std::string& text, const std::string& name) {
  return Reader(text, name).read();
}

StatusOr<Touchstone> read_touchstone_file(const std::string& path) {
  StatusOr<std::string> text = read_input_file(path);
  if (!text) return text.status();
  return read_touchstone_text(*text, path);
}

std::string write_touchstone(const Touchstone& t, const std::string& comment) {
  std::string out;
  size_t start = 0;
  while (start <= comment.size()) {
    const size_t end = std::min(comment.find('\n', start), comment.size());
    out += "! " + comment.substr(start, end - start) + "\n";
    start = end + 1;
  }
  out += fmt::format("# HZ S RI R {}\n", t.z0);
  const int n = t.ports;
  for (size_t k = 0; k < t.freqs.size(); ++k) {
    const Eigen::MatrixXcd& s = t.s[k];
    out += fmt::format("{:.12g}", t.freqs[k]);
    if (n <= 2) {
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          out += fmt::format(" {:.12g} {:.12g}", s(i, j).real(), s(i, j).imag());
      out += "\n";
      continue;
    }
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        if (j > 0 && j % 4 == 0) out += "\n";
        out += fmt::format(" {:.12g} {:.12g}", s(i, j).real(), s(i, j).imag());
      }
      out += "\n";
    }
  }
  return out;
}

}  // namespace isolink
