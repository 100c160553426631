// tetrasand: one executable, one subcommand per stage. Exit codes: see core/error.h and README.md.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <map>

#include "app/commands.h"
#include "core/error.h"
#include "core/log.h"

int main(int argc, char** argv) {
  using namespace ts;
  CLI::App app{
      "tetrasand: triangle meshes -> narrow-band SDFs -> particle rigid bodies -> GPU sand simulation.\n"
      "Exit codes: 0 ok, 1 bad input, 2 usage, 3 GPU/context failure, 4 simulation unstable, 5 internal error."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "tetrasand 0.1.0");
  app::GlobalOptions global;
  app.add_option("--device", global.device, "EGL device index (default: TETRASAND_DEVICE, else first GPU, else llvmpipe)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-v,--verbose", global.verbose, "Log debug messages");
  app.add_flag("-q,--quiet", global.quiet, "Log errors only");
  app.add_flag("--gl-debug", global.gl_debug, "KHR_debug output; check GL errors after every kernel");

  std::map<CLI::App*, app::Runner> runners;
  auto add = [&](app::Runner runner) { runners[app.get_subcommands({}).back()] = std::move(runner); };
  add(app::add_devices_command(app, global));
  add(app::add_info_command(app, global));
  add(app::add_sdf_command(app, global));
  add(app::add_sample_command(app, global));
  add(app::add_preview_command(app, global));
  add(app::add_sim_command(app, global));
  add(app::add_export_command(app, global));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : static_cast<int>(ExitCode::Usage);
  }
  if (global.quiet) log::set_level(log::Level::Error);
  if (global.verbose) log::set_level(log::Level::Debug);
#ifndef NDEBUG
  global.gl_debug = true;  // Debug builds always check GL errors per kernel.
#endif

  try {
    for (auto& [command, run] : runners) {
      if (command->parsed()) return run();
    }
    return static_cast<int>(ExitCode::Usage);
  } catch (const Error& e) {
    log::error("{}", e.what());
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    log::error("out of memory");
    return static_cast<int>(ExitCode::BadInput);
  } catch (const std::exception& e) {
    log::error("internal error: {}", e.what());
    return static_cast<int>(ExitCode::Internal);
  }
}
