// `tetrasand export lammps SCENE.toml -o DIR`: the scene as a LAMMPS input deck (export/lammps_deck.h),
// for scenes that outgrow one GPU and run on a cluster under LAMMPS with MPI.
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "core/log.h"
#include "export/lammps_deck.h"
#include "scene/scene.h"

namespace ts::app {

Runner add_export_command(CLI::App& app, const GlobalOptions&) {
  auto* cmd = app.add_subcommand("export", "Write a scene for another simulator");
  cmd->require_subcommand(1);
  auto* lammps = cmd->add_subcommand("lammps", "LAMMPS input deck (in.tetrasand, data, rigid bodies, grain molecule)");
  struct Options {
    std::string scene;
    std::string output = "lammps-deck";
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  lammps->add_option("SCENE", o->scene, "Scene file (TOML; see assets/scenes/README.md)")->required()->check(CLI::ExistingFile);
  lammps->add_option("-o,--output", o->output, "Output directory")->capture_default_str();
  lammps->add_flag("--json", o->json,
                   "Print what was written (files, bodies, dt, steps, approximations) as JSON instead of text");
  return [o] {
    const scene::Scene scene = scene::load_scene(o->scene);
    const exporter::LammpsDeck deck = exporter::export_lammps(scene, o->output);
    if (o->json) {
      nlohmann::ordered_json files = nlohmann::ordered_json::array();
      for (const auto& f : deck.files) files.push_back(f.string());
      const nlohmann::ordered_json out = {{"scene", o->scene},       {"output", o->output},
                                          {"input", deck.input.string()}, {"files", files},
                                          {"dynamic_bodies", deck.dynamic_bodies},
                                          {"frozen_particles", deck.frozen_particles},
                                          {"dt_s", deck.dt},         {"steps", deck.steps},
                                          {"approximations", deck.approximations}};
      fmt::print("{}\n", out.dump(2));
      return 0;
    }
    fmt::print("{}: LAMMPS deck in {} ({} rigid bodies, {} frozen particles, dt = {:.4g} s, {} steps)\n", o->scene,
               o->output, deck.dynamic_bodies, deck.frozen_particles, deck.dt, deck.steps);
    for (const std::string& a : deck.approximations) fmt::print("  not exactly the same: {}\n", a);
    fmt::print("run it with: cd {} && lmp -in in.tetrasand   (or mpirun -np N lmp -in in.tetrasand)\n", o->output);
    return 0;
  };
}

}  // namespace ts::app
