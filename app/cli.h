#pragma once
// The whole command line of `tetrasand`: the global flags and every subcommand's options on one
// CLI11 app, and the function that runs each subcommand once parsed. main() parses and runs it; the
// option tests and the command-line fuzz target (fuzz/) parse it without running anything.
#include <CLI/CLI.hpp>

#include <map>
#include <memory>

#include "app/commands.h"

namespace ts::app {

struct CommandLine {
  CLI::App app;
  GlobalOptions global;
  std::map<CLI::App*, Runner> runners;  // by subcommand
};

// Built on the heap: the runners refer to `global` by address.
std::unique_ptr<CommandLine> make_command_line();

}  // namespace ts::app
