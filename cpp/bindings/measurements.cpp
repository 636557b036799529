// Bindings of measurement files and of the class MeasurementSet. Its columns: pose (n), q_deg (n x
// dof), xyz (n x 3), target (n), payload_kg (n, NaN for the model's payload),
// line (n: source line, 0 when simulated), source; when the set has them also temperature_c (n),
// abc (n x 3: the measured orientations), dir (n x dof: the joints' directions of motion), time_s
// (n), config (n int64 codes) with config_names (the values by code, in order of first appearance)
// and setup (n int64 codes) with setup_names.
#include "common.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <iterator>

#include "kincal/io/measurements.hpp"
#include "kincal/model/model.hpp"

using namespace kincal;

namespace {

using Codes = Eigen::Matrix<int64_t, Eigen::Dynamic, 1>;

/// The codes and names of a text column (config, setup) from the dict; names default to the codes'
/// numbers. InputError for a code out of range or a name a CSV cannot hold.
std::vector<std::string> codes_from(const py::dict& d, const char* key, size_t n, const std::string& source,
                                    Codes& codes) {
  codes = d[key].cast<Codes>();
  if (static_cast<size_t>(codes.size()) != n)
    throw InputError(source + ": " + key + " of a different length");
  const std::string names_key = std::string(key) + "_names";
  std::vector<std::string> names;
  if (d.contains(names_key.c_str())) {
    names = d[names_key.c_str()].cast<std::vector<std::string>>();
  } else {
    const int64_t top = n ? codes.maxCoeff() : -1;
    for (int64_t k = 0; k <= top; ++k) names.push_back(std::to_string(k));
  }
  for (const auto& name : names)
    if (name.empty() || name.find_first_of(",\n\r\"") != std::string::npos ||
        std::isspace(static_cast<unsigned char>(name.front())) || std::isspace(static_cast<unsigned char>(name.back())))
      throw InputError(source + ": " + names_key + ": '" + name +
                       "' is not a CSV value (empty, a comma, quote or line break, or spaces around it)");
  for (size_t i = 0; i < n; ++i)
    if (codes[i] < 0 || codes[i] >= static_cast<int64_t>(names.size()))
      throw InputError(source + ": " + key + " code " + std::to_string(codes[i]) + " at row " + std::to_string(i) +
                       " is not one of 0.." + std::to_string(static_cast<int64_t>(names.size()) - 1));
  return names;
}

}  // namespace

namespace {

/// The probe rows' kinds, stations, radii and lengths and the artifact of a measurement dict into m.
void probe_from_dict(const py::dict& d, size_t n, MeasurementSet& m) {
  m.station_names = d["station_names"].cast<std::vector<std::string>>();
  for (const auto& k : d["station_kinds"].cast<std::vector<std::string>>()) {
    MeasureKind kind = MeasureKind::point;
    for (MeasureKind c : {MeasureKind::sphere, MeasureKind::plane, MeasureKind::distance})
      if (k == to_string(c)) kind = c;
    if (kind == MeasureKind::point) throw InputError(m.source + ": station kind '" + k + "' is not a probe's");
    m.station_kinds.push_back(kind);
  }
  if (m.station_kinds.size() != m.station_names.size()) throw InputError(m.source + ": a station without its kind");
  const auto kind = d["kind"].cast<Codes>(), station = d["station"].cast<Codes>();
  const auto radius = d["radius_mm"].cast<Eigen::VectorXd>(), length = d["length_mm"].cast<Eigen::VectorXd>();
  if (static_cast<size_t>(kind.size()) != n || static_cast<size_t>(station.size()) != n ||
      static_cast<size_t>(radius.size()) != n || static_cast<size_t>(length.size()) != n)
    throw InputError(m.source + ": probe columns of a different length");
  for (size_t i = 0; i < n; ++i) {
    Measurement& r = m.rows[i];
    if (kind[i] < 0 || kind[i] > static_cast<int64_t>(MeasureKind::distance))
      throw InputError(m.source + ": kind code " + std::to_string(kind[i]) + " at row " + std::to_string(i));
    r.kind = static_cast<MeasureKind>(kind[i]);
    if (r.kind == MeasureKind::point && r.has_abc) r.kind = MeasureKind::pose;
    if (!is_probe(r.kind)) continue;
    if (station[i] < 0 || station[i] >= static_cast<int64_t>(m.station_names.size()) ||
        m.station_kinds[static_cast<size_t>(station[i])] != r.kind)
      throw InputError(m.source + ": row " + std::to_string(i) + " names no " + to_string(r.kind) + " station");
    r.station = static_cast<int>(station[i]);
    r.radius_mm = radius[i];
    r.length_mm = length[i];
  }
  if (!d.contains("artifact")) return;
  std::string text = "a,b,distance_mm,angle_deg\n";  // through the reader: its checks, its messages
  auto num = [](double v) { return std::isnan(v) ? std::string() : py::str(py::float_(v)).cast<std::string>(); };
  using Term = std::tuple<std::string, std::string, double, double, std::string>;
  const auto terms = d["artifact"].cast<std::vector<Term>>();
  for (const auto& t : terms)
    text += std::get<0>(t) + "," + std::get<1>(t) + "," + num(std::get<2>(t)) + "," + num(std::get<3>(t)) + "\n";
  parse_artifact(text, m.source + " (artifact)", m);
  for (size_t k = 0; k < terms.size() && k < m.artifact.size(); ++k)  // a term keeps the file:line it came with
    if (!std::get<4>(terms[k]).empty()) m.artifact[k].where = std::get<4>(terms[k]);
}

}  // namespace

