// tetrasand.sample(), tetrasand.load_body() and tetrasand.Body: the sampler of `tetrasand sample` and
// the body files it writes, with the same checks, settings and verdict.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>

#include "body/body_file.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/naming_file.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "sampler/body_verdict.h"
#include "sampler/sample_mesh.h"

namespace ts::python {

namespace {

// A body as Python holds it: the particle body, and its verdict (judged from its figures and, for a
// body sampled in this process, its thin features; body.json does not keep those).
struct Body {
  body::ParticleBody body;
  sampler::BodyVerdict verdict;
};

// What sample() takes beside the mesh, as keyword arguments.
struct SampleArgs {
  std::optional<std::size_t> count;
  std::optional<double> radius, voxel;
  std::uint64_t seed = 0;
  std::string sign = "pseudonormal";
  bool fill = false;
  double density = 1000.0, coverage = 1.0, scale = 1.0;
  int rounds = 12;
  std::string backend = "auto", sdf_backend = "auto";
  py::object progress;
};

void require_positive(std::optional<double> value, const char* name) {
  if (value && !(*value > 0.0)) throw py::value_error(std::string(name) + " must be > 0");
}

// The sampler's settings, checked as the command line checks its options.
sampler::SampleSettings settings_of(const SampleArgs& a) {
  if (a.count && a.radius) throw py::value_error("give count or radius, not both");
  if (a.count && *a.count == 0) throw py::value_error("count must be > 0");
  require_positive(a.radius, "radius");
  require_positive(a.voxel, "voxel");
  require_positive(a.density, "density");
  require_positive(a.coverage, "coverage");
  require_positive(a.scale, "scale");
  if (a.rounds < 0) throw py::value_error("rounds must be >= 0");
  if (a.sign != "pseudonormal" && a.sign != "winding")
    throw py::value_error("sign='" + a.sign + "': must be pseudonormal or winding");
  sampler::SampleSettings s;
  s.count = a.count.value_or(0);
  s.radius = a.radius.value_or(0.0);
  s.voxel_size = a.voxel.value_or(0.0);
  s.seed = a.seed;
  s.fill = a.fill;
  s.density = a.density;
  s.coverage = a.coverage;
  s.max_rounds = a.rounds;
  s.backend = backend_from(a.backend, "backend");
  s.sdf_backend = backend_from(a.sdf_backend, "sdf_backend");
  return s;
}

// The sampler's progress reports, handed to the Python callable with the GIL held. The callable is
// held by pointer: the sampler may copy the std::function while the GIL is released, and copying a
// py::object would touch its reference count without it.
std::function<void(const sampler::SampleProgress&)> progress_of(const py::object& callback) {
  if (callback.is_none()) return {};
  const py::object* call = &callback;
  return [call](const sampler::SampleProgress& p) {
    py::gil_scoped_acquire gil;
    py::dict d;
    d["round"] = p.round, d["iteration"] = p.iteration, d["particles"] = p.particles, d["residual"] = p.residual;
    (*call)(d);
  };
}

Body sample(const py::object& mesh_arg, const SampleArgs& args) {
  sampler::SampleSettings settings = settings_of(args);
  std::string name;
  TriangleMesh mesh = mesh_from(mesh_arg, name);
  if (args.scale != 1.0) scale_mesh(mesh, args.scale);
  sampler::check_sample_mesh(mesh, name, args.sign == "winding", settings);
  const auto progress = progress_of(args.progress);
  Body out;
  {
    py::gil_scoped_release released;  // the sampler runs seconds to minutes on its own threads
    const std::unique_ptr<gpu::Context> context = context_for({settings.backend, settings.sdf_backend});
    sampler::SampleResult result =
        naming_file(name, [&] { return sampler::sample_mesh(context.get(), mesh, settings, progress); });
    out.body = std::move(result.body);
    out.verdict = sampler::judge_body(out.body, result.thin);
  }
  source_of(mesh_arg, mesh, out.body.source_path, out.body.source_sha256);
  return out;
}

Body load_body(const std::filesystem::path& json) {
  Body out;
  out.body = body::read_body(json);
  out.verdict = sampler::judge_body(out.body, sampler::ThinFeatures{});
  return out;
}

// The coverage certificate's figure, or None for a body without one (format versions 1 and 2).
py::object certificate_field(const Body& b, bool bound) {
  const auto& c = b.body.quality.certificate;
  if (!c) return py::none();
  return bound ? py::object(py::float_(c->bound_over_r)) : py::object(py::bool_(c->certified));
}

void add_body_class(py::module_& m) {
  py::class_<Body>(m, "Body", "A particle rigid body: particles in mesh coordinates and the solid's mass properties")
      .def_property_readonly("positions", [](const Body& b) { return points_array(b.body.positions); },
                             "N x 3 particle centres [m], mesh coordinates")
      .def_property_readonly("normals", [](const Body& b) { return points_array(b.body.normals); },
                             "N x 3 outward surface normals (interior particles: 0 0 0)")
      .def_property_readonly("count", [](const Body& b) { return b.body.positions.size(); })
      .def_property_readonly("interior_count", [](const Body& b) { return b.body.interior_count; })
      .def_property_readonly("radius", [](const Body& b) { return b.body.particle_radius; }, "particle radius [m]")
      .def_property_readonly("mass", [](const Body& b) { return b.body.mass; }, "[kg]")
      .def_property_readonly("density", [](const Body& b) { return b.body.density; }, "[kg/m^3]")
      .def_property_readonly("volume", [](const Body& b) { return b.body.volume; }, "[m^3]")
      .def_property_readonly("center_of_mass", [](const Body& b) { return vector_array(b.body.center_of_mass); })
      .def_property_readonly("inertia", [](const Body& b) { return matrix_array(b.body.inertia); },
                             "3 x 3 [kg m^2] about the centre of mass, mesh axes")
      .def_property_readonly("principal_moments", [](const Body& b) { return vector_array(b.body.principal_moments); })
      .def_property_readonly("principal_axes", [](const Body& b) { return matrix_array(b.body.principal_axes); },
                             "3 x 3, columns: unit axes")
      .def_property_readonly("relative_radius", [](const Body& b) { return b.body.quality.relative_radius; })
      .def_property_readonly("cv", [](const Body& b) { return b.body.quality.cv; })
      .def_property_readonly("covering_radius", [](const Body& b) { return b.body.quality.covering_radius; })
      .def_property_readonly("covering_over_r", [](const Body& b) { return b.body.quality.covering_over_r; })
      .def_property_readonly("max_abs_phi_over_r", [](const Body& b) { return b.body.quality.max_abs_phi_over_r; })
      .def_property_readonly("converged", [](const Body& b) { return b.body.quality.converged; })
      .def_property_readonly("coverage_certified", [](const Body& b) { return certificate_field(b, false); })
      .def_property_readonly("covering_bound_over_r", [](const Body& b) { return certificate_field(b, true); })
      .def_property_readonly("verdict", [](const Body& b) { return std::string(sampler::verdict_name(b.verdict.verdict)); })
      .def_property_readonly("verdict_reasons", [](const Body& b) { return b.verdict.reasons; })
      .def_property_readonly("source_path", [](const Body& b) { return b.body.source_path; })
      .def("save",
           [](const Body& b, const std::filesystem::path& directory, const std::string& name) {
             return body::write_body(directory, name, b.body);
           },
           py::arg("directory"), py::arg("name"),
           "Writes DIRECTORY/NAME.particles.ply and NAME.body.json as `tetrasand sample` does (atomically); "
           "returns the body.json path");
}

}  // namespace

void add_body_bindings(py::module_& m) {
  add_body_class(m);
  m.def(
      "sample",
      [](const py::object& mesh, std::optional<std::size_t> count, std::optional<double> radius, std::uint64_t seed,
         const std::string& sign, bool fill, double density, const std::string& backend, const std::string& sdf_backend,
         std::optional<double> voxel, double coverage, int rounds, double scale, const py::object& progress) {
        return sample(mesh, SampleArgs{count, radius, voxel, seed, sign, fill, density, coverage, scale, rounds,
                                       backend, sdf_backend, progress});
      },
      py::arg("mesh"), py::kw_only(), py::arg("count") = py::none(), py::arg("radius") = py::none(),
      py::arg("seed") = 0, py::arg("sign") = "pseudonormal", py::arg("fill") = false, py::arg("density") = 1000.0,
      py::arg("backend") = "auto", py::arg("sdf_backend") = "auto", py::arg("voxel") = py::none(),
      py::arg("coverage") = 1.0, py::arg("rounds") = 12, py::arg("scale") = 1.0, py::arg("progress") = py::none(),
      "Samples a closed mesh (a path, or a (vertices, faces) pair of arrays) into a Body, as `tetrasand sample` "
      "does; progress(dict) is called as the relaxation goes");
  m.def("load_body", &load_body, py::arg("path"),
        "Reads NAME.body.json and its PLY; the verdict is judged from the file's figures (thin features are not "
        "stored in it)");
}

}  // namespace ts::python
