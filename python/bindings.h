#pragma once
// The parts of the `tetrasand` module, each registered by its own file: bodies and sampling
// (body_binding.cpp), fields (sdf_binding.cpp), scenes (scene_binding.cpp). module.cpp holds the
// exceptions and calls these.
#include <pybind11/pybind11.h>

namespace ts::python {

void add_body_bindings(pybind11::module_& m);
void add_sdf_bindings(pybind11::module_& m);
void add_scene_bindings(pybind11::module_& m);

}  // namespace ts::python
