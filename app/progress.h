#pragma once
// The one progress printer of every command (sdf's scan conversion, sample's relaxation, sim's steps): on a
// terminal a live line redrawn in place (carriage return, on stderr); in a pipe or a log, periodic log lines
// (each tenth of the work where its fraction is known, and at least every `period` seconds of a run that goes
// on), so a long run in CI shows it is alive without a line per step. Standard output is left to the results.
#include <chrono>
#include <string>

namespace ts::app {

class Progress {
 public:
  using Clock = std::chrono::steady_clock;

  // period: the longest gap between two piped lines [s].
  explicit Progress(double period = 10.0);
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress();

  // `line`: the whole state now; `done`: the fraction of the work done in [0, 1], or negative when not known
  // (then a pipe gets a line every `period` seconds only).
  void update(const std::string& line, double done = -1.0);
  // Ends the live line (a newline after it on a terminal); called by the destructor too.
  void end();

  bool terminal() const { return terminal_; }

 private:
  bool terminal_;
  double period_;
  bool drawn_ = false;           // a live line is on the terminal, not yet ended
  int reported_tenths_ = 0;      // tenths of the work a piped line has reported
  Clock::time_point last_line_;  // when the last piped line was written
};

}  // namespace ts::app
