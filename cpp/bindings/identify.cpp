// Bindings of measurement campaigns and identification. A measurement set crosses the boundary as
// a dict of numpy arrays: pose (n), q_deg (n x dof), xyz (n x 3), target (n), payload_kg (n, NaN
// for the model's payload), line (n: source line, 0 when simulated).
#include "common.hpp"

#include <tuple>

#include "kincal/identify.hpp"
#include "kincal/model.hpp"

using namespace kincal;

namespace {

using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

py::dict to_dict(const MeasurementSet& m, int dof) {
  const size_t n = m.rows.size();
  Eigen::VectorXi pose(n), target(n), line(n);
  RowMat q(n, dof), xyz(n, 3);
  Eigen::VectorXd pay(n), temp(n);
  const bool dir = n > 0 && m.rows[0].dir.size() == dof;
  RowMat dirs(dir ? n : 0, dof);
  for (size_t i = 0; i < n; ++i) {
    temp[i] = m.rows[i].temperature_c;
    if (dir) dirs.row(i) = m.rows[i].dir.transpose();
    const Measurement& r = m.rows[i];
    pose[i] = r.pose;
    target[i] = r.target;
    line[i] = r.line;
    q.row(i) = r.q_deg.transpose();
    xyz.row(i) = r.xyz.transpose();
    pay[i] = r.payload_kg;
  }
  py::dict d;
  d["pose"] = pose;
  d["q_deg"] = q;
  d["xyz"] = xyz;
  d["target"] = target;
  d["payload_kg"] = pay;
  d["line"] = line;
  d["source"] = m.source;
  if (!std::isnan(temp.sum())) d["temperature_c"] = temp;
  if (m.orientation) {
    RowMat abc(n, 3);
    for (size_t i = 0; i < n; ++i) abc.row(i) = m.rows[i].abc.transpose();
    d["abc"] = abc;
  }
  if (dir) d["dir"] = dirs;
  return d;
}

MeasurementSet from_dict(const py::dict& d, int dof) {
  const auto pose = d["pose"].cast<Eigen::VectorXi>();
  const auto q = d["q_deg"].cast<RowMat>();
  const auto xyz = d["xyz"].cast<RowMat>();
  const size_t n = pose.size();
  const Eigen::VectorXi target =
      d.contains("target") ? d["target"].cast<Eigen::VectorXi>() : Eigen::VectorXi::Zero(n).eval();
  Eigen::VectorXd pay = Eigen::VectorXd::Constant(n, std::nan(""));
  if (d.contains("payload_kg")) pay = d["payload_kg"].cast<Eigen::VectorXd>();
  Eigen::VectorXi line = Eigen::VectorXi::Zero(n);
  if (d.contains("line")) line = d["line"].cast<Eigen::VectorXi>();
  MeasurementSet m;
  m.source = d.contains("source") ? d["source"].cast<std::string>() : std::string("<data>");
  if (static_cast<size_t>(q.rows()) != n || static_cast<size_t>(xyz.rows()) != n || xyz.cols() != 3 ||
      static_cast<size_t>(target.size()) != n || static_cast<size_t>(pay.size()) != n)
    throw InputError(m.source + ": measurement arrays of different lengths");
  if (q.cols() != dof)
    throw InputError(m.source + ": " + std::to_string(q.cols()) + " joint angles per row but the robot has " +
                     std::to_string(dof));
  int nt = 1;
  for (size_t i = 0; i < n; ++i) {
    Measurement r;
    r.pose = pose[i];
    r.q_deg = q.row(i).transpose();
    r.xyz = xyz.row(i).transpose();
    r.target = target[i];
    if (r.target < 0) throw InputError(m.source + ": negative target");
    r.payload_kg = pay[i];
    r.line = line[i];
    nt = std::max(nt, r.target + 1);
    m.rows.push_back(r);
  }
  if (d.contains("temperature_c")) {
    const auto t = d["temperature_c"].cast<Eigen::VectorXd>();
    if (static_cast<size_t>(t.size()) != n) throw InputError(m.source + ": temperature_c of a different length");
    for (size_t i = 0; i < n; ++i) m.rows[i].temperature_c = t[i];
  }
  if (d.contains("abc")) {
    const auto a = d["abc"].cast<RowMat>();
    if (static_cast<size_t>(a.rows()) != n || a.cols() != 3) throw InputError(m.source + ": abc of a different shape");
    for (size_t i = 0; i < n; ++i) m.rows[i].has_abc = true, m.rows[i].abc = a.row(i).transpose();
    m.orientation = true;
  }
  if (d.contains("dir")) {
    const auto dd = d["dir"].cast<RowMat>();
    if (static_cast<size_t>(dd.rows()) != n || dd.cols() != dof) throw InputError(m.source + ": dir of a different shape");
    for (size_t i = 0; i < n; ++i) m.rows[i].dir = dd.row(i).transpose();
  }
  m.n_targets = nt;
  return m;
}

/// ("name", joint from 1 or 0 for none) pairs
std::vector<Effect> effects_from(const std::vector<std::pair<std::string, int>>& e) {
  std::vector<Effect> out;
  for (const auto& p : e) {
    Effect ef{p.first, p.second - 1};
    ef.size();
    out.push_back(ef);
  }
  return out;
}

std::vector<EffectValue> effect_values_from(const std::vector<std::tuple<std::string, int, std::vector<double>>>& e) {
  std::vector<EffectValue> out;
  for (const auto& [name, joint, p] : e) {
    EffectValue v;
    v.effect = Effect{name, joint - 1};
    if (static_cast<int>(p.size()) != v.effect.size())
      throw InputError(v.effect.label() + ": " + std::to_string(v.effect.size()) + " values needed");
    v.p = p;
    out.push_back(v);
  }
  return out;
}

py::list effect_values_to(const std::vector<EffectValue>& e) {
  py::list l;
  for (const auto& v : e) l.append(py::make_tuple(v.effect.name, v.effect.joint + 1, v.p));
  return l;
}

std::vector<Vec3> targets_from(const RowMat& t) {
  std::vector<Vec3> v;
  for (int i = 0; i < t.rows(); ++i) v.emplace_back(t(i, 0), t(i, 1), t(i, 2));
  return v;
}

RowMat targets_to(const std::vector<Vec3>& v) {
  RowMat t(v.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) t.row(i) = v[i].transpose();
  return t;
}

}  // namespace

