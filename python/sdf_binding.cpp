// tetrasand.sdf() and tetrasand.Field: the narrow-band SDF of `tetrasand sdf`, built on the CPU (exact
// distance) or the GPU (scan conversion) by the rule of gpu/backend.h, handed out as numpy arrays and
// written as .vdb or .nvdb.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <openvdb/tools/Interpolation.h>

#include <cctype>
#include <map>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/naming_file.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "sdf/exact_sdf.h"
#include "sdf/grid.h"
#include "sdf/mesh_signs.h"
#include "sdf/pseudonormals.h"
#include "sdf/scan_calibration.h"
#include "sdf/scan_convert.h"
#include "sdf/sparse_field.h"
#include "sdf/vdb_io.h"

namespace ts::python {

namespace {

// A level set in world units (OpenVDB's FloatGrid: transform createLinearTransform(voxel)) and the
// grid it was built on: voxel (i, j, k) of `coords` is centred at origin + voxel_size * (i, j, k).
struct Field {
  openvdb::FloatGrid::Ptr grid;
  sdf::GridSpec spec;
  double band = 3.0;
  std::string sign, source;  // for the .vdb's metadata: the sign method and the mesh's path or "<arrays>"
};

struct SdfArgs {
  std::optional<double> voxel;
  std::optional<int> resolution;
  double band = 3.0;
  std::string sign = "pseudonormal";
  std::string backend = "auto";
};

sdf::SdfSettings settings_of(const SdfArgs& a) {
  if (a.voxel && a.resolution) throw py::value_error("give voxel or resolution, not both");
  if (a.voxel && !(*a.voxel > 0.0)) throw py::value_error("voxel must be > 0");
  if (a.resolution && *a.resolution <= 0) throw py::value_error("resolution must be > 0");
  if (!(a.band >= 1.0)) throw py::value_error("band must be >= 1 (voxels)");
  if (a.sign != "pseudonormal" && a.sign != "winding")
    throw py::value_error("sign='" + a.sign + "': must be pseudonormal or winding");
  sdf::SdfSettings s;
  s.voxel_size = a.voxel.value_or(0.0);
  if (a.resolution) s.resolution = *a.resolution;
  s.band = a.band;
  s.sign = a.sign == "winding" ? sdf::SignMethod::Winding : sdf::SignMethod::Pseudonormal;
  return s;
}

// The GPU path of `tetrasand sdf`: scan conversion (its method by the cached calibration), winding
// signs afterwards where asked.
openvdb::FloatGrid::Ptr scanned(gpu::Context& context, const TriangleMesh& mesh, const sdf::GridSpec& spec,
                                const sdf::SdfSettings& s) {
  sdf::ScanConvertOptions scan;
  scan.method = sdf::choose_scan(context, "auto").method;
  scan.band = s.band;
  sdf::ScanConvertResult result = sdf::scan_convert(context, mesh, sdf::compute_pseudonormals(mesh), spec, scan);
  if (s.sign == sdf::SignMethod::Winding) sdf::resign_by_winding_number(*result.grid, sdf::ExactDistance(mesh));
  return result.grid;
}

Field build_sdf(const py::object& mesh_arg, const SdfArgs& args) {
  const sdf::SdfSettings settings = settings_of(args);
  const gpu::Backend requested = backend_from(args.backend, "backend");
  Field field;
  TriangleMesh mesh = mesh_from(mesh_arg, field.source);
  sdf::warn_about_signs(mesh, field.source, settings.sign);
  field.band = args.band, field.sign = args.sign;
  {
    py::gil_scoped_release released;  // the field takes seconds on its own threads
    field.spec = naming_file(field.source, [&] { return sdf::make_grid(bounding_box(mesh), settings); });
    std::unique_ptr<gpu::Context> context = context_for({requested});
    if (gpu::resolve_backend(requested, context.get()) == gpu::Backend::Gpu) {
      field.grid = scanned(*context, mesh, field.spec, settings);
    } else {
      field.grid = sdf::exact_sdf_grid(mesh, field.spec, settings.band, settings.sign);
    }
  }
  return field;
}

// The active (band) voxels' grid coordinates, in OpenVDB's iteration order (that of active_values).
py::array_t<std::int32_t> active_coords(const Field& f) {
  py::array_t<std::int32_t> coords({static_cast<py::ssize_t>(f.grid->activeVoxelCount()), py::ssize_t{3}});
  auto c = coords.mutable_unchecked<2>();
  py::ssize_t n = 0;
  for (auto it = f.grid->cbeginValueOn(); it && n < c.shape(0); ++it, ++n) {
    const openvdb::Coord ijk = it.getCoord();
    for (int k = 0; k < 3; ++k) c(n, k) = ijk[k] - f.spec.index_offset[k];
  }
  return coords;
}

// The active (band) voxels' signed distances [m], in the order of active_coords.
py::array_t<float> active_values(const Field& f) {
  py::array_t<float> values(static_cast<py::ssize_t>(f.grid->activeVoxelCount()));
  auto v = values.mutable_unchecked<1>();
  py::ssize_t n = 0;
  for (auto it = f.grid->cbeginValueOn(); it && n < v.shape(0); ++it, ++n) v(n) = *it;
  return values;
}

// Trilinear samples at world points (the background, signed, outside the band).
py::array_t<double> sample_field(const Field& f, const py::object& points) {
  const std::vector<Eigen::Vector3d> p = points_from(points, "points");
  py::array_t<double> out(static_cast<py::ssize_t>(p.size()));
  double* values = out.mutable_data();
  {
    py::gil_scoped_release released;
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*f.grid);
    for (std::size_t i = 0; i < p.size(); ++i) values[i] = sampler.wsSample(openvdb::Vec3R(p[i].x(), p[i].y(), p[i].z()));
  }
  return out;
}

// .vdb (with the metadata `tetrasand sdf` writes) or .nvdb (zip-compressed, its default), atomically.
void save_field(const Field& f, const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext != ".vdb" && ext != ".nvdb")
    throw InputError(path, "the output must end in .vdb (OpenVDB) or .nvdb (NanoVDB)");
  const bool from_file = f.source != "<arrays>";
  const std::vector<std::filesystem::path> inputs =
      from_file ? std::vector<std::filesystem::path>{f.source} : std::vector<std::filesystem::path>{};
  if (ext == ".nvdb") {
    sdf::NanoGrid nano = sdf::to_nanovdb(*f.grid);
    sdf::write_nvdb(path, nano, inputs);
    return;
  }
  std::map<std::string, std::string> metadata{{"tetrasand:source", f.source},
                                              {"tetrasand:band_voxels", std::to_string(f.band)},
                                              {"tetrasand:sign", f.sign}};
  if (from_file) metadata["tetrasand:source_sha256"] = sha256_file(f.source);
  sdf::write_vdb(path, f.grid, metadata, inputs);
}

}  // namespace