py::dict measurements_to_dict(const MeasurementSet& m, int dof) {
  const size_t n = m.rows.size();
  Eigen::VectorXi pose(n), target(n), line(n);
  RowMatrix q(n, dof), xyz(n, 3);
  Eigen::VectorXd pay(n), temp(n);
  const bool dir = n > 0 && m.rows[0].dir.size() == dof;
  RowMatrix dirs(dir ? n : 0, dof);
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
  py::dict d = dict_of("pose", pose, "q_deg", q, "xyz", xyz, "target", target, "payload_kg", pay, "line", line,
                       "source", m.source);
  if (!std::isnan(temp.sum())) d["temperature_c"] = temp;
  if (m.orientation) {
    RowMatrix abc(n, 3);
    for (size_t i = 0; i < n; ++i)  // NaN: a reflector row (a point) among 6-D rows
      abc.row(i) = (m.rows[i].has_abc ? m.rows[i].abc : Vec3::Constant(std::nan("")).eval()).transpose();
    d["abc"] = abc;
  }
  if (dir) d["dir"] = dirs;
  if (m.has_time()) {
    Eigen::VectorXd t(n);
    for (size_t i = 0; i < n; ++i) t[i] = m.rows[i].time_s;
    d["time_s"] = t;
  }
  if (!m.config_names.empty()) {
    Codes c(n);
    for (size_t i = 0; i < n; ++i) c[i] = m.rows[i].config;
    d["config"] = c;
    d["config_names"] = m.config_names;
  }
  if (!m.setup_names.empty()) {
    Codes c(n);
    for (size_t i = 0; i < n; ++i) c[i] = m.rows[i].setup;
    d["setup"] = c;
    d["setup_names"] = m.setup_names;
  }
  if (m.has_probe()) {  // probe rows: their kind, station (-1: a point or a pose), radius and length
    Codes kind(n), station(n);
    Eigen::VectorXd radius(n), length(n);
    for (size_t i = 0; i < n; ++i) {
      const Measurement& r = m.rows[i];
      kind[i] = static_cast<int64_t>(r.kind);
      station[i] = r.station;
      radius[i] = r.radius_mm;
      length[i] = r.length_mm;
    }
    std::vector<std::string> kinds;
    for (MeasureKind k : m.station_kinds) kinds.emplace_back(to_string(k));
    d["kind"] = kind;
    d["station"] = station;
    d["station_names"] = m.station_names;
    d["station_kinds"] = kinds;
    d["radius_mm"] = radius;
    d["length_mm"] = length;
  }
  if (!m.artifact.empty()) {
    py::list art;
    for (const ArtifactTerm& a : m.artifact)
      art.append(py::make_tuple(m.station_names.at(static_cast<size_t>(a.a)), m.station_names.at(static_cast<size_t>(a.b)),
                                a.distance_mm, a.angle_deg, a.where));
    d["artifact"] = art;
  }
  return d;
}

