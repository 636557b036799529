#include "common.hpp"

#include "bench.hpp"
#include "kincal/feed/feed.hpp"
#include "kincal/compensation/program.hpp"

#include <optional>

using namespace kincal;

namespace {


ProgramOptions options(bool compensate, bool instrument, bool fd, double delta, double epsilon, int max_iter,
                       bool corrected_start, const std::string& residual, std::optional<double> temperature_c,
                       const std::vector<double>& initial_direction, bool keep_branch) {
  ProgramOptions o;
  o.compensate = compensate;
  o.instrument_frame = instrument;
  o.corrected_start = corrected_start;
  o.comp.finite_difference = fd;
  o.comp.delta = delta;
  o.comp.epsilon = epsilon;
  o.comp.max_iterations = max_iter;
  if (residual == "abc")
    o.comp.residual = Residual::Abc;
  else if (residual != "rotation_vector")
    throw InputError("residual must be 'rotation_vector' or 'abc', not '" + residual + "'");
  if (temperature_c) o.temperature_c = *temperature_c;
  o.initial_direction = initial_direction;
  o.keep_branch = keep_branch;
  return o;
}

py::dict result_dict(const ProgramResult& r) {
  RowMatrix q(static_cast<Eigen::Index>(r.q_deg.size()), 6);
  for (size_t i = 0; i < r.q_deg.size(); ++i) q.row(static_cast<Eigen::Index>(i)) = r.q_deg[i].transpose();
  py::dict d;
  d["q_deg"] = q;
  d["iterations"] = r.iterations;
  d["residual"] = r.residual;
  RowMatrix dir(static_cast<Eigen::Index>(r.dir.size()), 6);
  for (size_t i = 0; i < r.dir.size(); ++i) dir.row(static_cast<Eigen::Index>(i)) = r.dir[i].transpose();
  d["dir"] = dir;
  d["warnings"] = r.warnings;
  return d;
}

}  // namespace

#define KINCAL_COMP_ARGS                                                                                  \
  py::arg("compensate") = true, py::arg("instrument") = false, py::arg("finite_difference") = false,     \
      py::arg("delta") = 1e-8, py::arg("epsilon") = 1e-15, py::arg("max_iterations") = 20,               \
      py::arg("corrected_start") = true, py::arg("residual") = "rotation_vector",                        \
      py::arg("temperature_c") = py::none(), py::arg("initial_direction") = std::vector<double>{},        \
      py::arg("keep_branch") = false
#define KINCAL_COMP_PARAMS                                                                                \
  bool comp, bool instr, bool fd, double delta, double eps, int it, bool cs, const std::string &residual, \
      std::optional<double> temp, const std::vector<double>&initial, bool keep
#define KINCAL_COMP_OPTIONS options(comp, instr, fd, delta, eps, it, cs, residual, temp, initial, keep)

