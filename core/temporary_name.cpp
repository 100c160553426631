#include "core/temporary_name.h"

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <climits>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

namespace ts {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kIdDigits = 16;

// Reads an unsigned decimal field of `text` at `*at` that ends at `end_char` ('\0': the text's end).
template <typename Int>
bool parse_field(std::string_view text, std::size_t* at, Int* value, int base, char end_char) {
  const char* first = text.data() + *at;
  const char* last = text.data() + text.size();
  if (first == last || *first == '+' || *first == '-') return false;
  const auto [end, error] = std::from_chars(first, last, *value, base);
  if (error != std::errc() || end == first) return false;
  *at = static_cast<std::size_t>(end - text.data());
  if (end_char == '\0') return end == last;
  if (end == last || *end != end_char) return false;
  ++*at;
  return true;
}

bool pid_exists(std::int64_t pid) { return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM; }

std::uint64_t own_start_time() {
  static const std::uint64_t start = process_start_time(::getpid());
  return start;
}

}  // namespace

std::string format_temporary_name(const TemporaryName& name) {
  std::string out(".");  // appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "." + string
  out.append(name.target);
  out.append(kTemporaryMarker);
  out.append(fmt::format("{}.{}.{:016x}", name.pid, name.start, name.id));
  return out;
}

std::optional<TemporaryName> parse_temporary_name(std::string_view file_name) {
  const std::size_t marker = file_name.rfind(kTemporaryMarker);
  if (marker == std::string_view::npos || marker < 2 || file_name.front() != '.') return std::nullopt;
  TemporaryName name;
  name.target = std::string(file_name.substr(1, marker - 1));
  std::size_t at = marker + kTemporaryMarker.size();
  if (!parse_field(file_name, &at, &name.pid, 10, '.') || name.pid <= 0 || name.pid > INT_MAX)
    return std::nullopt;
  if (!parse_field(file_name, &at, &name.start, 10, '.')) return std::nullopt;
  if (file_name.size() - at != kIdDigits) return std::nullopt;
  for (const char c : file_name.substr(at)) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return std::nullopt;
  }
  if (!parse_field(file_name, &at, &name.id, 16, '\0')) return std::nullopt;
  // Only the one spelling format_temporary_name writes (no leading zeros in the decimal fields).
  if (format_temporary_name(name) != file_name) return std::nullopt;
  return name;
}

std::uint64_t process_start_time(std::int64_t pid) {
  std::ifstream in(fmt::format("/proc/{}/stat", pid));
  std::stringstream text;
  text << in.rdbuf();
  const std::string stat = text.str();
  // Field 2 (the command) may hold spaces and parentheses: the fields after it follow the last ')'.
  const std::size_t close = stat.rfind(')');
  if (!in || close == std::string::npos) return 0;
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  for (int k = 3; k <= 22 && fields >> field; ++k) {
    if (k < 22) continue;
    std::uint64_t start = 0;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), start);
    return error == std::errc() && end == field.data() + field.size() ? start : 0;
  }
  return 0;
}

TemporaryName temporary_name_for(const std::string& target) {
  std::random_device device;
  const std::uint64_t id = (std::uint64_t{device()} << 32) | device();
  return {target, ::getpid(), own_start_time(), id};
}

bool writer_is_gone(const TemporaryName& name) {
  // An id given to another process since the writer ended: its start time differs from the writer's.
  const std::uint64_t start = name.pid == ::getpid() ? own_start_time() : process_start_time(name.pid);
  if (name.pid != ::getpid() && !pid_exists(name.pid)) return true;
  return name.start != 0 && start != 0 && start != name.start;
}

void remove_dead_temporaries(const fs::path& dir, const std::optional<std::string>& target) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const auto name = parse_temporary_name(entry.path().filename().string());
    if (!name || (target && name->target != *target)) continue;
    if (!entry.is_regular_file(ec) || entry.is_symlink(ec)) continue;
    if (writer_is_gone(*name)) fs::remove(entry.path(), ec);
  }
}

}  // namespace ts
