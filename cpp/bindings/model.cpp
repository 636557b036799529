#include "common.hpp"

#include "kincal/identify/simulate.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/io/model_json.hpp"
#include "kincal/model/coverage.hpp"
#include "kincal/model/model.hpp"
#include "kincal/model/robots.hpp"

#include <array>
#include <tuple>
#include <optional>

using namespace kincal;

namespace {

// What a robot's calibrated model and its campaign carry besides the geometry (placements, tool
// frame, the angles its fit saw, effects' data needs), and the robots made from one with those changed.
void define_robot_calibration(py::class_<Robot>& robot) {
  robot.def_property_readonly("t_ref_c", [](const Robot& r) { return r.calibrated()->spec().t_ref_c; })
      .def_property_readonly(
          "placements",
          [](const Robot& r) {
            std::vector<std::tuple<std::string, Vec3, Vec3>> out;
            const Campaign& s = r.campaign();
            if (s.setups.empty()) out.emplace_back("", s.base_in_instrument.xyz, s.base_in_instrument.abc);
            for (const SetupFrame& f : s.setups) out.emplace_back(f.name, f.base_in_instrument.xyz, f.base_in_instrument.abc);
            return out;
          },
          "the instrument placements the robot's campaign knows: (name, xyz_mm, abc_deg) per setup; one\n"
          "named '' (its base_in_instrument) without setups. fk and compensate use the first.")
      .def_property_readonly("nominal_spec", [](const Robot& r) { return r.nominal()->spec(); })
      .def_property_readonly("calibrated_spec", [](const Robot& r) { return r.calibrated()->spec(); })
      .def(
          "with_tool",
          [](const Robot& r, const Vec3& xyz_mm, const Vec3& abc_deg, const std::string& tcp) {
            ModelSpec s = r.calibrated()->spec();
            s.tool = Pose6{xyz_mm, abc_deg};
            s.tcp = tcp;
            return Robot{r.nominal(), std::make_shared<Model>(s), r.campaign()};
          },
          py::arg("xyz_mm"), py::arg("abc_deg"), py::arg("tcp"),
          "The robot whose calibrated model has this tool frame, its origin recorded as tcp ('measured', "
          "'tool-targets', 'nominal')")
      .def("nominal_only",
           [](const Robot& r) { return r.identified() ? Robot{r.nominal(), r.nominal()} : r; },
           "The robot with its nominal model as its calibrated one (not identified; the campaign that\n"
           "calibrated it left out)")
      .def_property_readonly("t_mean_s", [](const Robot& r) { return r.campaign().t_mean_s; },
                             "the drift's reference time (s), when the campaign's instrument drifts")
      .def(
          "with_placements",
          [](const Robot& r, const std::vector<std::tuple<std::string, Vec3, Vec3>>& setups) {
            if (setups.empty()) throw InputError("with_placements: at least one placement");
            Campaign c = r.campaign();
            c.base_in_instrument = Pose6{std::get<1>(setups[0]), std::get<2>(setups[0])};
            c.setups.clear();
            if (setups.size() > 1)
              for (const auto& [name, xyz, abc] : setups) c.setups.push_back(SetupFrame{name, Pose6{xyz, abc}});
            // a nominal robot seen from placements becomes a calibrated one (as it always did): its
            // nominal model keeps the identity placement
            return Robot{r.nominal(), r.identified() ? r.calibrated() : std::make_shared<Model>(r.calibrated()->spec()), c};
          },
          py::arg("setups"),
          "The robot with its campaign seen from these placements: (name, xyz_mm, abc_deg) per setup, the\n"
          "first its base_in_instrument (one: no setups)")
      .def_property_readonly("tcp", [](const Robot& r) { return r.calibrated()->spec().tcp; },
                             "where the calibrated model's tool frame comes from: 'measured' (6-D rows), "
                             "'tool-targets', 'nominal' (reflectors only), '' when not recorded")
      .def("tcp_warning", [](const Robot& r, const std::string& source) { return tcp_warning(r, source); },
           py::arg("source"),
           "The one warning line for a model whose TCP is nominal (not measured), naming source; '' otherwise")
      .def_property_readonly("fitted_ranges_deg", [](const Robot& r) { return r.campaign().fitted_deg; },
                             "per joint, the angles the identification saw ([lo, hi] deg); empty when unknown")
      .def(
          "with_fitted_ranges",
          [](const Robot& r, const std::vector<JointRange>& ranges) {
            if (!r.identified()) throw InputError("with_fitted_ranges: a nominal robot was fitted on nothing");
            if (!ranges.empty()) check_joint_ranges(ranges, r.calibrated()->dof(), "with_fitted_ranges");
            Campaign c = r.campaign();
            c.fitted_deg = ranges;
            return Robot{r.nominal(), r.calibrated(), c};
          },
          py::arg("ranges"), "The robot whose campaign records the angles its fit saw (joint_ranges())");
}

// What the calibrated model's effects need, and the robots made with effects or errors added.
void define_robot_effects(py::class_<Robot>& robot) {
  robot.def_property_readonly("needs_dir", [](const Robot& r) { return r.calibrated()->needs_dir(); },
                             "backlash: the direction of motion into each pose is needed")
      .def_property_readonly("needs_temperature", [](const Robot& r) { return r.calibrated()->needs_temperature(); },
                             "thermal expansion: the temperature is needed")
      .def(
          "with_effects",
          [](const Robot& r, const std::vector<std::pair<Effect, std::vector<double>>>& effects, double t_ref) {
            std::vector<EffectValue> ev;
            Campaign c = r.campaign();
            for (const auto& [e, p] : effects) {
              ev.push_back(EffectValue{e, p});
              if (!e.kind().of_instrument()) continue;  // the campaign's instrument drifts
              if (c.drift) throw InputError("with_effects: the instrument's drift is given twice");
              c.drift = ev.back();
            }
            return Robot{r.nominal(), std::make_shared<Model>(with_effects(r.calibrated()->spec(), ev, t_ref)), c};
          },
          py::arg("effects"), py::arg("t_ref") = 20.0,
          "The robot with effects (Effect, values in core units) added to its calibrated model (a drift\n"
          "to its campaign)")
      .def(
          "with_calibrated",
          [](const Robot& r, unsigned seed, double sigma_mm, double sigma_deg, double compliance,
             std::optional<std::array<double, 6>> instrument) {
            ModelSpec s = perturbed_spec(r.nominal()->spec(), seed, sigma_mm, sigma_deg, compliance);
            Campaign c = campaign_of(r, false);  // the nominal model's placement, unless given
            if (instrument) {
              const auto& v = *instrument;
              c.base_in_instrument.xyz = Vec3(v[0], v[1], v[2]);
              c.base_in_instrument.abc = Vec3(v[3], v[4], v[5]);
            }
            return Robot{r.nominal(), std::make_shared<Model>(s), c};
          },
          py::arg("seed"), py::arg("sigma_mm") = 1.0, py::arg("sigma_deg") = 0.05, py::arg("compliance") = 0.0,
          py::arg("base_in_instrument") = py::none(),
          "A robot whose calibrated model has simulated manufacturing errors (for simulations and demos)");
}

// A model's definition as Python reads it (read-only: a Robot's with_... methods make changed ones).
void define_specs(py::module_& m) {
  py::class_<Pose6>(m, "Pose6", "A frame: its origin (mm) and KUKA ABC angles (deg)")
      .def_property_readonly("xyz_mm", [](const Pose6& p) { return Vec3(p.xyz); })
      .def_property_readonly("abc_deg", [](const Pose6& p) { return Vec3(p.abc); });
  py::class_<JointSpec>(m, "JointSpec", "One joint of a model (base frame, zero configuration; read-only)")
      .def_readonly("name", &JointSpec::name)
      .def_property_readonly("point_mm", [](const JointSpec& j) { return Vec3(j.point); }, "a point of the axis")
      .def_property_readonly("axis", [](const JointSpec& j) { return Vec3(j.axis); })
      .def_readonly("lower_deg", &JointSpec::lower_deg)
      .def_readonly("upper_deg", &JointSpec::upper_deg)
      .def_readonly("max_velocity_deg_s", &JointSpec::max_velocity_deg_s, "0: unknown")
      .def_readonly("max_acceleration_deg_s2", &JointSpec::max_acceleration_deg_s2, "0: unknown")
      .def_readonly("max_jerk_deg_s3", &JointSpec::max_jerk_deg_s3, "0: unknown")
      .def_readonly("mass_kg", &JointSpec::mass_kg, "the link this joint moves")
      .def_property_readonly("com_mm", [](const JointSpec& j) { return Vec3(j.com); }, "its centre of mass")
      .def_readonly("compliance_deg_per_knm", &JointSpec::compliance_deg_per_knm);
  py::class_<ModelSpec>(m, "ModelSpec", "What defines one robot geometry (read-only)")
      .def_readonly("name", &ModelSpec::name)
      .def_readonly("joints", &ModelSpec::joints)
      .def_readonly("tool", &ModelSpec::tool, "the tool (TCP) frame in the base frame at zero configuration")
      .def_readonly("payload_kg", &ModelSpec::payload_kg)
      .def_property_readonly("payload_com_mm", [](const ModelSpec& s) { return Vec3(s.payload_com); },
                             "in the tool frame")
      .def_property_readonly("gravity", [](const ModelSpec& s) { return Vec3(s.gravity); }, "base frame, m/s^2")
      .def_readonly("home_deg", &ModelSpec::home_deg)
      .def_readonly("joint_convention", &ModelSpec::joint_convention)
      .def_readonly("tcp", &ModelSpec::tcp, "where the tool frame comes from ('' when not recorded)");
}

}  // namespace

