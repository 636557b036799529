// Shared declarations of the _core bindings: one define_<area> per area, gathered in module.cpp,
// and the helpers several areas use.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>

namespace py = pybind11;

namespace kincal {
struct MeasurementSet;
struct Campaign;
class Robot;
}

void define_effects(py::module_& m);
void define_model(py::module_& m);
void define_kinematics(py::module_& m);
void define_compensation(py::module_& m);
void define_io(py::module_& m);
void define_controllers(py::module_& m);
void define_feed(py::module_& m);
void define_measurements(py::module_& m);
void define_measurement_model(py::module_& m);
void define_identify(py::module_& m);
void define_fivebar(py::module_& m);

/// The campaign of a robot's calibrated (or nominal) model: the robot's own, but for the nominal
/// model of an identified robot (then the identity placement: that campaign calibrated the other
/// model). Fits start from it, fk(instrument=True) sees through it (measurement_model.cpp).
const kincal::Campaign& campaign_of(const kincal::Robot& robot, bool calibrated);

/// A measurement set as its columns (a dict of numpy arrays), and back (measurements.cpp).
py::dict measurements_to_dict(const kincal::MeasurementSet& m, int dof);
kincal::MeasurementSet measurements_from_dict(const py::dict& d, int dof);

/// The class MeasurementSet of Python: the core's rows, never changed after construction, and their
/// columns as read-only numpy arrays, made on first use (measurements.cpp). A dict of columns converts
/// to it wherever a binding takes one.
struct PyMeasurementSet {
  std::shared_ptr<const kincal::MeasurementSet> set;
  int dof = 0;                  ///< joint angles per row
  mutable py::object columns;   ///< None until asked: the dict of read-only columns
  /// The rows, for a robot of `robot_dof` joints: InputError naming the source when they have another count.
  const kincal::MeasurementSet& of_dof(int robot_dof) const;
};
PyMeasurementSet measurement_set(kincal::MeasurementSet&& m, int dof);
/// The set a binding is given: a MeasurementSet, or a dict of columns made into one here (so that
/// the dict's errors, file and cause, reach Python as they are).
PyMeasurementSet set_arg(const py::handle& data);

inline void dict_put(py::dict&) {}

template <class T, class... Rest>
void dict_put(py::dict& d, const char* key, const T& value, const Rest&... rest) {
  d[key] = value;
  dict_put(d, rest...);
}

/// A dict of named values, Eigen vectors and matrices as numpy arrays: dict_of("id", id, "line",
/// line). Records cross the boundary so (measurement sets, five-bar points).
template <class... KeyValues>
py::dict dict_of(const KeyValues&... key_values) {
  py::dict d;
  dict_put(d, key_values...);
  return d;
}
