// Bindings of simulated campaigns, the identification's measurement model and identify(). Measurement
// sets cross the boundary as dicts of numpy arrays (measurements.cpp).
#include "common.hpp"

#include <algorithm>
#include <numeric>
#include <optional>
#include <tuple>

#include "kincal/identify/identifiability.hpp"
#include "kincal/identify/identify.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/model/model.hpp"

using namespace kincal;

namespace {

std::vector<EffectValue> effect_values_from(const std::vector<std::pair<Effect, std::vector<double>>>& e) {
  std::vector<EffectValue> out;
  for (const auto& [effect, p] : e) {
    if (static_cast<int>(p.size()) != effect.size())
      throw InputError(effect.label() + ": " + std::to_string(effect.size()) + " value(s) needed, " +
                       std::to_string(p.size()) + " given");
    out.push_back(EffectValue{effect, p});
  }
  return out;
}

py::list effect_values_to(const std::vector<EffectValue>& e) {
  py::list l;
  for (const auto& v : e) l.append(py::make_tuple(v.effect, v.p));
  return l;
}

/// Joint numbers from 1 (Python) to indices from 0 (the core), and back.
std::vector<int> joints_from_one(const std::vector<int>& joints) {
  std::vector<int> j;
  for (int k : joints) j.push_back(k - 1);
  return j;
}

std::vector<int> joints_to_one(const std::vector<int>& joints) {
  std::vector<int> j;
  for (int k : joints) j.push_back(k + 1);
  return j;
}

std::vector<Vec3> targets_from(const RowMatrix& t) {
  std::vector<Vec3> v;
  for (int i = 0; i < t.rows(); ++i) v.emplace_back(t(i, 0), t(i, 1), t(i, 2));
  return v;
}

RowMatrix targets_to(const std::vector<Vec3>& v) {
  RowMatrix t(v.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) t.row(i) = v[i].transpose();
  return t;
}

/// One parameter of the identification vector, described for Python (no name parsing there).
struct Parameter {
  std::string name, kind, unit;
  int joint = 0;    ///< from 1; 0 when the parameter concerns no joint (or link)
  int target = -1;  ///< from 0; -1 when not a target offset
  int setup = -1;   ///< the setup (code, from 0) of a base frame parameter; -1 for the others
  std::string setup_name;  ///< its name ("" with a single setup)
  int index = 0;
  std::optional<Effect> effect;  ///< the effect (of the layout's effect list) it belongs to
};

std::vector<Parameter> parameters_of(const ParamLayout& L) {
  std::vector<Parameter> out;
  for (int i = 0; i < L.size; ++i) {
    Parameter p;
    p.name = L.names[i];
    p.unit = L.units[i];
    p.index = i;
    if (i < L.compliance) {
      p.kind = "joint_geometry";
      p.joint = (i - L.joints) / 4 + 1;
    } else if (i < L.moments) {
      p.kind = "compliance";
      p.joint = L.loaded[i - L.compliance] + 1;
    } else if (i < L.tool) {
      p.kind = "gravity_moment";
      p.joint = L.moment_links[(i - L.moments) / 2] + 1;
    } else if (i < L.base) {
      p.kind = "tool";
    } else if (i < L.targets) {
      p.kind = "base";
      p.setup = (i - L.base) / 6;
      if (!L.setup_names.empty()) p.setup_name = L.setup_names[static_cast<size_t>(p.setup)];
    } else if (i < L.effects) {
      p.kind = "target";
      p.target = (i - L.targets) / 3;
    } else if (i >= L.stations) {
      p.kind = "station";
    } else {
      for (size_t e = 0; e < L.effect_list.size(); ++e)
        if (i >= L.effect_offset[e] && i < L.effect_offset[e] + L.effect_list[e].size()) {
          p.kind = L.effect_list[e].name;
          p.joint = L.effect_list[e].joint + 1;
          p.effect = L.effect_list[e];
        }
    }
    out.push_back(p);
  }
  return out;
}

/// The identification result with the robots Python sees (nominal + calibrated).
struct PyIdentifyResult {
  IdentifyResult r;
  Robot robot, nominal_fitted;
};

py::array_t<double> vec(const std::vector<double>& v) { return py::array_t<double>(v.size(), v.data()); }

/// Every instrument placement of a campaign: [(name, xyz_mm, abc_deg)], its base_in_instrument (name
/// "") when it has no setups.
std::vector<std::tuple<std::string, Vec3, Vec3>> placements(const Campaign& s) {
  std::vector<std::tuple<std::string, Vec3, Vec3>> out;
  if (s.setups.empty()) out.emplace_back("", s.base_in_instrument.xyz, s.base_in_instrument.abc);
  for (const SetupFrame& f : s.setups) out.emplace_back(f.name, f.base_in_instrument.xyz, f.base_in_instrument.abc);
  return out;
}


/// joint_compliance effects in the options' effect list are the compliance switches of the core
IdentifyOptions core_options(IdentifyOptions o, const Model& model) {
  std::vector<Effect> rest;
  bool any = false;
  std::vector<int> joints;
  for (const Effect& e : o.effects) {
    if (!e.kind().gravity_loaded_only) {
      rest.push_back(e);
      continue;
    }
    check_effect(e, model.dof(), "");
    if (!model.gravity_loaded(e.joint))
      throw InputError("joint_compliance: gravity does not load joint " + std::to_string(e.joint + 1) +
                       " of this robot (its axis is vertical)");
    any = true;
    joints.push_back(e.joint);
  }
  if (any) {
    if (!o.compliance) o.compliance_joints.clear();
    o.compliance = true;
    // the joints named: exactly those (with any compliance_joints given too)
    for (int j : joints)
      if (std::find(o.compliance_joints.begin(), o.compliance_joints.end(), j) == o.compliance_joints.end())
        o.compliance_joints.push_back(j);
  }
  o.effects = rest;
  return o;
}


void define_identify_functions(py::module_& m) {
  m.def("default_prior_sd", &default_prior_sd,
        "The priors' default standard deviations by kind, in the core's units (mm, rad): the one home of "
        "these defaults");
  py::class_<SimulationOptions>(m, "SimulationOptions", "A tracker campaign to simulate (simulate)")
      .def(py::init<>())
      .def_readwrite("poses", &SimulationOptions::poses, "random configurations within the joint limits")
      .def_readwrite("seed", &SimulationOptions::seed)
      .def_readwrite("noise_mm", &SimulationOptions::noise_mm, "Gaussian noise per coordinate (mm)")
      .def_readwrite("outlier_fraction", &SimulationOptions::outlier_fraction, "share of rows with a gross error")
      .def_readwrite("outlier_mm", &SimulationOptions::outlier_mm, "size of a gross error (mm)")
      .def_property(
          "targets", [](const SimulationOptions& o) { return targets_to(o.targets); },
          [](SimulationOptions& o, const RowMatrix& t) {
            if (t.cols() != 3 || t.rows() < 1) throw InputError("simulate: targets are rows of x, y, z (mm)");
            o.targets = targets_from(t);
          },
          "target offsets in the tool frame (mm, one row each)")
      .def_readwrite("limit_margin", &SimulationOptions::limit_margin, "poses drawn in this share of each range")
      .def_property(
          "effects", [](const SimulationOptions& o) { return effect_values_to(o.effects); },
          [](SimulationOptions& o, const std::vector<std::pair<Effect, std::vector<double>>>& e) {
            o.effects = effect_values_from(e);
          },
          "effects hidden in the truth: (Effect, values in core units)")
      .def_readwrite("t_ref", &SimulationOptions::t_ref, "reference temperature of thermal_expansion (deg C)")
      .def_readwrite("t_min", &SimulationOptions::t_min, "the temperature drifts from this (deg C) ...")
      .def_readwrite("t_max", &SimulationOptions::t_max, "... to this over the campaign")
      .def_readwrite("orientation_noise_deg", &SimulationOptions::orientation_noise_deg,
                     ">= 0: the first target's rows are 6-D with this noise per axis (deg); -1: points")
      .def_readwrite("duration_s", &SimulationOptions::duration_s,
                     "> 0: rows get time_s, the campaign running from 0 to this (s)");
  m.def(
      "simulate",
      [](const Robot& truth, const SimulationOptions& o) {
        return measurement_set(simulate(*truth.calibrated(), o, truth.campaign()), truth.calibrated()->dof());
      },
      py::arg("truth"), py::arg("options") = SimulationOptions{},
      "A measurement campaign on the calibrated (true) model of a robot, seen through its campaign (a\n"
      "hidden drift without a duration: 3 h, centred on the mean time)");
  m.def(
      "point_errors",
      [](const Robot& r, const RowMatrix& targets, const py::object& d, const std::vector<StationValue>& stations) {
        const auto e = point_errors(*r.calibrated(), r.campaign(), targets_from(targets),
                                    set_arg(d).of_dof(r.calibrated()->dof()),
                                    stations);
        return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(e.data(), e.size()));
      },
      py::arg("robot"), py::arg("targets"), py::arg("data"), py::arg("stations") = std::vector<StationValue>{},
      "Distance (mm) between every measured point and the calibrated model's prediction (its effects acting,\n"
      "each row seen from its setup's placement, the campaign's drift at the row's time); a probe row's error\n"
      "along its constraint against its station among `stations` (NaN when not among them)");
  m.def(
      "check_effect_columns",
      [](const Robot& r, const py::object& d, const std::vector<Effect>& effects) {
        check_effect_columns(*r.nominal(), set_arg(d).of_dof(r.nominal()->dof()), effects);
      },
      py::arg("robot"), py::arg("data"), py::arg("effects"),
      "ValueError (file:line of the first row without it) unless the data carry every column the effects\n"
      "read (the registry's needs: temperature_c, time_s, dir1..dirN)");
  m.def(
      "orientation_errors",
      [](const Robot& r, const py::object& d) {
        const auto e = orientation_errors(*r.calibrated(), r.campaign(), set_arg(d).of_dof(r.calibrated()->dof()));
        return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(e.data(), e.size()));
      },
      py::arg("robot"), py::arg("data"),
      "Angle (deg) between every measured orientation (the 6-D rows, in order; reflector rows left out) and\n"
      "the calibrated model's (its effects acting, each row seen from its setup's placement at its time)");

  py::class_<Parameter>(m, "Parameter", "One parameter of the identification vector")
      .def_readonly("name", &Parameter::name, "e.g. 'joint3.tilt_u', 'base.ry', 'joint2.te_sin1'")
      .def_readonly("kind", &Parameter::kind,
                    "'joint_geometry', 'compliance', 'gravity_moment', 'tool', 'base', 'target' or the effect's name")
      .def_readonly("joint", &Parameter::joint, "joint (or link) from 1; 0 when none")
      .def_readonly("target", &Parameter::target, "target from 0; -1 when none")
      .def_readonly("setup", &Parameter::setup, "setup code (from 0) of a base frame parameter; -1 for the others")
      .def_readonly("setup_name", &Parameter::setup_name, "its setup's name ('' with a single setup)")
      .def_readonly("unit", &Parameter::unit, "'rad', 'mm', 'deg/kNm', '1/degC'")
      .def_readonly("index", &Parameter::index, "position in the parameter vector")
      .def_readonly("effect", &Parameter::effect, "the effect it belongs to (None for the others)")
      .def("__repr__", [](const Parameter& p) { return "<Parameter " + std::to_string(p.index) + " " + p.name + ">"; });
}

