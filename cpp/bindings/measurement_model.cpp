// kincal: Python bindings of the identification's measurement model (PointModel: its residuals and
// Jacobian for a parameter vector), the probe stations a fit identifies and the probe campaigns'
// simulation (measurements without a tracker).
#include "common.hpp"

#include "kincal/identify/design.hpp"

#include <numeric>
#include <optional>

#include "kincal/identify/point_model.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/identify/stations.hpp"

using namespace kincal;

namespace {

/// The setup names of a PointModel: those given, else the campaign's own setups (a calibrated model
/// identified on several setups predicts them with their frames).
std::vector<std::string> setup_names_or_model(const std::optional<std::vector<std::string>>& given,
                                              const Campaign& c) {
  if (given) return *given;
  std::vector<std::string> names;
  for (const SetupFrame& f : c.setups) names.push_back(f.name);
  return names;
}

}  // namespace

const Campaign& campaign_of(const Robot& robot, bool calibrated) {
  static const Campaign none;
  return calibrated || !robot.identified() ? robot.campaign() : none;
}

namespace {

// Python's PointModel: the robot's model (kept alive), the layout's options and the measurement
// model built from them; residuals() builds one for the data's payloads
struct PyPointModel {
  std::shared_ptr<const Model> model;
  Campaign reference;  ///< the placements the layout's are relative to
  LayoutOptions options;
  PointModel pm;
};


void define_probe_stations(py::module_& m) {
  py::class_<StationValue>(m, "StationValue", "A probe station as identified (instrument frame of its rows' setup)")
      .def_readonly("name", &StationValue::name)
      .def_property_readonly("kind", [](const StationValue& v) { return to_string(v.kind); },
                             "'sphere', 'plane' or 'distance' (a ballbar's pivot)")
      .def_readonly("point", &StationValue::point, "a sphere's centre or a pivot (mm)")
      .def_readonly("normal", &StationValue::normal, "a plane's unit normal, towards the flange")
      .def_readonly("offset", &StationValue::offset, "a plane's offset: normal . y = offset (mm)")
      .def("__repr__", [](const StationValue& v) { return "<StationValue " + v.name + " " + to_string(v.kind) + ">"; });
  py::class_<ProbeSimulationOptions>(m, "ProbeSimulationOptions", "A probe campaign to simulate (simulate_probe)")
      .def(py::init<>())
      .def_property(
          "kind", [](const ProbeSimulationOptions& o) { return to_string(o.kind); },
          [](ProbeSimulationOptions& o, const std::string& k) {
            for (MeasureKind c : {MeasureKind::sphere, MeasureKind::plane, MeasureKind::distance})
              if (k == to_string(c)) return void(o.kind = c);
            throw InputError("simulate: --kind " + k + ": expected sphere, plane or distance");
          },
          "'sphere', 'plane' or 'distance'")
      .def_readwrite("stations", &ProbeSimulationOptions::stations,
                     "spheres or pivots placed in reach; planes: faces of one block (at most 5)")
      .def_readwrite("touches", &ProbeSimulationOptions::touches, "rows per station")
      .def_readwrite("cone_deg", &ProbeSimulationOptions::cone_deg, "the probe's axis within this angle of its mean")
      .def_readwrite("probe", &ProbeSimulationOptions::probe, "the ball centre in the tool frame (mm)")
      .def_readwrite("radius_mm", &ProbeSimulationOptions::radius_mm, "plane: the ball's radius")
      .def_readwrite("length_mm", &ProbeSimulationOptions::length_mm, "distance: the ballbar's length")
      .def_readwrite("block_mm", &ProbeSimulationOptions::block_mm, "plane: the block's edge")
      .def_readwrite("noise_mm", &ProbeSimulationOptions::noise_mm, "along the constraint (mm)")
      .def_readwrite("limit_margin", &ProbeSimulationOptions::limit_margin)
      .def_readwrite("seed", &ProbeSimulationOptions::seed)
      .def_readwrite("artifact", &ProbeSimulationOptions::artifact, "write the known distances and angles");
  m.def(
      "simulate_probe",
      [](const Robot& truth, const ProbeSimulationOptions& o) {
        return measurement_set(simulate_probe(*truth.calibrated(), o), truth.calibrated()->dof());
      },
      py::arg("truth"), py::arg("options"),
      "A probe campaign on the calibrated (true) model of a robot: every row's ball centre on its\n"
      "constraint, the noise along it; the artifact's terms under 'artifact'");
}

void define_point_model(py::module_& m) {
  py::class_<PyPointModel>(m, "PointModel", "The identification residuals and their analytic Jacobian")
      .def(py::init([](const Robot& r, int n_targets, const std::vector<Effect>& effects, double t_ref,
                       bool from_calibrated, const std::optional<std::vector<std::string>>& setups,
                       std::optional<double> t_mean_s, bool fit_gravity, const ParamLayout* stations_of) {
             std::shared_ptr<const Model> m = from_calibrated ? r.calibrated() : r.nominal();
             const Campaign& c = campaign_of(r, from_calibrated);
             LayoutOptions o{n_targets, effects, t_ref, setup_names_or_model(setups, c),
                             t_mean_s ? *t_mean_s : c.t_mean_s, fit_gravity};
             if (stations_of) {
               o.station_names = stations_of->station_names;
               o.station_kinds = stations_of->station_kinds;
               o.station_normals = stations_of->station_normals;
             }
             PointModel pm(*m, o, nullptr, c);
             return new PyPointModel{std::move(m), c, std::move(o), std::move(pm)};
           }),
           py::arg("robot"), py::arg("n_targets"), py::arg("effects") = std::vector<Effect>{},
           py::arg("t_ref") = 20.0, py::arg("from_calibrated") = false, py::arg("setups") = py::none(),
           py::arg("t_mean_s") = py::none(), py::arg("fit_gravity") = false, py::arg("stations_of") = nullptr,
           "setups: the data's setup names (default: the campaign's setups); stations_of: a layout whose probe\n"
           "stations (names, kinds, reference normals) this one has too; t_mean_s: the drift's reference\n"
           "time (default: the campaign's); fit_gravity: the compliances' torques from fitted mass moments\n"
           "(parameters of kind 'gravity_moment', 2 per link) instead of the model's masses")
      .def_property_readonly("layout", [](const PyPointModel& p) -> const ParamLayout& { return p.pm.layout(); },
                             py::return_value_policy::reference_internal)
      .def_property_readonly("names", [](const PyPointModel& p) { return p.pm.layout().names; })
      .def("start", [](const PyPointModel& p, const py::object& d) {
             return p.pm.start(set_arg(d).of_dof(p.pm.layout().dof));
           }, py::arg("data"))
      .def(
          "residuals",
          [](const PyPointModel& p, const std::vector<double>& x, const py::object& d, bool jac, double weight,
             bool artifact, const std::optional<std::vector<int>>& columns) {
            const ParamLayout& L = p.pm.layout();
            const PyMeasurementSet set = set_arg(d);
            const MeasurementSet& data = set.of_dof(L.dof);
            if (static_cast<int>(x.size()) != L.size) throw InputError("PointModel: wrong parameter count");
            if (!L.setup_names.empty() && data.setup_names != L.setup_names)
              throw InputError(data.source + ": the data's setups are not the layout's (" +
                               std::to_string(L.n_setups) + " setups in that order)");
            const PointState at = PointModel(*p.model, p.options, &data, p.reference).at(x);
            const size_t n = residual_size(residual_kind(data)) * data.rows.size();
            const size_t na = artifact ? data.artifact.size() : 0;
            std::vector<int> cols(L.size);
            std::iota(cols.begin(), cols.end(), 0);
            if (columns) {
              for (int c : *columns)
                if (c < 0 || c >= L.size) throw InputError("PointModel.residuals: column " + std::to_string(c) + " of " +
                                                           std::to_string(L.size));
              cols = *columns;
            }
            const auto F = static_cast<Eigen::Index>(cols.size());
            Eigen::VectorXd r(n + na);
            RowMatrix J(jac ? n + na : 0, F);
            {
              py::gil_scoped_release free;  // the rows run on the core's threads
              all_residuals(at, data, weight, cols, r.data(), jac ? J.data() : nullptr);
              Eigen::VectorXd full(jac ? L.size : 0);  // an artifact term's whole row, then its columns
              for (size_t k = 0; k < na; ++k) {
                const auto row = static_cast<Eigen::Index>(n + k);
                r[row] = at.artifact_residual(data.artifact[k], jac ? full.data() : nullptr);
                for (Eigen::Index c = 0; jac && c < F; ++c) J(row, c) = full[cols[static_cast<size_t>(c)]];
              }
            }
            // moved into the arrays (not copied): a planning Jacobian is hundreds of MB
            return py::make_tuple(py::cast(std::move(r)), py::cast(std::move(J)));
          },
          py::arg("x"), py::arg("data"), py::arg("jacobian") = false, py::arg("orientation_weight") = 100.0,
          py::arg("artifact") = false, py::arg("columns") = py::none(),
          "The rows' residuals (residual_size per row, unused equations 0) and with `artifact` the\n"
          "artifact's terms after them (mm: a length's error, an angle's on a 1 m lever); the Jacobian\n"
          "of the layout's parameters, or of `columns` (their indices) only");
}

}  // namespace

void define_measurement_model(py::module_& m) {
  define_probe_stations(m);
  define_point_model(m);
  m.def(
      "d_optimal_gains",
      [](const py::array_t<float, py::array::c_style>& J,
         const py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>& idx,
         const py::array_t<float, py::array::c_style>& L) {
        if (J.ndim() != 3 || L.ndim() != 2 || L.shape(0) != J.shape(2) || L.shape(1) != J.shape(2) ||
            idx.ndim() != 1)
          throw InputError("d_optimal_gains: J is (candidates, rows, columns), L (columns, columns), idx indices");
        py::array_t<float> out(idx.shape(0));
        {
          py::gil_scoped_release free;
          d_optimal_gains(J.data(), static_cast<std::size_t>(J.shape(0)), static_cast<int>(J.shape(1)),
                          static_cast<int>(J.shape(2)), idx.data(), static_cast<std::size_t>(idx.shape(0)), L.data(),
                          out.mutable_data());
        }
        return out;
      },
      py::arg("J"), py::arg("idx"), py::arg("L"),
      "log det(I + A A^T), A = J[i] L, of each candidate i of idx (float32 J and L, L lower triangular): the\n"
      "D-optimal gain of adding candidate i's rows to an information matrix M with M^-1 = L L^T");
}
