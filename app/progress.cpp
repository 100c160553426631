#include "app/progress.h"

#include <unistd.h>

#include <cstdio>

#include "core/log.h"

namespace ts::app {

Progress::Progress(double period)
    : terminal_(::isatty(STDERR_FILENO) != 0), period_(period), last_line_(Clock::now()) {}

Progress::~Progress() { end(); }

void Progress::update(const std::string& line, double done) {
  if (terminal_) {
    // The trailing spaces clear what a longer previous line left.
    std::fprintf(stderr, "\r%s   ", line.c_str());
    drawn_ = true;
    return;
  }
  const int tenths = done >= 0.0 ? static_cast<int>(10.0 * done) : 0;
  const bool next_tenth = done >= 0.0 && done < 1.0 && tenths > reported_tenths_;
  const bool overdue = std::chrono::duration<double>(Clock::now() - last_line_).count() >= period_;
  if (!next_tenth && !overdue) return;
  if (next_tenth) reported_tenths_ = tenths;
  last_line_ = Clock::now();
  log::info("{}", line);
}

void Progress::end() {
  if (!drawn_) return;
  std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace ts::app
