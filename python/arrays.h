#pragma once
// What the Python module's bindings share: numpy arrays to and from Eigen, the mesh argument (a path or
// a (vertices, faces) pair of arrays), the backend argument, and a GL context made only when a stage
// runs on the GPU (gpu/backend.h's rule, as every command applies it).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "gpu/backend.h"
#include "gpu/context.h"

namespace ts::python {

namespace py = pybind11;

// An N x 3 float64 array of the points (a copy).
template <typename Vector>
py::array_t<double> points_array(const std::vector<Vector>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto view = out.template mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < view.shape(0); ++i) {
    for (py::ssize_t k = 0; k < 3; ++k) view(i, k) = static_cast<double>(points[static_cast<std::size_t>(i)][k]);
  }
  return out;
}
py::array_t<double> vector_array(const Eigen::Vector3d& v);
py::array_t<double> matrix_array(const Eigen::Matrix3d& m);
// An N x 3 array (anything numpy converts to float64) as points; `what` names it in the error.
std::vector<Eigen::Vector3d> points_from(const py::handle& array, const std::string& what);

// The mesh argument: a path (str or os.PathLike) is loaded as `tetrasand sample` loads it; a pair
// (vertices V x 3, faces F x 3 integer) is taken as it is. `name` gets what messages and body.json
// call it: the path, or "<arrays>".
TriangleMesh mesh_from(const py::handle& mesh, std::string& name);
// The source of a body made from `mesh`: its path and the SHA-256 of the file, or, for arrays, of the
// vertex and face bytes (body.json records one either way).
void source_of(const py::handle& mesh, const TriangleMesh& loaded, std::string& path, std::string& sha256);

// "auto", "gpu" or "cpu"; ValueError naming the argument otherwise.
gpu::Backend backend_from(const std::string& text, const char* argument);
// A GL context when any of `stages` asks for more than the CPU (auto asks the device), else none.
std::unique_ptr<gpu::Context> context_for(std::initializer_list<gpu::Backend> stages);

}  // namespace ts::python
