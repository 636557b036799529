#include "common.hpp"

#include "kincal/model/model.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "kincal C++ core (private: use the kincal package)";
  py::register_exception<kincal::InputError>(m, "InputError", PyExc_ValueError);
  define_effects(m);
  define_model(m);
  define_kinematics(m);
  define_compensation(m);
  define_io(m);
  define_controllers(m);
  define_feed(m);
  define_measurements(m);
  define_measurement_model(m);  // before identify: its records appear in identify's signatures
  define_identify(m);
  define_fivebar(m);
}