void define_identify(py::module_& m) {
  m.def(
      "read_measurements", [](const std::string& path, int dof) { return to_dict(read_measurements(path, dof), dof); },
      py::arg("path"), py::arg("dof"));
  m.def(
      "parse_measurements",
      [](const std::string& text, const std::string& src, int dof) { return to_dict(parse_measurements(text, src, dof), dof); },
      py::arg("text"), py::arg("source") = "<text>", py::arg("dof") = 6);
  m.def(
      "format_measurements",
      [](const py::dict& d, int dof) { return format_measurements(from_dict(d, dof), dof); }, py::arg("data"),
      py::arg("dof"));
  m.def(
      "simulate",
      [](const Robot& truth, int poses, unsigned seed, double noise_mm, double outlier_fraction, double outlier_mm,
         const RowMat& targets, double limit_margin,
         const std::vector<std::tuple<std::string, int, std::vector<double>>>& effects, double t_ref,
         double orientation_noise_deg) {
        SimulationOptions o;
        o.orientation_noise_deg = orientation_noise_deg;
        o.effects = effect_values_from(effects);
        o.t_ref = t_ref;
        o.poses = poses;
        o.seed = seed;
        o.noise_mm = noise_mm;
        o.outlier_fraction = outlier_fraction;
        o.outlier_mm = outlier_mm;
        o.targets = targets_from(targets);
        o.limit_margin = limit_margin;
        return to_dict(simulate(*truth.calibrated, o), truth.calibrated->dof());
      },
      py::arg("truth"), py::arg("poses"), py::arg("seed"), py::arg("noise_mm"), py::arg("outlier_fraction"),
      py::arg("outlier_mm"), py::arg("targets"), py::arg("limit_margin") = 0.9,
      py::arg("effects") = std::vector<std::tuple<std::string, int, std::vector<double>>>{}, py::arg("t_ref") = 20.0,
      py::arg("orientation_noise_deg") = -1.0,
      "A measurement campaign on the calibrated (true) model of a robot");
  m.def(
      "point_errors",
      [](const Robot& r, const RowMat& targets, const py::dict& d,
         const std::vector<std::tuple<std::string, int, std::vector<double>>>& effects, double t_ref) {
        const auto e = point_errors(*r.calibrated, targets_from(targets), from_dict(d, r.calibrated->dof()),
                                    effect_values_from(effects), t_ref);
        return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(e.data(), e.size()));
      },
      py::arg("robot"), py::arg("targets"), py::arg("data"),
      py::arg("effects") = std::vector<std::tuple<std::string, int, std::vector<double>>>{}, py::arg("t_ref") = 20.0,
      "Distance (mm) between every measured point and the calibrated model's prediction");
  m.def(
      "identify",
      [](const Robot& robot, const py::dict& d, bool compliance, const std::string& loss, double loss_scale_mm,
         int max_iterations, const std::vector<std::string>& fix, py::object progress, bool from_calibrated, bool covariance,
         const std::vector<std::pair<std::string, int>>& effects, const std::vector<int>& compliance_joints,
         double orientation_weight) {
        const Model& nominal = from_calibrated ? *robot.calibrated : *robot.nominal;
        const MeasurementSet data = from_dict(d, nominal.dof());
        IdentifyOptions o;
        o.compliance = compliance;
        o.loss = loss;
        o.loss_scale_mm = loss_scale_mm;
        o.max_iterations = max_iterations;
        o.fix = fix;
        o.covariance = covariance;
        o.effects = effects_from(effects);
        o.orientation_weight = orientation_weight;
        for (int j : compliance_joints) o.compliance_joints.push_back(j - 1);
        if (!progress.is_none()) o.progress = [progress](int it, double cost) { progress(it, cost); };
        const IdentifyResult r = identify(nominal, data, o);
        py::dict out;
        out["robot"] = Robot{robot.nominal, std::make_shared<const Model>(r.calibrated)};
        out["nominal_fitted"] = Robot{robot.nominal, std::make_shared<const Model>(r.nominal_fitted)};
        out["termination"] = r.termination;
        out["targets"] = targets_to(r.targets);
        out["nominal_targets"] = targets_to(r.nominal_targets);
        out["names"] = r.layout.names;
        out["units"] = r.layout.units;
        out["x"] = r.x;
        out["start"] = r.start;
        out["nominal_x"] = r.nominal_x;
        out["stddev"] = r.stddev;
        std::vector<bool> fixed(r.fixed.begin(), r.fixed.end());
        out["fixed"] = fixed;
        out["fixed_reason"] = r.fixed_reason;
        out["iterations"] = r.iterations;
        out["initial_cost"] = r.initial_cost;
        out["final_cost"] = r.final_cost;
        out["rms_mm"] = r.rms_mm;
        out["max_mm"] = r.max_mm;
        out["nominal_rms_mm"] = r.nominal_rms_mm;
        out["nominal_max_mm"] = r.nominal_max_mm;
        out["condition_number"] = r.condition_number;
        out["observability_index"] = r.observability_index;
        py::list corr;
        for (const auto& c : r.correlations) corr.append(py::make_tuple(c.a, c.b, c.r));
        out["correlations"] = corr;
        out["termination"] = r.termination;
        out["compliance_joints"] = r.layout.loaded;
        out["effects"] = effect_values_to(r.effects);
        out["t_ref"] = r.t_ref;
        return out;
      },
      py::arg("robot"), py::arg("data"), py::arg("compliance") = true, py::arg("loss") = "huber",
      py::arg("loss_scale_mm") = 0.1, py::arg("max_iterations") = 100, py::arg("fix") = std::vector<std::string>{},
      py::arg("progress") = py::none(), py::arg("from_calibrated") = false, py::arg("covariance") = true,
      py::arg("effects") = std::vector<std::pair<std::string, int>>{}, py::arg("compliance_joints") = std::vector<int>{},
      py::arg("orientation_weight") = 100.0,
      "Identify from measurements, starting from the nominal model (or from the calibrated one: then\n"
      "the parameters are corrections to it, e.g. to refit only the base frame and targets)");

  py::class_<PointModel>(m, "PointModel", "The identification residuals and their analytic Jacobian")
      .def(py::init([](const Robot& r, int n_targets, const std::vector<std::pair<std::string, int>>& effects,
                       double t_ref, bool from_calibrated) {
             return new PointModel(from_calibrated ? *r.calibrated : *r.nominal, n_targets, effects_from(effects), t_ref);
           }),
           py::arg("robot"), py::arg("n_targets"), py::arg("effects") = std::vector<std::pair<std::string, int>>{},
           py::arg("t_ref") = 20.0, py::arg("from_calibrated") = false, py::keep_alive<1, 2>())
      .def_property_readonly("names", [](const PointModel& p) { return p.layout().names; })
      .def("start", [](const PointModel& p, const py::dict& d) { return p.start(from_dict(d, p.layout().dof)); })
      .def(
          "residuals",
          [](PointModel& p, const std::vector<double>& x, const py::dict& d, bool jac, double weight) {
            const MeasurementSet data = from_dict(d, p.layout().dof);
            if (static_cast<int>(x.size()) != p.layout().size) throw InputError("PointModel: wrong parameter count");
            p.prepare_payloads(data);
            p.set_params(x);
            const int P = p.layout().size, RS = data.orientation ? 6 : 3;
            Eigen::VectorXd r(RS * data.rows.size());
            RowMat J(jac ? RS * data.rows.size() : 0, P);
            std::vector<double> full(6 * static_cast<size_t>(P));
            for (size_t i = 0; i < data.rows.size(); ++i) {
              row_residuals(p, data.rows[i], weight, RS == 6, r.data() + RS * i, jac ? full.data() : nullptr);
              if (jac) std::copy_n(full.data(), RS * P, J.data() + RS * i * P);
            }
            return py::make_tuple(r, J);
          },
          py::arg("x"), py::arg("data"), py::arg("jacobian") = false, py::arg("orientation_weight") = 100.0);
}
