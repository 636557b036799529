// Bindings of the effect registry (kincal/effects.hpp): the one list of effect names, their
// parameters and units, read by the Python package instead of lists of its own.
#include "common.hpp"

#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include <optional>

#include "kincal/effects/effects.hpp"
#include "kincal/identify/identify.hpp"
#include "kincal/model/model.hpp"

using namespace kincal;

void define_effects(py::module_& m) {
  py::class_<EffectKind>(m, "EffectKind", "One kind of effect of the registry")
      .def_readonly("name", &EffectKind::name)
      .def_readonly("domain", &EffectKind::domain, "'serial' or 'fivebar'")
      .def_readonly("concerns", &EffectKind::concerns, "'joint', 'link' or 'robot'")
      .def_readonly("needs", &EffectKind::needs, "the data column it reads: '', 'dir' or 'temperature_c'")
      .def_readonly("acts_on", &EffectKind::acts_on, "'joint_angle', 'length_scale' or 'link_length'")
      .def_readonly("description", &EffectKind::description)
      .def_readonly("gravity_loaded_only", &EffectKind::gravity_loaded_only)
      .def_readonly("harmonic", &EffectKind::harmonic, "sine and cosine amplitudes per harmonic order")
      .def_readonly("ordered", &EffectKind::ordered, "harmonic with every order 1..K, named by its order K")
      .def_property_readonly("reads_dir", &EffectKind::reads_dir, "reads the direction of motion (dir1..dirN)")
      .def_property_readonly("scales_lengths", &EffectKind::scales_lengths, "scales the robot's lengths")
      .def_property_readonly("of_instrument", &EffectKind::of_instrument,
                             "the measurement's (the instrument's drift), never applied to the robot")
      .def("__repr__", [](const EffectKind& k) { return "<EffectKind " + k.name + ">"; });
  m.def("effect_kinds", &effect_kinds, py::return_value_policy::copy, "Every effect kind, in the diagnosis's order");
  m.def("effect_kind", py::overload_cast<const std::string&>(&effect_kind), py::arg("name"), py::return_value_policy::copy);
  m.def(
      "joint_basis",
      [](const Effect& e, const Eigen::VectorXd& q_rad, std::optional<Eigen::VectorXd> dir) {
        if (!e.kind().basis) throw InputError(e.name + " is no joint-angle effect (it has no basis)");
        if (dir && dir->size() != q_rad.size()) throw InputError("joint_basis: one dir per angle");
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> b(q_rad.size(), e.size());
        for (Eigen::Index i = 0; i < q_rad.size(); ++i)
          joint_basis(e, q_rad[i], dir ? (*dir)[i] : 1.0, b.row(i).data());
        return b;
      },
      py::arg("effect"), py::arg("q_rad"), py::arg("dir") = py::none(),
      "The basis of a joint-angle effect at each angle (n x size): dq = sum_k p_k b_k(q, dir), the core's own");
  m.def(
      "link_basis",
      [](const Effect& e, const Eigen::VectorXd& t1_rad, const Eigen::VectorXd& t2_rad) {
        if (t1_rad.size() != t2_rad.size()) throw InputError("link_basis: one t2 per t1");
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> b(t1_rad.size(), e.size());
        for (Eigen::Index i = 0; i < t1_rad.size(); ++i) link_basis(e, t1_rad[i], t2_rad[i], b.row(i).data());
        return b;
      },
      py::arg("effect"), py::arg("t1_rad"), py::arg("t2_rad"),
      "The basis of a five-bar link-length effect at each pair of actuated angles (n x size): the link's\n"
      "length moves by sum_k p_k b_k(t1, t2) (mm), the core's own");

  py::class_<Effect>(m, "Effect", "An effect on one joint (or link), or on the whole robot")
      .def(py::init([](const std::string& name, int joint, std::vector<int> harmonics, int order) {
             const bool is_map = effect_kind(name).id == EffectId::joint_map;
             if (order != 0 && !is_map)
               throw InputError(name + " has no order (only joint_map has: its highest harmonic)");
             if (is_map) {
               if (order < 0 || order > 64) throw InputError("joint_map: the order must be 1..64, not " + std::to_string(order));
               if (order == 0) order = harmonics.empty() ? 0 : harmonics.back();
               Effect e = joint_map(joint - 1, order);
               if (e.harmonics != harmonics && harmonics != std::vector<int>{1, 2})
                 throw InputError("joint_map carries every harmonic order 1..K: give its order K");
               return e;
             }
             Effect e{name, joint - 1, std::move(harmonics)};
             if (!e.harmonic()) e.harmonics.clear();
             return e;
           }),
           py::arg("name"), py::arg("joint") = 0, py::arg("harmonics") = std::vector<int>{1, 2}, py::arg("order") = 0,
           "joint counted from 1; 0 for an effect on the whole robot; harmonics: transmission_error's orders; "
           "order: joint_map's order K (harmonics 1..K; default 2)")
      .def_readonly("name", &Effect::name)
      .def_property_readonly("kind", [](const Effect& e) { return e.kind(); }, "its kind in the registry")
      .def_property_readonly("joint", [](const Effect& e) { return e.joint + 1; }, "from 1; 0: the whole robot")
      .def_readonly("harmonics", &Effect::harmonics)
      .def_property_readonly("order", &Effect::order, "joint_map: its order K; 0 for the others")
      .def_property_readonly("size", &Effect::size)
      .def_property_readonly("label", &Effect::label)
      .def_property_readonly("parameter_names", &Effect::parameter_names)
      .def_property_readonly("units", &Effect::units, "core units (angles in rad)")
      .def_property_readonly("file_units", &Effect::file_units, "units in model files (angles in deg)")
      .def_property_readonly("file_scale", &Effect::file_scale, "file value = core value * scale")
      .def("check", [](const Effect& e, int dof) { check_effect(e, dof, ""); }, py::arg("dof"))
      .def(py::self == py::self)
      .def("__hash__",
           [](const Effect& e) {
             // consistent with ==: the harmonic orders count for transmission_error and joint_map only
             py::tuple h = py::tuple(py::cast(e.harmonic() ? e.harmonics : std::vector<int>{}));
             return py::hash(py::make_tuple(e.name, e.joint, h));
           })
      .def("__repr__", [](const Effect& e) { return "<Effect " + e.label() + ">"; });
}
