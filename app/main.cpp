// tetrasand: one executable, one subcommand per stage. Exit codes: see core/error.h and README.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>

#include "app/cli.h"
#include "core/error.h"
#include "core/log.h"

int main(int argc, char** argv) {
  using namespace ts;
  const auto cli = app::make_command_line();
  try {
    cli->app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli->app.exit(e) == 0 ? 0 : static_cast<int>(ExitCode::Usage);
  }
  app::GlobalOptions& global = cli->global;
  if (global.quiet) log::set_level(log::Level::Error);
  if (global.verbose) log::set_level(log::Level::Debug);
#ifndef NDEBUG
  global.gl_debug = true;  // Debug builds always check GL errors per kernel.
#endif

  try {
    for (auto& [command, run] : cli->runners) {
      if (command->parsed()) return run();
    }
    return static_cast<int>(ExitCode::Usage);
  } catch (const Error& e) {
    log::error("{}", e.what());
    return static_cast<int>(e.code());
  } catch (const std::filesystem::filesystem_error& e) {
    // A directory that cannot be made or a file that cannot be moved: the place, not the program.
    // what() reads "filesystem error: cannot create directories: Not a directory [PATH]".
    std::string problem = e.what();
    if (problem.starts_with("filesystem error: ")) problem.erase(0, std::strlen("filesystem error: "));
    problem = problem.substr(0, problem.find(" ["));
    log::error("{}: {}", e.path1().string(), problem);
    return static_cast<int>(ExitCode::BadInput);
  } catch (const std::bad_alloc&) {
    log::error("out of memory");
    return static_cast<int>(ExitCode::BadInput);
  } catch (const std::exception& e) {
    log::error("internal error: {}", e.what());
    return static_cast<int>(ExitCode::Internal);
  }
}
