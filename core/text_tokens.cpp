#include "core/text_tokens.h"

#include <charconv>
#include <cstdlib>
#include <string>

namespace ts::detail {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

}  // namespace

std::optional<std::string_view> Tokens::next() {
  skip_space();
  if (pos_ >= text_.size()) return std::nullopt;
  const std::size_t begin = pos_;
  while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
  return text_.substr(begin, pos_ - begin);
}

void Tokens::skip_space() {
  while (pos_ < text_.size() && is_space(text_[pos_])) line_ += text_[pos_++] == '\n' ? 1 : 0;
}

std::optional<std::int64_t> parse_integer(std::string_view token) {
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

std::optional<double> parse_number(std::string_view token) {
  double value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (end != token.data() + token.size()) return std::nullopt;
  if (ec == std::errc()) return value;
  if (ec != std::errc::result_out_of_range) return std::nullopt;
  // from_chars leaves `value` alone when the number is out of range; strtod (the "C" locale: tetrasand
  // never sets one) saturates it. The token is known to be a whole number by now.
  return std::strtod(std::string(token).c_str(), nullptr);
}

}  // namespace ts::detail
