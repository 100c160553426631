// `tetrasand info MESH`: load, validate and measure a mesh.
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "core/error.h"
#include "core/mass_properties.h"
#include "core/mesh_io.h"
#include "core/mesh_report.h"

namespace ts::app {

Runner add_info_command(CLI::App& app, const GlobalOptions&) {
  auto* cmd = app.add_subcommand("info", "Report a mesh's validity (holes, non-manifold, self-intersections...) and mass properties");
  struct Options {
    std::string mesh;
    bool json = false;
    double density = 1000.0;
    double scale = 1.0;
    bool skip_self_intersections = false;
  };
  auto options = std::make_shared<Options>();
  cmd->add_option("MESH", options->mesh, "Mesh file (OBJ, PLY, STL, OFF, glTF/GLB, ... anything assimp reads)")->required();
  cmd->add_flag("--json", options->json, "Print the report as JSON");
  cmd->add_option("--density", options->density, "Density for the mass properties [kg/m^3]")->capture_default_str();
  cmd->add_option("--scale", options->scale, "Multiply coordinates by this factor (e.g. 0.001 for millimetres)")->capture_default_str();
  cmd->add_flag("--no-self-intersections", options->skip_self_intersections, "Skip the self-intersection test (large meshes)");
  return [options] {
    TriangleMesh mesh = load_mesh(options->mesh);
    if (options->scale != 1.0) scale_mesh(mesh, options->scale);
    ReportOptions report_options;
    report_options.self_intersections = !options->skip_self_intersections;
    const MeshReport report = analyze_mesh(mesh, report_options);
    nlohmann::json mass = nullptr;
    std::string mass_text;
    if (report.closed() && report.signed_volume > 0) {
      const MassProperties m = compute_mass_properties(mesh, options->density);
      auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
      auto mat = [&](const Eigen::Matrix3d& a) {
        return nlohmann::json{vec(a.row(0).transpose()), vec(a.row(1).transpose()), vec(a.row(2).transpose())};
      };
      mass = {{"density", m.density},         {"volume", m.volume},   {"mass", m.mass},
              {"center_of_mass", vec(m.center_of_mass)}, {"inertia", mat(m.inertia)},
              {"principal_moments", vec(m.principal_moments)}, {"principal_axes", mat(m.principal_axes)}};
      mass_text = fmt::format(
          "density               {:.6g} kg/m^3\nvolume                {:.9g} m^3\nmass                  {:.9g} kg\n"
          "centre of mass        ({:.9g}, {:.9g}, {:.9g}) m\nprincipal moments     ({:.6g}, {:.6g}, {:.6g}) kg m^2\n",
          m.density, m.volume, m.mass, m.center_of_mass.x(), m.center_of_mass.y(), m.center_of_mass.z(),
          m.principal_moments.x(), m.principal_moments.y(), m.principal_moments.z());
    } else {
      mass_text = "mass properties       none: the mesh does not enclose a volume (" + closed_solid_problems(report) + ")\n";
    }
    if (options->json) {
      nlohmann::json out = to_json(report);
      out["file"] = options->mesh;
      out["mass_properties"] = mass;
      fmt::print("{}\n", out.dump(2));
    } else {
      fmt::print("{}\n{}{}", options->mesh, format_report(report), mass_text);
    }
    return 0;
  };
}

}  // namespace ts::app