void define_param_layout(py::module_& m) {
  py::class_<ParamLayout> layout(m, "ParamLayout", "Layout of the identification parameter vector");
  // its sizes, and the offsets of the parts of the vector in their order
  const std::tuple<const char*, int ParamLayout::*, const char*> sizes_and_offsets[] = {
      {"dof", &ParamLayout::dof, "number of joints"},
      {"n_targets", &ParamLayout::n_targets, "number of targets"},
      {"n_setups", &ParamLayout::n_setups, "number of instrument placements (6 base parameters each)"},
      {"drift", &ParamLayout::drift, "offset of the drift's 6 parameters (-1: none)"},
      {"size", &ParamLayout::size, "number of parameters"},
      {"joints", &ParamLayout::joints, "offset of the joint geometry (4 per joint)"},
      {"compliance", &ParamLayout::compliance, "offset of the compliances (1 per gravity-loaded joint)"},
      {"moments", &ParamLayout::moments, "offset of the fitted gravity's mass moments (2 per link; none with masses)"},
      {"tool", &ParamLayout::tool, "offset of the tool frame (6)"},
      {"base", &ParamLayout::base, "offset of the base frames in the instrument frame (6 per setup)"},
      {"targets", &ParamLayout::targets, "offset of the target offsets (3 per target)"},
      {"effects", &ParamLayout::effects, "offset of the extra effects' parameters"}};
  for (const auto& [name, field, doc] : sizes_and_offsets) layout.def_readonly(name, field, doc);
  layout
      .def_readonly("effect_list", &ParamLayout::effect_list, "the extra effects, in order")
      .def_readonly("effect_offset", &ParamLayout::effect_offset, "offset of each extra effect")
      .def_readonly("t_ref", &ParamLayout::t_ref, "reference temperature of thermal_expansion (degC)")
      .def_readonly("t_mean", &ParamLayout::t_mean, "reference time of the drift (s)")
      .def_readonly("setup_names", &ParamLayout::setup_names, "the setups by code (empty: a single one)")
      .def_readonly("stations", &ParamLayout::stations, "offset of the probe stations' parameters (3 each)")
      .def_readonly("station_names", &ParamLayout::station_names, "the probe stations by code")
      .def_property_readonly("station_kinds", [](const ParamLayout& L) {
             std::vector<std::string> k;
             for (MeasureKind s : L.station_kinds) k.emplace_back(to_string(s));
             return k;
           }, "'sphere', 'plane' or 'distance' per station")
      .def_readonly("station_normals", &ParamLayout::station_normals,
                    "every station's reference normal (planes: their tilts are from it)")
      .def_property_readonly("gravity", [](const ParamLayout& L) { return L.fit_gravity ? "fit" : "masses"; },
                             "where the compliances' gravity torques come from: 'masses' (the model's) or 'fit'")
      .def_property_readonly("loaded", [](const ParamLayout& L) { return joints_to_one(L.loaded); },
                             "joints (from 1) with a compliance parameter: the gravity-loaded ones")
      .def_readonly("names", &ParamLayout::names, "one per parameter, e.g. 'joint3.tilt_u', 'base.ry'")
      .def_readonly("units", &ParamLayout::units, "one per parameter: 'rad', 'mm', 'deg/kNm', ...")
      .def_property_readonly("parameters", &parameters_of)
      .def(
          "indices",
          [](const ParamLayout& L, const std::string& kind, int joint) {
            std::vector<int> out;
            for (const Parameter& p : parameters_of(L))
              if (p.kind == kind && (joint < 0 || p.joint == joint)) out.push_back(p.index);
            return out;
          },
          py::arg("kind"), py::arg("joint") = -1,
          "indices of the parameters of a kind (and of one joint, from 1, when joint >= 0)")
      .def("__len__", [](const ParamLayout& L) { return L.size; });
}