void define_model(py::module_& m) {
  define_specs(m);
  py::class_<Robot> robot(m, "Robot", "A robot: nominal geometry and calibrated geometry (immutable)");
  robot.def_static("load", &load_robot, py::arg("name_or_path"), "A built-in name or a model JSON file")
      .def_static("from_json", &robot_from_json, py::arg("text"), py::arg("source") = "<json>")
      .def("to_json", [](const Robot& r) { return robot_to_json(r); })
      .def("with_joint_convention", [](const Robot& r, const std::string& source, const std::string& convention) {
             return with_joint_convention(r, source, convention);
           }, py::arg("source"), py::arg("convention"),
           "The robot read from source numbered as its controller numbers the joints (fanuc; '': the model's own); "
           "a model JSON carries its own")
      .def_property_readonly("dof", [](const Robot& r) { return r.nominal()->dof(); })
      .def_property_readonly("identified", &Robot::identified)
      .def_property_readonly("name", [](const Robot& r) { return r.nominal()->spec().name; })
      .def_property_readonly("compliance_count", [](const Robot& r) { return r.nominal()->compliance_count(); })
      .def_property_readonly("geometric_parameter_count", [](const Robot& r) { return 4 * r.nominal()->dof() + 6; })
      .def_property_readonly("closed_form_ik",
                             [](const Robot& r) { return r.ik().structure().spherical_wrist_parallel_23; })
      .def_property_readonly("ik_reason", [](const Robot& r) { return r.ik().structure().reason; })
      .def_property_readonly("home_deg", [](const Robot& r) { return r.nominal()->spec().home_deg; })
      .def_property_readonly("limits_deg",
                             [](const Robot& r) {
                               std::vector<std::pair<double, double>> l;
                               for (const auto& j : r.nominal()->spec().joints) l.emplace_back(j.lower_deg, j.upper_deg);
                               return l;
                             })
      .def_property_readonly(
          "effects",
          [](const Robot& r) {
            py::list l;
            for (const auto& ev : r.calibrated()->spec().effects) l.append(py::make_tuple(ev.effect, ev.p));
            if (r.campaign().drift) l.append(py::make_tuple(r.campaign().drift->effect, r.campaign().drift->p));
            return l;
          },
          "the calibrated model's effects besides compliance, then its campaign's drift: (Effect, values in\n"
          "core units)");
  define_robot_calibration(robot);
  define_robot_effects(robot);
  m.def("builtin_names", &builtin_names);

  py::class_<Extrapolation>(m, "Extrapolation",
                            "A joint whose periodic effects rows of joint angles ask for outside the angles they were "
                            "fitted on (extrapolated())")
      .def_readonly("joint", &Extrapolation::joint, "counted from 1")
      .def_readonly("effects", &Extrapolation::effects, "the joint's periodic effects, e.g. 'joint_map(joint 1)'")
      .def_readonly("fitted_deg", &Extrapolation::fitted, "the fitted range [lo, hi] (deg)")
      .def_readonly("rows", &Extrapolation::rows, "rows outside it")
      .def_readonly("first", &Extrapolation::first, "the first of them (0-based)")
      .def("message", &extrapolation_message, py::arg("total"), py::arg("noun") = "rows",
           "the warning in words: 'joint 1 is outside the -180..-45 deg its ...'");
  m.def(
      "joint_ranges", [](const RowMatrix& q_deg) { return joint_ranges(q_deg.data(), q_deg.rows(), q_deg.cols()); },
      py::arg("q_deg"),
      "Per joint, the range [lo, hi] (deg) of rows of joint angles: the shortest arc of the circle that holds\n"
      "every angle (modulo 360 deg), lo in [-180, 180); [-180, 180] when no gap is wider than 10 deg");
  m.def(
      "outside_range",
      [](const Eigen::VectorXd& q_deg, const JointRange& range) {
        std::vector<bool> out(static_cast<size_t>(q_deg.size()));
        for (Eigen::Index i = 0; i < q_deg.size(); ++i) out[static_cast<size_t>(i)] = outside_range(q_deg[i], range);
        return out;
      },
      py::arg("q_deg"), py::arg("range"), "angles (deg, any turn) more than 1 deg outside a range [lo, hi]");
  m.def(
      "extrapolated",
      [](const Robot& r, const RowMatrix& q_deg) {
        if (q_deg.rows() > 0 && q_deg.cols() != r.calibrated()->dof())
          throw InputError("extrapolated: " + std::to_string(q_deg.cols()) + " joint columns for a robot of " +
                           std::to_string(r.calibrated()->dof()));
        return extrapolated(r.calibrated()->spec(), r.campaign().fitted_deg, q_deg.data(), q_deg.rows(),
                            r.calibrated()->dof());
      },
      py::arg("robot"), py::arg("q_deg"),
      "The joints whose periodic effects (transmission_error, joint_map) rows of joint angles (deg) take\n"
      "outside the ranges the calibrated model was fitted on (none when it carries no ranges)");
}
