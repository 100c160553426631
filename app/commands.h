#pragma once
// Each subcommand registers its options on the CLI11 app and returns the function that runs it.
#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>

#include "core/error.h"
#include "core/naming_file.h"
#include "gpu/context.h"

namespace ts::app {

struct GlobalOptions {
  int device = -1;         // --device N (else TETRASAND_DEVICE, else auto)
  bool verbose = false;
  bool quiet = false;
  bool gl_debug = false;   // --gl-debug: KHR_debug output, GL errors checked after every kernel
};

using Runner = std::function<int()>;

// A subcommand whose options live in one `Options` struct: each add(cmd, options) declares some of
// them (in the order --help lists them), run(options, global) runs the command once they are parsed.
template <typename Options, typename Run, typename... AddOptions>
Runner add_command(CLI::App& app, const GlobalOptions& global, const std::string& name, const std::string& description,
                   Run run, AddOptions... add) {
  CLI::App* cmd = app.add_subcommand(name, description);
  auto options = std::make_shared<Options>();
  (add(cmd, *options), ...);
  return [options, &global, run] { return run(*options, global); };
}

// The GL context options every GPU command takes from the global flags.
inline gpu::ContextOptions context_options(const GlobalOptions& global) {
  gpu::ContextOptions options;
  options.device = global.device;
  options.debug = global.gl_debug;
  return options;
}

Runner add_devices_command(CLI::App& app, const GlobalOptions& global);
Runner add_export_command(CLI::App& app, const GlobalOptions& global);
Runner add_frames_command(CLI::App& app, const GlobalOptions& global);
Runner add_info_command(CLI::App& app, const GlobalOptions& global);
Runner add_preview_command(CLI::App& app, const GlobalOptions& global);
Runner add_sample_command(CLI::App& app, const GlobalOptions& global);
Runner add_sdf_command(CLI::App& app, const GlobalOptions& global);
Runner add_sim_command(CLI::App& app, const GlobalOptions& global);

}  // namespace ts::app