void define_identify_options(py::module_& m) {
  const IdentifyOptions def;
  py::class_<IdentifyOptions>(m, "IdentifyOptions", "Options of identify()")
      .def(py::init([](bool compliance, const std::string& loss, double loss_scale_mm, int max_iterations,
                       const std::vector<std::string>& fix, const std::vector<int>& compliance_joints,
                       const std::vector<Effect>& effects, bool covariance, double orientation_weight,
                       double rank_tolerance, double weak_tolerance, double min_torque_share,
                       double correlation_threshold, double prior_scale,
                       const std::optional<std::vector<std::pair<std::string, double>>>& prior_sd,
                       const std::string& gravity) {
             IdentifyOptions o;
             o.gravity = parse_gravity(gravity);
             o.compliance = compliance, o.compliance_joints = joints_from_one(compliance_joints), o.effects = effects;
             o.loss = parse_loss(loss), o.loss_scale_mm = loss_scale_mm, o.max_iterations = max_iterations;
             o.fix = fix, o.covariance = covariance, o.orientation_weight = orientation_weight;
             o.rank_tolerance = rank_tolerance, o.weak_tolerance = weak_tolerance;
             o.min_torque_share = min_torque_share, o.correlation_threshold = correlation_threshold;
             o.prior_scale = prior_scale;
             if (prior_sd) o.prior_sd = *prior_sd;
             return o;
           }),
           py::arg("compliance") = def.compliance, py::arg("loss") = loss_word(def.loss),
           py::arg("loss_scale_mm") = def.loss_scale_mm, py::arg("max_iterations") = def.max_iterations,
           py::arg("fix") = std::vector<std::string>{}, py::arg("compliance_joints") = std::vector<int>{},
           py::arg("effects") = std::vector<Effect>{}, py::arg("covariance") = def.covariance,
           py::arg("orientation_weight") = def.orientation_weight, py::arg("rank_tolerance") = def.rank_tolerance,
           py::arg("weak_tolerance") = def.weak_tolerance, py::arg("min_torque_share") = def.min_torque_share,
           py::arg("correlation_threshold") = def.correlation_threshold, py::arg("prior_scale") = def.prior_scale,
           py::arg("prior_sd") = py::none(), py::arg("gravity") = gravity_word(def.gravity))
      .def_readwrite("compliance", &IdentifyOptions::compliance, "identify the joint compliances")
      .def_property(
          "loss", [](const IdentifyOptions& o) { return loss_word(o.loss); },
          [](IdentifyOptions& o, const std::string& w) { o.loss = parse_loss(w); }, "'none', 'huber' or 'cauchy'")
      .def_property(
          "gravity", [](const IdentifyOptions& o) { return gravity_word(o.gravity); },
          [](IdentifyOptions& o, const std::string& w) { o.gravity = parse_gravity(w); },
          "the compliances' gravity torques: 'masses', 'fit' (mass moments identified) or 'auto'")
      .def_readwrite("loss_scale_mm", &IdentifyOptions::loss_scale_mm,
                     "where the robust loss bends on a row's residual norm (mm); 0: from the data")
      .def_readwrite("prior_sd", &IdentifyOptions::prior_sd,
                     "prior standard deviations by kind, core units (joint_mm, joint_rad, compliance, tool_mm,\n"
                     "tool_rad, base_mm, base_rad, target_mm, an effect's name); assign a whole list")
      .def_readwrite("prior_scale", &IdentifyOptions::prior_scale, "times every prior standard deviation; 0: no priors")
      .def_readwrite("max_iterations", &IdentifyOptions::max_iterations, "Levenberg-Marquardt iterations at most")
      .def_readwrite("rank_tolerance", &IdentifyOptions::rank_tolerance,
                     "a unit Jacobian column closer than this to the others' span is redundant (held)")
      .def_readwrite("min_torque_share", &IdentifyOptions::min_torque_share,
                     "the compliance of a joint with less gravity torque than this share of the largest is held")
      .def_readwrite("weak_tolerance", &IdentifyOptions::weak_tolerance,
                     "a unit column closer than this is so weakly seen that it is held too")
      .def_readwrite("correlation_threshold", &IdentifyOptions::correlation_threshold,
                     "correlations at least this large (in absolute value) are reported")
      .def_readwrite("covariance", &IdentifyOptions::covariance, "standard deviations and correlations")
      .def_readwrite("fix", &IdentifyOptions::fix, "parameter names held in any case")
      .def_property(
          "compliance_joints", [](const IdentifyOptions& o) { return joints_to_one(o.compliance_joints); },
          [](IdentifyOptions& o, const std::vector<int>& j) { o.compliance_joints = joints_from_one(j); },
          "with compliance: only these joints (from 1; empty: every gravity-loaded joint)")
      .def_readwrite("effects", &IdentifyOptions::effects,
                     "effects identified with the rest (assign a whole list); joint_compliance entries turn\n"
                     "the compliance of their joints on")
      .def_readwrite("orientation_weight", &IdentifyOptions::orientation_weight,
                     "mm per rad: how orientation residuals weigh against positions")
      .def_readwrite("artifact_sd_mm", &IdentifyOptions::artifact_sd_mm,
                     "the artifact's uncertainty (mm): its terms weigh noise / it (0: as one row's coordinate)")
      .def_readwrite("noise_mm", &IdentifyOptions::noise_mm,
                     "the noise per coordinate (mm) when known: weighs the priors and bends the loss (0: estimated)")
      .def_readwrite("target_start", &IdentifyOptions::target_start,
                     "where each target's offset on the tool starts (mm, tool frame; empty: the origin), e.g. a\n"
                     "probe's nominal ball offset")
      .def_readwrite("penalties", &IdentifyOptions::penalties,
                     "ridge penalties (parameter name, weight in mm per unit of the parameter), e.g. a joint_map's\n"
                     "smoothness penalty (assign a whole list)");
}

