// Shared declarations of the _core bindings: one define_<area> per area, gathered in module.cpp.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace py = pybind11;

void define_effects(py::module_& m);
void define_model(py::module_& m);
void define_kinematics(py::module_& m);
void define_compensation(py::module_& m);
void define_io(py::module_& m);
void define_feed(py::module_& m);
void define_identify(py::module_& m);
void define_fivebar(py::module_& m);
