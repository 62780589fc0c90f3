// A progress line for long work on stderr: `isolink sim`, `run`, `worst`, `pack` and `sweep`.
//
//   ProgressLine line({.label = "isolink run"});  // silent unless stderr is a terminal
//   line.show("down 40 %");                         // drawn at once, then at most every 0.5 s
//   line.note("a warning");                          // printed above the line, never lost
//   line.finish();                                   // the line is cleared; output goes on below
//   (or line.done("12/12 points, done in 3.1 s"): the last text, kept as a line)
//
// On a terminal the line is redrawn in place ("\r" + erase to the end of the line), so a run
// leaves no trace of it once finished. On a pipe or a file it prints nothing, unless
// pipe_interval is set (sweeps log a line every 5 s there, for batch logs). Thread-safe: the
// engines of two directions may report from two threads.
#pragma once

#include <cstdio>
#include <functional>
#include <mutex>
#include <string>

namespace isolink {

// Whether stderr is a terminal (isatty).
bool stderr_is_terminal();

// "12.3 s", "4 min 05 s", "2 h 03 min"; "?" for a negative or non-finite figure.
std::string duration_text(double seconds);

class ProgressLine {
 public:
  struct Options {
    std::string label;           // printed before the text ("isolink run: down 40 %")
    bool enabled = true;         // false: print nothing (--quiet)
    double tty_interval = 0.5;   // s between redraws on a terminal
    double pipe_interval = 0.0;  // s between lines on a pipe; 0: silent there
    // For tests: where to write, whether it is a terminal, and the clock (seconds). Defaults:
    // stderr, stderr_is_terminal(), steady_clock.
    std::FILE* out = nullptr;
    int terminal = -1;  // -1: ask stderr_is_terminal()
    std::function<double()> clock;
  };

  explicit ProgressLine(Options opt);
  ~ProgressLine();  // finish()
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  // Whether show() can print anything here.
  bool active() const { return active_; }
  // Seconds since construction.
  double elapsed() const;
  // The line's new text: drawn now if it is the first or the interval has passed, else kept
  // for later (force: draw now).
  void show(const std::string& text, bool force = false);
  // show("what 42 %") for an engine's progress callback (fraction 0-1).
  void show_fraction(const std::string& what, double fraction);
  // A whole line printed above the progress line (the line is redrawn after it).
  void note(const std::string& line);
  // The last word: text drawn now and kept (a whole line on a terminal and on a pipe).
  void done(const std::string& text);
  // Clears the line on a terminal (nothing is left of it). Later show() calls draw again.
  void finish();

 private:
  void draw_locked(const std::string& text);  // mu_ held
  double now() const;

  Options opt_;
  bool active_ = false;
  bool terminal_ = false;
  std::FILE* out_ = nullptr;
  double start_ = 0;
  double last_ = -1;     // last draw (s); -1: none yet
  bool drawn_ = false;   // a line is on the terminal now
  std::string current_;  // the latest text
  mutable std::mutex mu_;
};

}  // namespace isolink
