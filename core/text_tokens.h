#pragma once
// Whitespace-separated tokens of a text file and the numbers in them, for the strict readers of text
// formats (core/mesh_file_checks.h: OFF; core/ply.h: PLY headers and ascii data).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace ts::detail {

// Splits a text at spaces, tabs, carriage returns, line feeds, vertical tabs and form feeds,
// counting lines as it goes.
class Tokens {
 public:
  // Tokens of `text` from byte `start`, which lies on line `line` (1-based).
  explicit Tokens(std::string_view text, std::size_t start = 0, std::size_t line = 1)
      : text_(text), pos_(start), line_(line) {}

  // The next token, or nullopt at the end of the text.
  std::optional<std::string_view> next();
  // The line of the token last returned (after the end: the last line).
  std::size_t line() const { return line_; }
  // Bytes into the text, just after the token last returned.
  std::size_t position() const { return pos_; }

 private:
  void skip_space();
  std::string_view text_;
  std::size_t pos_;
  std::size_t line_;
};

// The whole token as a decimal integer, or nullopt.
std::optional<std::int64_t> parse_integer(std::string_view token);

// The whole token as a floating-point number, or nullopt. "nan" and "inf" are numbers (callers
// report them by value, with a clearer message), and so is a number beyond double's range: it
// reads as +-infinity or, below the smallest subnormal, as 0, as strtod gives it.
std::optional<double> parse_number(std::string_view token);

}  // namespace ts::detail