void define_identify_result(py::module_& m) {
  py::class_<PyIdentifyResult>(m, "IdentifyResult", "What identify() found")
      .def_property_readonly("robot", [](const PyIdentifyResult& r) { return r.robot; },
                             "nominal + calibrated (with the identified effects)")
      .def_property_readonly("nominal_fitted", [](const PyIdentifyResult& r) { return r.nominal_fitted; },
                             "the nominal geometry with the fitted base frame")
      .def_property_readonly("layout", [](const PyIdentifyResult& r) -> const ParamLayout& { return r.r.layout; },
                             py::return_value_policy::reference_internal)
      .def_property_readonly("parameters", [](const PyIdentifyResult& r) { return parameters_of(r.r.layout); })
      .def_property_readonly("x", [](const PyIdentifyResult& r) { return vec(r.r.x); })
      .def_property_readonly("start", [](const PyIdentifyResult& r) { return vec(r.r.start); })
      .def_property_readonly("nominal_x", [](const PyIdentifyResult& r) { return vec(r.r.nominal_x); })
      .def_property_readonly("stddev", [](const PyIdentifyResult& r) { return vec(r.r.stddev); },
                             "NaN for held parameters")
      .def_property_readonly("fixed",
                             [](const PyIdentifyResult& r) {
                               py::array_t<bool> a(r.r.fixed.size());
                               for (size_t i = 0; i < r.r.fixed.size(); ++i) a.mutable_at(i) = r.r.fixed[i];
                               return a;
                             })
      .def_property_readonly("fixed_reason", [](const PyIdentifyResult& r) { return r.r.fixed_reason; })
      .def_property_readonly("held_unseen",
                             [](const PyIdentifyResult& r) {
                               py::array_t<bool> a(r.r.fixed.size());
                               for (size_t i = 0; i < r.r.fixed.size(); ++i)
                                 a.mutable_at(i) = held_unseen(r.r, static_cast<int>(i));
                               return a;
                             },
                             "held at its start because these rows do not see it (a frame's direction every "
                             "tool orientation shares); counted as free by the core's too-few-points refusal")
      .def_property_readonly("at_prior",
                             [](const PyIdentifyResult& r) {
                               py::array_t<bool> a(r.r.layout.size);
                               for (int i = 0; i < r.r.layout.size; ++i)
                                 a.mutable_at(i) = i < static_cast<int>(r.r.at_prior.size()) && r.r.at_prior[i];
                               return a;
                             },
                             "free but determined by its prior, not by the data")
      .def_property_readonly("prior_sd", [](const PyIdentifyResult& r) { return vec(r.r.prior_sd); },
                             "each parameter's prior standard deviation (scaled; inf: no prior)")
      .def_property_readonly("noise_mm", [](const PyIdentifyResult& r) { return r.r.noise_mm; },
                             "the residuals' robust spread per coordinate (mm; 0: not estimated)")
      .def_property_readonly("loss_scale_mm", [](const PyIdentifyResult& r) { return r.r.loss_scale_mm; },
                             "the robust loss's scale in the final fit (mm; 0: none)")
      .def_property_readonly("targets", [](const PyIdentifyResult& r) { return targets_to(r.r.targets); })
      .def_property_readonly("nominal_targets", [](const PyIdentifyResult& r) { return targets_to(r.r.nominal_targets); })
      .def_property_readonly("stations", [](const PyIdentifyResult& r) { return r.r.stations; },
                             "the probe stations fitted (the campaign's; empty without probe rows)")
      .def_property_readonly("nominal_stations", [](const PyIdentifyResult& r) { return r.r.nominal_stations; },
                             "the probe stations fitted with the nominal geometry")
      .def_property_readonly("effects", [](const PyIdentifyResult& r) { return effect_values_to(r.r.effects); },
                             "(Effect, values in core units) of every extra effect")
      .def_property_readonly("t_ref", [](const PyIdentifyResult& r) { return r.r.t_ref; })
      .def_property_readonly("t_mean_s", [](const PyIdentifyResult& r) { return r.r.campaign.t_mean_s; },
                             "reference time of the drift (s): the data's mean time")
      .def_property_readonly("setups", [](const PyIdentifyResult& r) { return placements(r.r.campaign); },
                             "every instrument placement: (name, xyz_mm, abc_deg); name '' for a single one")
      .def_property_readonly("nominal_setups", [](const PyIdentifyResult& r) { return placements(r.r.nominal_campaign); },
                             "the placements fitted on the nominal geometry")
      .def_property_readonly("iterations", [](const PyIdentifyResult& r) { return r.r.iterations; })
      .def_property_readonly("chord_steps", [](const PyIdentifyResult& r) { return r.r.chord_steps; })
      .def_property_readonly("initial_cost", [](const PyIdentifyResult& r) { return r.r.initial_cost; })
      .def_property_readonly("final_cost", [](const PyIdentifyResult& r) { return r.r.final_cost; })
      .def_property_readonly("rms_mm", [](const PyIdentifyResult& r) { return r.r.rms_mm; })
      .def_property_readonly("max_mm", [](const PyIdentifyResult& r) { return r.r.max_mm; })
      .def_property_readonly("nominal_rms_mm", [](const PyIdentifyResult& r) { return r.r.nominal_rms_mm; })
      .def_property_readonly("nominal_max_mm", [](const PyIdentifyResult& r) { return r.r.nominal_max_mm; })
      .def_property_readonly("condition_number", [](const PyIdentifyResult& r) { return r.r.condition_number; })
      .def_property_readonly("scale_determined", [](const PyIdentifyResult& r) { return r.r.scale_determined; },
                             "whether the data see the arm's overall scale (a probe campaign needs a known length)")
      .def_property_readonly("observability_index", [](const PyIdentifyResult& r) { return r.r.observability_index; })
      .def_property_readonly("correlations",
                             [](const PyIdentifyResult& r) {
                               std::vector<std::tuple<std::string, std::string, double>> c;
                               for (const auto& x : r.r.correlations) c.emplace_back(x.a, x.b, x.r);
                               return c;
                             },
                             "(name a, name b, r) above the threshold")
      .def_property_readonly("termination", [](const PyIdentifyResult& r) { return r.r.termination; })
      .def_property_readonly("converged", [](const PyIdentifyResult& r) { return r.r.converged; },
                             "every Levenberg-Marquardt pass stopped on a tolerance (none at its iteration cap)")
      .def_property_readonly("stop_reason", [](const PyIdentifyResult& r) { return r.r.stop_reason; },
                             "the solver's reason: termination type and message (of the first pass that did "
                             "not converge, if one did not)")
      .def(
          "__getitem__",
          [](py::object self, const std::string& key) -> py::object {
            // the dict of earlier versions: every attribute by its name, and names / units
            const auto& r = self.cast<const PyIdentifyResult&>();
            if (key == "names") return py::cast(r.r.layout.names);
            if (key == "units") return py::cast(r.r.layout.units);
            if (key == "layout" || key == "parameters" || !py::hasattr(self, key.c_str()))
              throw py::key_error(key);
            return self.attr(key.c_str());
          },
          py::arg("key"), "the attribute of that name (the dict access of earlier versions)");
}

