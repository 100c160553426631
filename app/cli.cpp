#include "app/cli.h"

#include <fmt/format.h>

#include "app/cli_docs.h"
#include "app/numeric_options.h"

namespace ts::app {

namespace {

// `tetrasand completion bash`: the completion script, made from this very command line.
Runner add_completion_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("completion", "Print the bash completion script (installed by cmake --install)");
  auto shell = std::make_shared<std::string>("bash");
  cmd->add_option("SHELL", *shell, "The shell: bash")->check(CLI::IsMember({"bash"}))->capture_default_str();
  return [&app] {
    fmt::print("{}", bash_completion(app));
    return 0;
  };
}

// `tetrasand manpage`: the man page (roff), made from this very command line.
Runner add_manpage_command(CLI::App& app) {
  app.add_subcommand("manpage", "Print the man page, section 1, in roff (installed by cmake --install)");
  return [&app] {
    fmt::print("{}", man_page(app));
    return 0;
  };
}

}  // namespace

std::unique_ptr<CommandLine> make_command_line() {
  auto cli = std::make_unique<CommandLine>();
  CLI::App& app = cli->app;
  app.name("tetrasand");  // usage lines name the command, not the path it was started by
  app.description(
      "tetrasand: triangle meshes -> narrow-band SDFs -> particle rigid bodies -> GPU sand simulation.\n"
      "Exit codes: 0 ok, 1 bad input, 2 usage, 3 GPU/context failure, 4 simulation unstable, 5 internal "
      "error.");
  app.require_subcommand(1);
  app.formatter(std::make_shared<WrappingFormatter>());  // before the subcommands, which copy it
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
  add(add_completion_command(app));
  add(add_manpage_command(app));
  return cli;
}

}  // namespace ts::app