MeasurementSet measurements_from_dict(const py::dict& d, int dof) {
  const auto pose = d["pose"].cast<Eigen::VectorXi>();
  const auto q = d["q_deg"].cast<RowMatrix>();
  const auto xyz = d["xyz"].cast<RowMatrix>();
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
  m.rows.resize(n);  // filled in place: a plan's campaign has hundreds of thousands of rows
  for (size_t i = 0; i < n; ++i) {
    Measurement& r = m.rows[i];
    r.pose = pose[i];
    r.q_deg = q.row(i).transpose();
    r.xyz = xyz.row(i).transpose();
    r.target = target[i];
    if (r.target < 0) throw InputError(m.source + ": negative target");
    r.payload_kg = pay[i];
    r.line = line[i];
    nt = std::max(nt, r.target + 1);
  }
  if (d.contains("temperature_c")) {
    const auto t = d["temperature_c"].cast<Eigen::VectorXd>();
    if (static_cast<size_t>(t.size()) != n) throw InputError(m.source + ": temperature_c of a different length");
    for (size_t i = 0; i < n; ++i) m.rows[i].temperature_c = t[i];
  }
  if (d.contains("abc")) {
    const auto a = d["abc"].cast<RowMatrix>();
    if (static_cast<size_t>(a.rows()) != n || a.cols() != 3) throw InputError(m.source + ": abc of a different shape");
    for (size_t i = 0; i < n; ++i) {
      const int nan = static_cast<int>(std::isnan(a(i, 0))) + static_cast<int>(std::isnan(a(i, 1))) +
                      static_cast<int>(std::isnan(a(i, 2)));
      if (nan == 3) continue;  // a reflector row among 6-D rows
      if (nan > 0 || !a.row(i).allFinite())
        throw InputError(m.source + ": abc at row " + std::to_string(i) + " needs three finite angles (or three NaN: a point)");
      m.rows[i].has_abc = true;
      m.rows[i].abc = a.row(i).transpose();
      m.orientation = true;
    }
  }
  if (d.contains("dir")) {
    const auto dd = d["dir"].cast<RowMatrix>();
    if (static_cast<size_t>(dd.rows()) != n || dd.cols() != dof) throw InputError(m.source + ": dir of a different shape");
    for (size_t i = 0; i < n; ++i) m.rows[i].dir = dd.row(i).transpose();
  }
  if (d.contains("time_s")) {
    const auto t = d["time_s"].cast<Eigen::VectorXd>();
    if (static_cast<size_t>(t.size()) != n) throw InputError(m.source + ": time_s of a different length");
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(t[i])) throw InputError(m.source + ": time_s at row " + std::to_string(i) + " is not finite");
      m.rows[i].time_s = t[i];
    }
  }
  Codes codes;
  if (d.contains("config")) {
    m.config_names = codes_from(d, "config", n, m.source, codes);
    for (size_t i = 0; i < n; ++i) m.rows[i].config = static_cast<int>(codes[i]);
  }
  if (d.contains("setup")) {
    m.setup_names = codes_from(d, "setup", n, m.source, codes);
    for (size_t i = 0; i < n; ++i) m.rows[i].setup = static_cast<int>(codes[i]);
  }
  if (d.contains("station_names")) probe_from_dict(d, n, m);
  m.n_targets = nt;
  return m;
}

const MeasurementSet& PyMeasurementSet::of_dof(int robot_dof) const {
  if (dof != robot_dof && !set->rows.empty())
    throw InputError(set->source + ": " + std::to_string(dof) + " joint angles per row but the robot has " +
                     std::to_string(robot_dof));
  return *set;
}

PyMeasurementSet measurement_set(MeasurementSet&& m, int dof) {
  return PyMeasurementSet{std::make_shared<const MeasurementSet>(std::move(m)), dof, py::none()};
}

namespace {
PyMeasurementSet from_columns(const py::dict& d, int dof);
}  // namespace

