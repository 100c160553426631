#pragma once
// Two tiers of errors (see docs/architecture.md): assert() for programmer errors; these typed,
// contextual exceptions for user data and the environment. main() maps each kind to an exit code.
#include <filesystem>
#include <stdexcept>
#include <string>

namespace ts {

// Process exit codes, documented in README.md ("Exit codes").
enum class ExitCode : int {
  Ok = 0,
  BadInput = 1,   // a file or parameter the user gave is wrong
  Usage = 2,      // the command line itself is wrong (CLI11 reports these)
  GpuFailure = 3, // no usable GL 4.5 context, or the GPU failed
  Unstable = 4,   // a simulation blew up (NaN, energy growth); the last good state was written
  Internal = 5,   // a bug: please report
};

class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

// Bad user input. The message names the file (when there is one) and the problem.
class InputError : public Error {
 public:
  explicit InputError(const std::string& message) : Error(ExitCode::BadInput, message) {}
  InputError(const std::filesystem::path& file, const std::string& problem)
      : Error(ExitCode::BadInput, file.string() + ": " + problem) {}
};

// The GPU or its driver could not do what was asked (no context, compile/link failure, GL error).
class GpuError : public Error {
 public:
  explicit GpuError(const std::string& message) : Error(ExitCode::GpuFailure, message) {}
};

}  // namespace ts
