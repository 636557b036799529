// Bindings of the hidden robot, its synthesis, the error matrix and the 6-bar truth. Points cross
// as dicts of numpy arrays: id, theta1_deg, theta2_deg, desired (n x 2), measured (n x 2), line.
#include "common.hpp"

#include "kincal/fivebar/fit.hpp"
#include "kincal/fivebar/fivebar.hpp"
#include "kincal/model/model.hpp"

using namespace kincal;

namespace {

using Rows2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

Rows2 rows_of(const std::vector<Vec2>& v) {
  Rows2 out(static_cast<Eigen::Index>(v.size()), 2);
  for (size_t i = 0; i < v.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  return out;
}

py::dict points_to(const std::vector<FiveBarPoint>& pts) {
  const size_t n = pts.size();
  Eigen::VectorXi id(n), line(n);
  Eigen::VectorXd t1(n), t2(n);
  Rows2 des(n, 2), mea(n, 2);
  for (size_t i = 0; i < n; ++i) {
    id[i] = pts[i].id;
    line[i] = pts[i].line;
    t1[i] = pts[i].t1_deg;
    t2[i] = pts[i].t2_deg;
    des.row(i) = pts[i].desired.transpose();
    mea.row(i) = pts[i].measured.transpose();
  }
  return dict_of("id", id, "theta1_deg", t1, "theta2_deg", t2, "desired", des, "measured", mea, "line", line);
}

std::vector<FiveBarPoint> points_from(const py::dict& d) {
  const auto id = d["id"].cast<Eigen::VectorXi>();
  const auto t1 = d["theta1_deg"].cast<Eigen::VectorXd>();
  const auto t2 = d["theta2_deg"].cast<Eigen::VectorXd>();
  const auto des = d["desired"].cast<Rows2>();
  const auto mea = d["measured"].cast<Rows2>();
  const size_t n = id.size();
  if (static_cast<size_t>(t1.size()) != n || static_cast<size_t>(t2.size()) != n ||
      static_cast<size_t>(des.rows()) != n || static_cast<size_t>(mea.rows()) != n)
    throw InputError("five-bar points: arrays of different lengths");
  std::vector<FiveBarPoint> pts(n);
  for (size_t i = 0; i < n; ++i) {
    pts[i].id = id[i];
    pts[i].t1_deg = t1[i];
    pts[i].t2_deg = t2[i];
    pts[i].desired = des.row(i).transpose();
    pts[i].measured = mea.row(i).transpose();
  }
  if (d.contains("line")) {
    const auto line = d["line"].cast<Eigen::VectorXi>();
    for (size_t i = 0; i < n && i < static_cast<size_t>(line.size()); ++i) pts[i].line = line[i];
  }
  return pts;
}

}  // namespace

namespace {

void define_fivebar_mechanism(py::module_& m) {
  py::class_<FiveBar>(m, "FiveBar", "The hidden robot: a 5-bar with concurrent fixed joints (lengths in mm)")
      .def(py::init([](double a, double b, double c, double d, int assembly, int working1, int working2) {
             return FiveBar{a, b, c, d, assembly, working1, working2};
           }),
           py::arg("a") = 150.0, py::arg("b") = 150.0, py::arg("c") = 150.0, py::arg("d") = 150.0,
           py::arg("assembly") = 1, py::arg("working1") = 1, py::arg("working2") = -1)
      .def_readwrite("assembly", &FiveBar::assembly)
      .def_readwrite("working1", &FiveBar::working1)
      .def_readwrite("working2", &FiveBar::working2)
      .def_readwrite("a", &FiveBar::a)
      .def_readwrite("b", &FiveBar::b)
      .def_readwrite("c", &FiveBar::c)
      .def_readwrite("d", &FiveBar::d)
      .def("__repr__", [](const FiveBar& f) { return "FiveBar(" + fivebar_to_json(f) + ")"; })
      .def(
          "fk",
          [](const FiveBar& f, double t1, double t2) -> py::object {
            Vec2 c;
            if (!fivebar_fk(f, t1 * kDeg, t2 * kDeg, c)) return py::none();
            return py::cast(Eigen::Vector2d(c));
          },
          py::arg("theta1_deg"), py::arg("theta2_deg"), "C (mm) for actuator angles (deg), None if the loop cannot close")
      .def(
          "ik",
          [](const FiveBar& f, double x, double y) -> py::object {
            double t1, t2;
            if (!fivebar_ik(f, Vec2(x, y), t1, t2)) return py::none();
            return py::make_tuple(t1 / kDeg, t2 / kDeg);
          },
          py::arg("x"), py::arg("y"), "actuator angles (deg) for C, None if out of reach")
      .def(
          "jacobian",
          [](const FiveBar& f, double t1, double t2) -> py::object {
            Mat2 j;
            if (!fivebar_jacobian(f, t1 * kDeg, t2 * kDeg, j)) return py::none();
            return py::cast(Eigen::Matrix2d(j));
          },
          py::arg("theta1_deg"), py::arg("theta2_deg"), "dC/dtheta (mm per rad)");
  m.def("read_fivebar_table", [](const std::string& p) { return points_to(read_fivebar_table(p)); }, py::arg("path"));
  m.def(
      "fivebar_synthesis",
      [](const py::dict& pts, const std::vector<int>& use, bool lsq) -> py::object {
        FiveBar f;
        if (!fivebar_synthesis(points_from(pts), use, lsq, f)) return py::none();
        return py::cast(f);
      },
      py::arg("points"), py::arg("use"), py::arg("least_squares"));
  m.def(
      "fivebar_max_error",
      [](const FiveBar& f, const py::dict& pts, bool desired) { return fivebar_max_error(f, points_from(pts), desired); },
      py::arg("model"), py::arg("points"), py::arg("desired") = false);
  m.def(
      "fivebar_best_subset",
      [](const py::dict& pts, bool lsq, bool desired, int n_min, int n_max) {
        const SubsetResult r = fivebar_best_subset(points_from(pts), lsq, desired, n_min, n_max);
        return py::make_tuple(r.model, r.points, r.max_error, r.subsets_tried);
      },
      py::arg("points"), py::arg("least_squares"), py::arg("desired"), py::arg("n_min"), py::arg("n_max"));
  py::class_<ErrorMatrix>(m, "ErrorMatrix", "Errors desired - measured on a regular grid, bilinear (eq. 7)")
      .def_static(
          "from_points", [](const py::dict& pts, const std::string& src) { return ErrorMatrix::from_points(points_from(pts), src); },
          py::arg("points"), py::arg("source") = "<grid>")
      .def_static("from_json", &ErrorMatrix::from_json, py::arg("text"), py::arg("source") = "<json>")
      .def("to_json", &ErrorMatrix::to_json)
      .def("at", [](const ErrorMatrix& e, double x, double y) { return Eigen::Vector2d(e.at(Vec2(x, y))); })
      .def_readonly("x0", &ErrorMatrix::x0)
      .def_readonly("y0", &ErrorMatrix::y0)
      .def_readonly("dx", &ErrorMatrix::dx)
      .def_readonly("dy", &ErrorMatrix::dy)
      .def_readonly("nx", &ErrorMatrix::nx)
      .def_readonly("ny", &ErrorMatrix::ny);
  m.def(
      "fivebar_command",
      [](const FiveBar& f, const ErrorMatrix* e, const Rows2& xy, const std::string& source,
         const std::vector<long>& lines) {
        std::vector<Vec2> pts(static_cast<size_t>(xy.rows()));
        for (Eigen::Index i = 0; i < xy.rows(); ++i) pts[static_cast<size_t>(i)] = xy.row(i).transpose();
        if (!lines.empty() && lines.size() != pts.size())
          throw InputError("fivebar_command: " + std::to_string(lines.size()) + " lines for " +
                           std::to_string(pts.size()) + " points");
        // an error names the point's file:line when its lines are given, else its row (from 1)
        return rows_of(fivebar_commands(f, e, pts, [&](size_t i) {
          if (lines.empty()) return (source.empty() ? "" : source + ": ") + "row " + std::to_string(i + 1);
          return source + ":" + std::to_string(lines[i]);
        }));
      },
      py::arg("model"), py::arg("matrix"), py::arg("xy"), py::arg("source") = "",
      py::arg("lines") = std::vector<long>{},
      "joint commands (deg) for desired points, in order; an error names source:line of the point (lines: "
      "the points' file lines) or its row");
}

void define_fivebar_files(py::module_& m) {
  m.def(
      "fivebar_command_file",
      [](const FiveBar& f, const ErrorMatrix* e, const std::string& path) {
        return rows_of(fivebar_command_file(f, e, path));
      },
      py::arg("model"), py::arg("matrix"), py::arg("path"),
      "joint commands (deg) for the desired points of a CSV with x,y (mm); errors name file:line");
  m.def(
      "fivebar_fit_nonlinear",
      [](const py::dict& pts, const FiveBar& start) {
        double rms = 0;
        const FiveBar f = fivebar_fit_nonlinear(points_from(pts), start, &rms);
        return py::make_tuple(f, rms);
      },
      py::arg("points"), py::arg("start"));
  m.def(
      "fivebar_errors",
      [](const FiveBar& f, const py::dict& pts, bool desired) {
        const auto p = points_from(pts);
        Rows2 e(p.size(), 2);
        Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> J(2 * p.size(), 4);
        for (size_t i = 0; i < p.size(); ++i) {
          Vec2 c;
          Eigen::Matrix<double, 2, 4> j;
          if (!fivebar_fk(f, p[i].t1_deg * kDeg, p[i].t2_deg * kDeg, c) ||
              !fivebar_length_jacobian(f, p[i].t1_deg * kDeg, p[i].t2_deg * kDeg, j))
            throw InputError("point " + std::to_string(p[i].id) + ": the model cannot close the loop there");
          e.row(i) = (c - (desired ? p[i].desired : p[i].measured)).transpose();
          J.block<2, 4>(2 * i, 0) = j;
        }
        return py::make_tuple(e, J);
      },
      py::arg("model"), py::arg("points"), py::arg("desired") = false,
      "model position minus target per point (n x 2) and d(position)/d(a, b, c, d) (2n x 4)");
  m.def("fivebar_from_json", &fivebar_from_json, py::arg("text"), py::arg("source") = "<json>");
  py::class_<SixBar>(m, "SixBar", "The over-constrained 6-bar truth simulator (see fivebar.hpp)")
      .def(py::init<>())
      .def_readwrite("a", &SixBar::a)
      .def_readwrite("b", &SixBar::b)
      .def_readwrite("c", &SixBar::c)
      .def_readwrite("d", &SixBar::d)
      .def_readwrite("e", &SixBar::e)
      .def_readwrite("h", &SixBar::h)
      .def_readwrite("offset1_deg", &SixBar::offset1_deg)
      .def_readwrite("offset2_deg", &SixBar::offset2_deg)
      .def_readwrite("companion_error", &SixBar::companion_error)
      .def_readwrite("strain_b", &SixBar::strain_b)
      .def_readwrite("strain_c", &SixBar::strain_c)
      .def_readwrite("clearance", &SixBar::clearance)
      .def(
          "position",
          [](const SixBar& s, double t1, double t2) -> py::object {
            Vec2 c;
            if (!s.position(t1, t2, c)) return py::none();
            return py::cast(Eigen::Vector2d(c));
          },
          py::arg("theta1_deg"), py::arg("theta2_deg"))
      .def(
          "coupler_lengths",
          [](const SixBar& s, double t1, double t2) {
            double b, c;
            s.coupler_lengths(t1, t2, b, c);
            return py::make_tuple(b, c);
          },
          py::arg("theta1_deg"), py::arg("theta2_deg"));
  m.def("paper_sixbar", &paper_sixbar, py::arg("seed"));
  m.def(
      "sixbar_campaign",
      [](const SixBar& s, const FiveBar& f, const ErrorMatrix* e, const Rows2& targets, double noise, unsigned seed) {
        std::vector<Vec2> t;
        for (Eigen::Index i = 0; i < targets.rows(); ++i) t.push_back(targets.row(i).transpose());
        return points_to(sixbar_campaign(s, f, e, t, noise, seed));
      },
      py::arg("truth"), py::arg("model"), py::arg("matrix"), py::arg("targets"), py::arg("noise_mm"), py::arg("seed"));
}

}  // namespace

void define_fivebar(py::module_& m) {
  define_fivebar_mechanism(m);
  define_fivebar_files(m);
}
