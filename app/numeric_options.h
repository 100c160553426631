#pragma once
// Checks of the command line's numeric options. CLI11's own range checks let NaN through (every
// comparison with NaN is false, so `--radius nan` passed as positive and was then ignored) and print
// their bounds with std::to_string (DBL_MAX in full, 309 digits). These reject NaN and infinity
// everywhere and name their bounds as %g does. A value that is not a number at all is left to
// CLI11's conversion, which names the option and the expected type. Every numeric option of every
// command has one of them (tests/app/cli_options_test.cpp checks NaN against each).
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace ts::app {

// Any finite number.
CLI::Validator finite();
// A finite number > 0 ("POSITIVE" in --help, as CLI::PositiveNumber).
CLI::Validator positive();
// A finite number >= 0 ("NONNEGATIVE" in --help, as CLI::NonNegativeNumber).
CLI::Validator non_negative();
// A finite number in [lo, hi] ("INT in [lo - hi]" in --help, as CLI::Range on an int).
CLI::Validator int_range(int lo, int hi);
// A finite number in [lo, hi] ("FLOAT in [lo - hi]" in --help, as CLI::Range on a double).
CLI::Validator range(double lo, double hi);

namespace detail {
// The problem with `text` as a number: "" when it is fine; nullopt when it is not a number at all
// (CLI11's conversion reports that). `lo`/`hi` are inclusive unless `lo_open`.
std::optional<std::string> number_problem(const std::string& text, double lo, double hi, bool lo_open);
}  // namespace detail

}  // namespace ts::app