void define_identify_call(py::module_& m) {
  m.def(
      "identify",
      [](const Robot& robot, const py::object& d, const IdentifyOptions& options, py::object progress,
         bool from_calibrated) {
        const Model& nominal = from_calibrated ? *robot.calibrated() : *robot.nominal();
        const PyMeasurementSet set = set_arg(d);
        const MeasurementSet& data = set.of_dof(nominal.dof());
        IdentifyOptions o = core_options(options, nominal);
        if (!progress.is_none()) o.progress = [progress](int it, double cost) { progress(it, cost); };
        PyIdentifyResult out{identify(nominal, data, o, campaign_of(robot, from_calibrated)), Robot{}, Robot{}};
        out.robot = Robot{robot.nominal(), std::make_shared<const Model>(out.r.calibrated), out.r.campaign};
        out.nominal_fitted =
            Robot{robot.nominal(), std::make_shared<const Model>(out.r.nominal_fitted), out.r.nominal_campaign};
        return out;
      },
      py::arg("robot"), py::arg("data"), py::arg("options") = IdentifyOptions{}, py::arg("progress") = py::none(),
      py::arg("from_calibrated") = false,
      "Identify from measurements, starting from the nominal model (or from the calibrated one: then\n"
      "the parameters are corrections to it, e.g. to refit only the base frame and targets). progress:\n"
      "called with (iteration, cost).");
}

}  // namespace

void define_identify(py::module_& m) {
  define_identify_functions(m);
  define_param_layout(m);
  define_identify_options(m);
  define_identify_result(m);
  define_identify_call(m);
}
