// _core bindings of the file readers and writers: pose and joint programs, CSV columns, the atomic
// writer, and the text parsers (the readers without the file, for tests and fuzzing).
#include "common.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/programs.hpp"

using namespace kincal;

namespace {

ProgramFormat format_of(bool gcode) { return gcode ? ProgramFormat::Gcode : ProgramFormat::Csv; }

}  // namespace

void define_io(py::module_& m) {
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
        return parse_pose_program(text, src, format_of(gcode)).poses.size();
      },
      py::arg("text"), py::arg("source") = "<text>", py::arg("gcode") = false);
  m.def(
      "parse_joint_program",
      [](const std::string& text, const std::string& src, bool gcode, int dof) {
        return parse_joint_program(text, src, format_of(gcode), dof).q.size();
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
}