PyMeasurementSet set_arg(const py::handle& data) {
  if (py::isinstance<PyMeasurementSet>(data)) return data.cast<PyMeasurementSet>();
  if (py::hasattr(data, "keys")) return from_columns(py::dict(py::reinterpret_borrow<py::object>(data)), -1);
  throw py::type_error("a MeasurementSet (or a mapping of its columns) is needed, not " +
                       py::str(py::type::of(data)).cast<std::string>());
}

namespace {

/// The columns of a set, made once: numpy arrays marked read-only (the set never changes).
py::dict columns_of(const PyMeasurementSet& s) {
  if (s.columns.is_none()) {
    py::dict d = measurements_to_dict(*s.set, s.dof);
    for (auto item : d)
      if (py::isinstance<py::array>(item.second)) item.second.attr("setflags")(py::arg("write") = false);
    s.columns = d;
  }
  return s.columns.cast<py::dict>();
}

/// One column (a copy of a list of names, so that the set's own stays as it is), None when absent.
py::object column(const PyMeasurementSet& s, const std::string& key) {
  const py::dict d = columns_of(s);
  if (!d.contains(key.c_str())) return py::none();
  py::object v = d[key.c_str()];
  return py::isinstance<py::list>(v) ? py::object(py::list(v)) : v;
}

/// A set from columns: dof -1 takes the joint count from q_deg.
PyMeasurementSet from_columns(const py::dict& d, int dof) {
  if (dof < 0) {
    const std::string source = d.contains("source") ? py::str(d["source"]).cast<std::string>() : "<data>";
    if (!d.contains("q_deg")) throw InputError(source + ": a measurement set needs q_deg (n x dof joint angles)");
    py::array q = py::array::ensure(d["q_deg"]);
    if (!q || q.ndim() != 2) throw InputError(source + ": a measurement set's q_deg is n x dof joint angles");
    dof = static_cast<int>(q.shape(1));
  }
  return measurement_set(measurements_from_dict(d, dof), dof);
}

const char* const kColumns[] = {"pose", "q_deg", "xyz", "target", "payload_kg", "line", "source", "temperature_c",
                                "abc", "dir", "time_s", "config", "config_names", "setup", "setup_names", "kind",
                                "station", "station_names", "station_kinds", "radius_mm", "length_mm", "artifact"};

void define_measurement_set(py::module_& m) {
  auto c = py::class_<PyMeasurementSet>(
      m, "MeasurementSet",
      "A measurement set: rows of joint angles and what was measured, immutable. Every column is a\n"
      "read-only numpy array (None when the set has no such column); subset() and with_columns() make new\n"
      "sets. A dict of columns converts to it wherever the core takes one.");
  c.def(py::init(&from_columns), py::arg("columns"), py::arg("dof") = -1,
        "From columns (a dict: pose, q_deg, xyz, target and the optional ones); dof -1: q_deg's width")
      .def_property_readonly("dof", [](const PyMeasurementSet& s) { return s.dof; }, "joint angles per row")
      .def_property_readonly("n_targets", [](const PyMeasurementSet& s) { return s.set->n_targets; },
                             "targets (reflectors) the rows name: the largest index + 1")
      .def("__len__", [](const PyMeasurementSet& s) { return s.set->rows.size(); })
      .def(
          "subset",
          [](const PyMeasurementSet& s, const py::array& rows) {
            const MeasurementSet& a = *s.set;
            const size_t n = a.rows.size();
            std::vector<size_t> pick;
            if (rows.dtype().kind() == 'b') {
              const auto mask = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(rows);
              if (mask.ndim() != 1 || static_cast<size_t>(mask.size()) != n)
                throw InputError(a.source + ": a mask of " + std::to_string(mask.size()) + " for " +
                                 std::to_string(n) + " rows");
              for (size_t i = 0; i < n; ++i)
                if (mask.data()[i]) pick.push_back(i);
            } else {
              if (rows.size() > 0 && rows.dtype().kind() != 'i' && rows.dtype().kind() != 'u')
                throw InputError(a.source + ": rows are a boolean mask or integer indices");
              const auto idx = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(rows);
              if (!idx || idx.ndim() != 1) throw InputError(a.source + ": rows are a mask or indices");
              for (py::ssize_t k = 0; k < idx.size(); ++k) {
                const int64_t i = idx.data()[k];
                if (i < 0 || i >= static_cast<int64_t>(n))
                  throw InputError(a.source + ": row " + std::to_string(i) + " of " + std::to_string(n));
                pick.push_back(static_cast<size_t>(i));
              }
            }
            return measurement_set(subset(a, pick), s.dof);
          },
          py::arg("rows"), "The rows `rows` (a boolean mask or indices, in that order) as a new set")
      .def(
          "columns",
          [](const PyMeasurementSet& s) { return measurements_to_dict(*s.set, s.dof); },
          "Every column as a new dict (its arrays writable copies)")
      .def(
          "with_columns",
          [](const PyMeasurementSet& s, const py::kwargs& kw) {
            py::dict d = measurements_to_dict(*s.set, s.dof);
            for (auto item : kw) {
              const auto key = item.first.cast<std::string>();
              if (std::find(std::begin(kColumns), std::end(kColumns), key) == std::end(kColumns))
                throw InputError(s.set->source + ": with_columns: '" + key + "' is not a column of a measurement set");
              d[item.first] = item.second;
            }
            return from_columns(d, kw.contains("q_deg") ? -1 : s.dof);
          },
          "A new set: these columns given, the others as they are (e.g. with_columns(q_deg=q))")
      // the dict of earlier versions, read-only: data["q_deg"], "abc" in data, keys(), iteration, items(), get()
      .def(
          "__getitem__",
          [](const PyMeasurementSet& s, const std::string& key) {
            py::object v = column(s, key);
            if (v.is_none()) throw py::key_error(key);
            return v;
          },
          py::arg("key"))
      .def("__contains__",
           [](const PyMeasurementSet& s, const std::string& key) { return columns_of(s).contains(key.c_str()); })
      .def("keys", [](const PyMeasurementSet& s) { return columns_of(s).attr("keys")(); })
      .def("__iter__", [](const PyMeasurementSet& s) { return py::iter(columns_of(s)); })
      .def("items", [](const PyMeasurementSet& s) {
        py::list out;
        for (auto item : columns_of(s))
          out.append(py::make_tuple(item.first, column(s, item.first.cast<std::string>())));
        return out;
      })
      .def(
          "get",
          [](const PyMeasurementSet& s, const std::string& key, py::object fallback) {
            py::object v = column(s, key);
            return v.is_none() ? fallback : v;
          },
          py::arg("key"), py::arg("default") = py::none())
      .def("__repr__", [](const PyMeasurementSet& s) {
        return "<MeasurementSet " + s.set->source + ": " + std::to_string(s.set->rows.size()) + " rows, " +
               std::to_string(s.dof) + " joints>";
      });
  for (const char* key : kColumns) {
    const std::string k = key;
    c.def_property_readonly(key, [k](const PyMeasurementSet& s) { return column(s, k); });
  }
}

}  // namespace