void add_sdf_bindings(py::module_& m) {
  py::class_<Field>(m, "Field", "A narrow-band signed distance field (negative inside)")
      .def_property_readonly("voxel_size", [](const Field& f) { return f.spec.voxel_size; }, "[m]")
      .def_property_readonly("origin", [](const Field& f) { return vector_array(f.spec.origin); },
                             "world position of voxel (0, 0, 0)'s centre [m]")
      .def_property_readonly("shape", [](const Field& f) { return py::make_tuple(f.spec.dims.x(), f.spec.dims.y(), f.spec.dims.z()); })
      .def_property_readonly("coords", &active_coords,
                             "M x 3 voxel indices of the band: centre = origin + voxel_size * (i, j, k)")
      .def_property_readonly("values", &active_values,
                             "M signed distances [m], in the order of coords")
      .def("sample", &sample_field, py::arg("points"), "Trilinear signed distance at N x 3 world points [m]")
      .def("save", &save_field, py::arg("path"), "Writes .vdb (OpenVDB level set) or .nvdb (NanoVDB), atomically");
  m.def(
      "sdf",
      [](const py::object& mesh, std::optional<double> voxel, std::optional<int> resolution, double band,
         const std::string& sign, const std::string& backend) {
        return build_sdf(mesh, SdfArgs{voxel, resolution, band, sign, backend});
      },
      py::arg("mesh"), py::kw_only(), py::arg("voxel") = py::none(), py::arg("resolution") = py::none(),
      py::arg("band") = 3.0, py::arg("sign") = "pseudonormal", py::arg("backend") = "auto",
      "The narrow-band SDF of a mesh (a path, or a (vertices, faces) pair), as `tetrasand sdf` builds it; "
      "default 128 voxels along the longest side");
}

}  // namespace ts::python
