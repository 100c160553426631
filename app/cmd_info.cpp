// `tetrasand info MESH`: load, validate and measure a mesh.
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/numeric_options.h"
#include "core/error.h"
#include "core/mass_properties.h"
#include "core/mesh_io.h"
#include "core/mesh_report.h"
#include "core/up_axis.h"

namespace ts::app {

namespace {

struct Options {
  std::string mesh;
  bool json = false;
  double density = 1000.0;
  double scale = 1.0;
  bool skip_self_intersections = false;
};

nlohmann::json vec_json(const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; }
nlohmann::json rows_json(const Eigen::Matrix3d& a) {
  return nlohmann::json{vec_json(a.row(0).transpose()), vec_json(a.row(1).transpose()), vec_json(a.row(2).transpose())};
}

nlohmann::json mass_json(const MassProperties& m) {
  return {{"density", m.density},
          {"volume", m.volume},
          {"mass", m.mass},
          {"center_of_mass", vec_json(m.center_of_mass)},
          {"inertia", rows_json(m.inertia)},
          {"principal_moments", vec_json(m.principal_moments)},
          {"principal_axes", rows_json(m.principal_axes)}};
}

std::string mass_text(const MassProperties& m) {
  return fmt::format(
      "density               {:.6g} kg/m^3\nvolume                {:.9g} m^3\nmass                  {:.9g} kg\n"
      "centre of mass        ({:.9g}, {:.9g}, {:.9g}) m\nprincipal moments     ({:.6g}, {:.6g}, {:.6g}) kg m^2\n",
      m.density, m.volume, m.mass, m.center_of_mass.x(), m.center_of_mass.y(), m.center_of_mass.z(),
      m.principal_moments.x(), m.principal_moments.y(), m.principal_moments.z());
}

void add_options(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.mesh, "Mesh file (OBJ, PLY, STL, OFF, glTF/GLB, ... anything assimp reads)")->required();
  cmd->add_flag("--json", o.json, "Print the report as JSON");
  cmd->add_option("--density", o.density, "Density for the mass properties [kg/m^3]")
      ->check(finite())
      ->capture_default_str();
  cmd->add_option("--scale", o.scale, "Multiply coordinates by this factor (e.g. 0.001 for millimetres)")
      ->check(finite())
      ->capture_default_str();
  cmd->add_flag("--no-self-intersections", o.skip_self_intersections, "Skip the self-intersection test (large meshes)");
}

int run_info(const Options& o) {
  TriangleMesh mesh = load_mesh(o.mesh);
  if (o.scale != 1.0) scale_mesh(mesh, o.scale);
  ReportOptions report_options;
  report_options.self_intersections = !o.skip_self_intersections;
  const MeshReport report = analyze_mesh(mesh, report_options);
  nlohmann::json mass = nullptr;
  std::string text;
  if (report.closed() && report.signed_volume > 0) {
    const MassProperties m = compute_mass_properties(mesh, o.density);
    mass = mass_json(m);
    text = mass_text(m);
  } else {
    text = "mass properties       none: the mesh does not enclose a volume (" + closed_solid_problems(report) + ")\n";
  }
  const UpAxisHint up = up_axis_hint(report.box);
  const std::string advice = up_axis_advice(up, o.mesh);
  if (o.json) {
    nlohmann::json out = to_json(report);
    out["file"] = o.mesh;
    out["mass_properties"] = mass;
    out["up_axis"] = {{"tallest", std::string(1, axis_name(up.tallest))},
                      {"runner_up", std::string(1, axis_name(up.runner_up))},
                      {"extent", vec_json(up.extent)},
                      {"ambiguous", up.ambiguous},
                      {"advice", advice}};
    fmt::print("{}\n", out.dump(2));
  } else {
    fmt::print("{}\n{}{}", o.mesh, format_report(report), text);
    fmt::print("up axis               tallest along {} ({:.6g} m; {} {:.6g} m): {}\n", axis_name(up.tallest),
               up.extent[up.tallest], axis_name(up.runner_up), up.extent[up.runner_up], advice);
  }
  return 0;
}

}  // namespace

Runner add_info_command(CLI::App& app, const GlobalOptions& global) {
  return add_command<Options>(app, global, "info",
                              "Report a mesh's validity (holes, non-manifold, self-intersections...) and mass properties",
                              [](const Options& o, const GlobalOptions&) { return run_info(o); }, add_options);
}

}  // namespace ts::app