void define_measurements(py::module_& m) {
  define_measurement_set(m);
  m.def(
      "read_measurements",
      [](const std::string& path, int dof, const Robot* robot) {
        MeasurementSet ms = read_measurements(path, dof);
        if (robot) measurements_from_controller(ms, robot->nominal()->spec());  // the controller's numbers
        return measurement_set(std::move(ms), dof);
      },
      py::arg("path"), py::arg("dof"), py::arg("robot") = nullptr);
  m.def(
      "parse_measurements",
      [](const std::string& text, const std::string& src, int dof) {
        return measurement_set(parse_measurements(text, src, dof), dof);
      },
      py::arg("text"), py::arg("source") = "<text>", py::arg("dof") = 6);
  m.def(
      "format_measurements",
      [](const py::object& d, int dof) { return format_measurements(set_arg(d).of_dof(dof), dof); },
      py::arg("data"), py::arg("dof"));
  m.def(
      "read_artifact",
      [](const std::string& path, const py::object& d, int dof) {
        MeasurementSet ms = set_arg(d).of_dof(dof);
        read_artifact(path, ms);
        return measurement_set(std::move(ms), dof);
      },
      py::arg("path"), py::arg("data"), py::arg("dof"),
      "The data with the artifact file's known distances and angles between their stations");
  m.def(
      "format_artifact", [](const py::object& d, int dof) { return format_artifact(set_arg(d).of_dof(dof)); },
      py::arg("data"), py::arg("dof"));
}
