#include "python/arrays.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string_view>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mesh_io.h"

namespace ts::python {

py::array_t<double> vector_array(const Eigen::Vector3d& v) {
  py::array_t<double> out(3);
  std::copy(v.data(), v.data() + 3, out.mutable_data());
  return out;
}

py::array_t<double> matrix_array(const Eigen::Matrix3d& m) {
  py::array_t<double> out({py::ssize_t{3}, py::ssize_t{3}});
  auto view = out.mutable_unchecked<2>();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) view(r, c) = m(r, c);
  }
  return out;
}

namespace {

// The shape as numpy prints it: "(4, 2)".
std::string shape_text(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) text += (d > 0 ? ", " : "") + std::to_string(a.shape(d));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

template <typename T>
py::array_t<T, py::array::c_style | py::array::forcecast> rows_of_three(const py::handle& h, const std::string& what) {
  auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a) throw InputError(fmt::format("{}: not an array of numbers", what));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InputError(fmt::format("{}: must be an N x 3 array, not of shape {}", what, shape_text(a)));
  return a;
}

bool is_path(const py::handle& h) {
  return py::isinstance<py::str>(h) || py::hasattr(h, "__fspath__");
}

}  // namespace

std::vector<Eigen::Vector3d> points_from(const py::handle& array, const std::string& what) {
  const auto a = rows_of_three<double>(array, what);
  const auto view = a.unchecked<2>();
  std::vector<Eigen::Vector3d> out(static_cast<std::size_t>(view.shape(0)));
  for (py::ssize_t i = 0; i < view.shape(0); ++i) out[static_cast<std::size_t>(i)] = {view(i, 0), view(i, 1), view(i, 2)};
  return out;
}

TriangleMesh mesh_from(const py::handle& mesh, std::string& name) {
  if (is_path(mesh)) {
    name = py::str(py::module_::import("os").attr("fspath")(mesh)).cast<std::string>();
    return load_mesh(name);
  }
  if (!py::isinstance<py::sequence>(mesh) || py::len(mesh) != 2)
    throw InputError("mesh: give a file path or a pair (vertices V x 3, faces F x 3)");
  name = "<arrays>";
  const py::sequence pair = mesh.cast<py::sequence>();
  TriangleMesh out;
  out.vertices = points_from(pair[0], "mesh vertices");
  const auto faces = rows_of_three<std::int64_t>(pair[1], "mesh faces");
  const auto view = faces.unchecked<2>();
  const auto vertices = static_cast<std::int64_t>(out.vertices.size());
  for (py::ssize_t f = 0; f < view.shape(0); ++f) {
    std::array<std::uint32_t, 3> t{};
    for (py::ssize_t k = 0; k < 3; ++k) {
      if (view(f, k) < 0 || view(f, k) >= vertices)
        throw InputError(fmt::format("mesh faces: row {} names vertex {}; there are {} vertices", f, view(f, k), vertices));
      t[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(view(f, k));
    }
    out.triangles.push_back(t);
  }
  if (out.empty()) throw InputError("mesh faces: no triangles");
  return out;
}

void source_of(const py::handle& mesh, const TriangleMesh& loaded, std::string& path, std::string& sha256) {
  if (is_path(mesh)) {
    path = py::str(py::module_::import("os").attr("fspath")(mesh)).cast<std::string>();
    sha256 = sha256_file(path);
    return;
  }
  path = "<arrays>";
  std::string bytes(reinterpret_cast<const char*>(loaded.vertices.data()),
                    loaded.vertices.size() * sizeof(Eigen::Vector3d));
  bytes.append(reinterpret_cast<const char*>(loaded.triangles.data()),
               loaded.triangles.size() * sizeof(loaded.triangles[0]));
  sha256 = sha256_hex(bytes);
}

gpu::Backend backend_from(const std::string& text, const char* argument) {
  if (const auto backend = gpu::parse_backend(text)) return *backend;
  throw py::value_error(fmt::format("{}='{}': must be auto, gpu or cpu", argument, text));
}

std::unique_ptr<gpu::Context> context_for(std::initializer_list<gpu::Backend> stages) {
  const bool needed = std::any_of(stages.begin(), stages.end(), [](gpu::Backend b) { return b != gpu::Backend::Cpu; });
  if (!needed) return nullptr;
  return std::make_unique<gpu::Context>();
}

}  // namespace ts::python
