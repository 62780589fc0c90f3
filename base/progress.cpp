#include "base/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace isolink {

bool stderr_is_terminal() {
  return isatty(STDERR_FILENO) != 0;
}

std::string duration_text(double s) {
  if (!(s >= 0) || !std::isfinite(s)) return "?";
  if (s < 60) return fmt::format("{:.1f} s", s);
  const long t = std::lround(s);
  if (t < 3600) return fmt::format("{} min {:02} s", t / 60, t % 60);
  return fmt::format("{} h {:02} min", t / 3600, (t % 3600) / 60);
}

ProgressLine::ProgressLine(Options opt) : opt_(std::move(opt)) {
  out_ = opt_.out ? opt_.out : stderr;
  terminal_ = opt_.terminal < 0 ? stderr_is_terminal() : opt_.terminal != 0;
  active_ = opt_.enabled && (terminal_ || opt_.pipe_interval > 0);
  start_ = now();
}

ProgressLine::~ProgressLine() {
  finish();
}

double ProgressLine::now() const {
  if (opt_.clock) return opt_.clock();
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double ProgressLine::elapsed() const {
  return now() - start_;
}

void ProgressLine::draw_locked(const std::string& text) {
  const std::string line = opt_.label.empty() ? text : opt_.label + ": " + text;
  if (terminal_) {
    std::fprintf(out_, "\r\033[K%s", line.c_str());
    drawn_ = true;
  } else {
    std::fprintf(out_, "%s\n", line.c_str());
  }
  std::fflush(out_);
}

void ProgressLine::show(const std::string& text, bool force) {
  if (!active_) return;
  std::lock_guard<std::mutex> lock(mu_);
  current_ = text;
  const double t = now();
  const double interval = terminal_ ? opt_.tty_interval : opt_.pipe_interval;
  if (!force && last_ >= 0 && t - last_ < interval) return;
  last_ = t;
  draw_locked(text);
}

void ProgressLine::show_fraction(const std::string& what, double fraction) {
  if (!active_) return;
  show(fmt::format("{} {:.0f} %", what, 100.0 * std::clamp(fraction, 0.0, 1.0)));
}

void ProgressLine::note(const std::string& line) {
  std::lock_guard<std::mutex> lock(mu_);
  if (drawn_) std::fputs("\r\033[K", out_);
  std::fprintf(out_, "%s\n", line.c_str());
  if (drawn_) draw_locked(current_);
  std::fflush(out_);
}

void ProgressLine::done(const std::string& text) {
  if (!active_) return;
  std::lock_guard<std::mutex> lock(mu_);
  current_ = text;
  draw_locked(text);
  if (terminal_) std::fputc('\n', out_);
  std::fflush(out_);
  drawn_ = false;
  last_ = -1;
}

void ProgressLine::finish() {
  if (!active_) return;
  std::lock_guard<std::mutex> lock(mu_);
  if (drawn_) {
    std::fputs("\r\033[K", out_);
    std::fflush(out_);
  }
  drawn_ = false;
  last_ = -1;
}

}  // namespace isolink
