#pragma once
// The names of the temporary files tetrasand writes beside an output before renaming them over it,
// and the rule for clearing away those a killed run left: only a name that parses exactly as ours
// (a marker no user file carries, the writer's process id and start time, a random id) and whose
// writer is gone is removed. Anything else in an output folder is never touched (issue 46: the old
// rule removed any ".NAME.tmp.N.N" whose N was not a live process, and threw on a 20-digit N).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace ts {

// ".TARGET.tetrasand-tmp.PID.START.ID": TARGET the output's file name, PID the writer's process id,
// START its start time (clock ticks after boot, /proc/PID/stat; 0 where unknown), ID 16 hex digits.
struct TemporaryName {
  std::string target;
  std::int64_t pid = 0;
  std::uint64_t start = 0;
  std::uint64_t id = 0;
};

inline constexpr std::string_view kTemporaryMarker = ".tetrasand-tmp.";

std::string format_temporary_name(const TemporaryName& name);

// The parts of `file_name` when it is exactly a temporary name (every field within its range), else
// nothing. Never throws: the name may be anything a user put in the folder.
std::optional<TemporaryName> parse_temporary_name(std::string_view file_name);

// A fresh temporary name for a file named `target` written by this process.
TemporaryName temporary_name_for(const std::string& target);

// A process's start time as /proc/PID/stat gives it (clock ticks after boot); 0 when unknown.
std::uint64_t process_start_time(std::int64_t pid);

// True when the process that wrote `name` has ended: its id is free, or taken by a process started
// at another time. This process's own names are never gone.
bool writer_is_gone(const TemporaryName& name);

// Removes the regular files in `dir` that are temporary names of dead writers (for the output named
// `target` only, when given). Best effort: what cannot be removed stays.
void remove_dead_temporaries(const std::filesystem::path& dir,
                             const std::optional<std::string>& target = std::nullopt);

}  // namespace ts
