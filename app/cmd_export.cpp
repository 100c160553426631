// `tetrasand export lammps SCENE.toml -o DIR`: the scene as a LAMMPS input deck (export/lammps_deck.h),
// for scenes that outgrow one GPU and run on a cluster under LAMMPS with MPI.
#include <fmt/format.h>

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
  };
  auto o = std::make_shared<Options>();
  lammps->add_option("SCENE", o->scene, "Scene file (TOML; see assets/scenes/README.md)")->required()->check(CLI::ExistingFile);
  lammps->add_option("-o,--output", o->output, "Output directory")->capture_default_str();
  return [o] {
    const scene::Scene scene = scene::load_scene(o->scene);
    const exporter::LammpsDeck deck = exporter::export_lammps(scene, o->output);
    fmt::print("{}: LAMMPS deck in {} ({} rigid bodies, {} frozen particles, dt = {:.4g} s, {} steps)\n", o->scene,
               o->output, deck.dynamic_bodies, deck.frozen_particles, deck.dt, deck.steps);
    for (const std::string& a : deck.approximations) fmt::print("  not exactly the same: {}\n", a);
    fmt::print("run it with: cd {} && lmp -in in.tetrasand   (or mpirun -np N lmp -in in.tetrasand)\n", o->output);
    return 0;
  };
}

}  // namespace ts::app
