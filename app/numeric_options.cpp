#include "app/numeric_options.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "core/checked_values.h"

namespace ts::app {
namespace detail {

std::optional<std::string> number_problem(const std::string& text, double lo, double hi, bool lo_open) {
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) return std::nullopt;
  // The same finiteness check as every scene, body and checkpoint value (core/checked_values.h).
  if (!finite_problem(value).empty()) return fmt::format("'{}' is not a finite number", text);
  const bool below = lo_open ? !(value > lo) : !(value >= lo);
  if (!below && value <= hi) return std::string();
  const std::string upper = hi == std::numeric_limits<double>::max() ? "" : fmt::format(" and <= {:g}", hi);
  return fmt::format("{} must be {} {:g}{}", text, lo_open ? ">" : ">=", lo, upper);
}

}  // namespace detail

namespace {

constexpr double kMax = std::numeric_limits<double>::max();

CLI::Validator checked(double lo, double hi, bool lo_open, const std::string& description) {
  return CLI::Validator(
      [lo, hi, lo_open](std::string& text) {
        return detail::number_problem(text, lo, hi, lo_open).value_or("");
      },
      description);
}

}  // namespace

CLI::Validator finite() { return checked(-kMax, kMax, false, ""); }
CLI::Validator positive() { return checked(0.0, kMax, true, "POSITIVE"); }
CLI::Validator non_negative() { return checked(0.0, kMax, false, "NONNEGATIVE"); }
CLI::Validator int_range(int lo, int hi) {
  return checked(lo, hi, false, fmt::format("INT in [{} - {}]", lo, hi));
}

CLI::Validator range(double lo, double hi) {
  return checked(lo, hi, false, fmt::format("FLOAT in [{} - {}]", lo, hi));
}

}  // namespace ts::app
