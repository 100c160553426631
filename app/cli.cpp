#include "app/cli.h"

#include "app/numeric_options.h"

namespace ts::app {

std::unique_ptr<CommandLine> make_command_line() {
  auto cli = std::make_unique<CommandLine>();
  CLI::App& app = cli->app;
  app.description(
      "tetrasand: triangle meshes -> narrow-band SDFs -> particle rigid bodies -> GPU sand simulation.\n"
      "Exit codes: 0 ok, 1 bad input, 2 usage, 3 GPU/context failure, 4 simulation unstable, 5 internal "
      "error.");
  app.require_subcommand(1);
  app.set_version_flag("--version", "tetrasand 0.1.0");
  GlobalOptions& global = cli->global;
  app.add_option("--device", global.device,
                 "EGL device index (default: TETRASAND_DEVICE, else first GPU, else llvmpipe)")
      ->check(non_negative());
  app.add_flag("-v,--verbose", global.verbose, "Log debug messages");
  app.add_flag("-q,--quiet", global.quiet, "Log errors only");
  app.add_flag("--gl-debug", global.gl_debug, "KHR_debug output; check GL errors after every kernel");

  auto add = [&](Runner runner) { cli->runners[app.get_subcommands({}).back()] = std::move(runner); };
  add(add_devices_command(app, global));
  add(add_info_command(app, global));
  add(add_sdf_command(app, global));
  add(add_sample_command(app, global));
  add(add_preview_command(app, global));
  add(add_sim_command(app, global));
  add(add_frames_command(app, global));
  add(add_export_command(app, global));
  return cli;
}

}  // namespace ts::app
