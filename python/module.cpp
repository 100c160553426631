// The `tetrasand` Python module's compiled part, tetrasand._core: the bindings (bindings.h) and the
// library's errors as Python exceptions carrying the command line's messages (file, line, key).
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include "core/error.h"
#include "gpu/shader_library.h"
#include "python/bindings.h"
#include "sdf/openvdb_init.h"

namespace py = pybind11;

namespace {

// ts::Error and its kinds. pybind11 tries the translators registered last first, so the base class
// comes first: a GpuError is caught as GpuError, an Error of any other kind as tetrasand.Error.
void add_exceptions(py::module_& m) {
  const auto base = py::register_exception<ts::Error>(m, "Error", PyExc_RuntimeError);
  base.doc() = "An error of tetrasand's library; the message is the command line's";
  const auto input = py::register_exception<ts::InputError>(m, "InputError", PyExc_ValueError);
  input.doc() = "Bad input: the message names the file (line and key where there are) and the problem";
  const auto gpu = py::register_exception<ts::GpuError>(m, "GpuError", base.ptr());
  gpu.doc() = "No usable GL 4.5 context, or the GPU failed";
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "tetrasand: triangle meshes to narrow-band SDFs, particle rigid bodies and sand simulations";
  add_exceptions(m);
  ts::sdf::ensure_openvdb_initialized();
  m.def("_set_shader_root", &ts::gpu::ShaderLibrary::set_host_root, py::arg("root"),
        "Where the kernels are when TETRASAND_SHADER_DIR is not set (the package's __init__ calls it)");
  m.def("_shader_root", [] { return ts::gpu::ShaderLibrary::default_root(); },
        "The folder the kernels are read from now (TETRASAND_SHADER_DIR, else the package's)");
  ts::python::add_body_bindings(m);
  ts::python::add_sdf_bindings(m);
  ts::python::add_scene_bindings(m);
}
