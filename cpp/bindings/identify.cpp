// Bindings of measurement campaigns and identification. A measurement set crosses the boundary as
// a dict of numpy arrays: pose (n), q_deg (n x dof), xyz (n x 3), target (n), payload_kg (n, NaN
// for the model's payload), line (n: source line, 0 when simulated).
#include "common.hpp"

#include "kincal/identify.hpp"
#include "kincal/model.hpp"

using namespace kincal;

namespace {

using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

py::dict to_dict(const MeasurementSet& m, int dof) {
  const size_t n = m.rows.size();
  Eigen::VectorXi pose(n), target(n), line(n);
  RowMat q(n, dof), xyz(n, 3);
  Eigen::VectorXd pay(n);
  for (size_t i = 0; i < n; ++i) {
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
  m.n_targets = nt;
  return m;
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
      "format_measurements",
      [](const py::dict& d, int dof) { return format_measurements(from_dict(d, dof), dof); }, py::arg("data"),
      py::arg("dof"));
  m.def(
      "simulate",
      [](const Robot& truth, int poses, unsigned seed, double noise_mm, double outlier_fraction, double outlier_mm,
         const RowMat& targets, double limit_margin) {
        SimulationOptions o;
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
      "A measurement campaign on the calibrated (true) model of a robot");
  m.def(
      "point_errors",
      [](const Robot& r, const RowMat& targets, const py::dict& d) {
        const auto e = point_errors(*r.calibrated, targets_from(targets), from_dict(d, r.calibrated->dof()));
        return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(e.data(), e.size()));
      },
      py::arg("robot"), py::arg("targets"), py::arg("data"),
      "Distance (mm) between every measured point and the calibrated model's prediction");
  m.def(
      "identify",
      [](const Robot& robot, const py::dict& d, bool compliance, const std::string& loss, double loss_scale_mm,
         int max_iterations, const std::vector<std::string>& fix, py::object progress, bool from_calibrated, bool covariance) {
        const Model& nominal = from_calibrated ? *robot.calibrated : *robot.nominal;
        const MeasurementSet data = from_dict(d, nominal.dof());
        IdentifyOptions o;
        o.compliance = compliance;
        o.loss = loss;
        o.loss_scale_mm = loss_scale_mm;
        o.max_iterations = max_iterations;
        o.fix = fix;
        o.covariance = covariance;
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
        return out;
      },
      py::arg("robot"), py::arg("data"), py::arg("compliance") = true, py::arg("loss") = "huber",
      py::arg("loss_scale_mm") = 0.1, py::arg("max_iterations") = 100, py::arg("fix") = std::vector<std::string>{},
      py::arg("progress") = py::none(), py::arg("from_calibrated") = false, py::arg("covariance") = true,
      "Identify from measurements, starting from the nominal model (or from the calibrated one: then\n"
      "the parameters are corrections to it, e.g. to refit only the base frame and targets)");

  py::class_<PointModel>(m, "PointModel", "The identification residuals and their analytic Jacobian")
      .def(py::init([](const Robot& r, int n_targets) { return new PointModel(*r.nominal, n_targets); }),
           py::arg("robot"), py::arg("n_targets"), py::keep_alive<1, 2>())
      .def_property_readonly("names", [](const PointModel& p) { return p.layout().names; })
      .def("start", [](const PointModel& p, const py::dict& d) { return p.start(from_dict(d, p.layout().dof)); })
      .def(
          "residuals",
          [](PointModel& p, const std::vector<double>& x, const py::dict& d, bool jac) {
            const MeasurementSet data = from_dict(d, p.layout().dof);
            if (static_cast<int>(x.size()) != p.layout().size) throw InputError("PointModel: wrong parameter count");
            p.prepare_payloads(data);
            p.set_params(x);
            const int P = p.layout().size;
            Eigen::VectorXd r(3 * data.rows.size());
            RowMat J(jac ? 3 * data.rows.size() : 0, P);
            for (size_t i = 0; i < data.rows.size(); ++i)
              r.segment<3>(3 * i) = p.predict(data.rows[i], jac ? J.data() + 3 * i * P : nullptr) - data.rows[i].xyz;
            return py::make_tuple(r, J);
          },
          py::arg("x"), py::arg("data"), py::arg("jacobian") = false);
}