void define_programs(py::module_& m) {
  m.def(
      "compensate_poses",
      [](const Robot& r, const RowMatrix& poses, KINCAL_COMP_PARAMS, const std::optional<Eigen::VectorXd>& temps) {
        if (poses.cols() != 6) throw InputError("poses need 6 columns x,y,z,a,b,c");
        std::vector<double> tv;
        if (temps) {
          if (temps->size() != poses.rows()) throw InputError("temperatures_c needs one value per pose");
          tv.assign(temps->data(), temps->data() + temps->size());
        }
        std::vector<Pose6> p;
        std::vector<std::string> where;
        for (Eigen::Index i = 0; i < poses.rows(); ++i) {
          if (!poses.row(i).allFinite()) throw InputError("pose " + std::to_string(i) + ": NaN or infinite value");
          p.push_back(Pose6{poses.row(i).head<3>().transpose(), poses.row(i).tail<3>().transpose()});
          where.push_back("pose " + std::to_string(i));
        }
        const ProgramOptions o = KINCAL_COMP_OPTIONS;
        ProgramResult res;
        {
          py::gil_scoped_release release;
          res = compensate_poses(r, p, where, o, tv);
        }
        return result_dict(res);
      },
      py::arg("robot"), py::arg("poses"), KINCAL_COMP_ARGS, py::arg("temperatures_c") = py::none(),
      "IK + Newton compensation of every pose (N x 6), branch kept continuous");
  m.def(
      "compensate_program",
      [](const Robot& r, const std::string& in, const std::string& out, KINCAL_COMP_PARAMS) {
        return result_dict(compensate_program_file(r, in, out, KINCAL_COMP_OPTIONS));
      },
      py::arg("robot"), py::arg("program"), py::arg("out"), KINCAL_COMP_ARGS,
      "Compensates a pose program file (CSV or G-code) into a joint program file, atomically");
  m.def(
      "read_pose_program",
      [](const std::string& path) {
        const PoseProgram p = read_pose_program(path);
        RowMatrix out(static_cast<Eigen::Index>(p.poses.size()), 6);
        for (size_t i = 0; i < p.poses.size(); ++i)
          out.row(static_cast<Eigen::Index>(i)) << p.poses[i].xyz.transpose(), p.poses[i].abc.transpose();
        return std::make_pair(out, p.pose_line);
      },
      py::arg("path"));
  m.def(
      "read_joint_program",
      [](const std::string& path, int dof) {
        const JointProgram p = read_joint_program(path, dof);
        RowMatrix out(static_cast<Eigen::Index>(p.q.size()), dof);
        for (size_t i = 0; i < p.q.size(); ++i)
          for (int j = 0; j < dof; ++j) out(static_cast<Eigen::Index>(i), j) = p.q[i][static_cast<size_t>(j)];
        return std::make_pair(out, p.line);
      },
      py::arg("path"), py::arg("dof"), "Joint program (CSV q1..qN or G-code A1=..) in degrees");
  m.def(
      "time_optimal_feed",
      [](const Eigen::VectorXd& s, const RowMatrix& d1, const RowMatrix& d2, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
         const Eigen::VectorXd& cap) {
        double t = 0;
        Eigen::VectorXd sd = time_optimal_feed(s, d1, d2, v, a, cap, t);
        return py::make_tuple(sd, t);
      },
      py::arg("s"), py::arg("d1"), py::arg("d2"), py::arg("v"), py::arg("a"), py::arg("cap"),
      "time-optimal s-dot along the path and the traversal time (see kincal/feed.hpp)");
  // text parsers (the file readers without the file): for tests and fuzzing
  m.def(
      "parse_csv",
      [](const std::string& text, const std::string& src) {
        const CsvTable t = parse_csv(text, src);
        return py::make_tuple(t.header, t.cells);
      },
      py::arg("text"), py::arg("source") = "<text>");
  m.def(
      "parse_pose_program",
      [](const std::string& text, const std::string& src, bool gcode) {
        return parse_pose_program(text, src, gcode).poses.size();
      },
      py::arg("text"), py::arg("source") = "<text>", py::arg("gcode") = false);
  m.def(
      "parse_joint_program",
      [](const std::string& text, const std::string& src, bool gcode, int dof) {
        return parse_joint_program(text, src, gcode, dof).q.size();
      },
      py::arg("text"), py::arg("source") = "<text>", py::arg("gcode") = false, py::arg("dof") = 6);
  m.def("write_file_atomic", &write_file_atomic, py::arg("path"), py::arg("text"));
  m.def(
      "read_csv_columns",
      [](const std::string& path, const std::vector<std::string>& names) {
        const CsvTable t = read_csv(path);
        std::vector<int> cols;
        for (const auto& n : names) cols.push_back(t.require(n));
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> out(t.cells.size(), names.size());
        for (size_t r = 0; r < t.cells.size(); ++r)
          for (size_t k = 0; k < cols.size(); ++k) out(r, k) = t.number(r, cols[k]);
        if (t.cells.empty()) throw InputError(path + ": no rows");
        return out;
      },
      py::arg("path"), py::arg("names"), "numeric columns of a CSV (finite numbers; errors name file:line)");
  m.def(
      "stream_lines",
      [](const Robot& r, const std::vector<std::string>& lines, bool instr, std::optional<double> temp,
         const std::vector<double>& initial, const std::string& residual) {
        StreamCompensator sc(r, options(true, instr, false, 1e-8, 1e-15, 20, true, residual, temp, initial, false));
        std::vector<std::string> out;
        char buf[8192];
        for (const auto& l : lines) out.emplace_back(buf, sc.process(l.data(), l.size(), buf, sizeof buf));
        return out;
      },
      py::arg("robot"), py::arg("lines"), py::arg("instrument") = false, py::arg("temperature_c") = py::none(),
      py::arg("initial_direction") = std::vector<double>{}, py::arg("residual") = "rotation_vector",
      "The streaming corrector on a list of lines (as kincal-compensate --stream)");
  m.def(
      "run_benchmarks",
      [](int n, unsigned seed, int threads) {
        py::gil_scoped_release release;
        auto r = run_benchmarks(n, seed, threads);
        py::gil_scoped_acquire acquire;
        py::dict d;
        for (auto& kv : r) d[py::str(kv.first)] = kv.second;
        return d;
      },
      py::arg("n") = 2000, py::arg("seed") = 1, py::arg("threads") = 0);
}
