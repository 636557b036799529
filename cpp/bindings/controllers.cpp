// _core bindings of the controller programs: the writers (write_controller_program) and the branch
// data of filtered targets (branch_data, select_branch), for tests and scripts.
#include "common.hpp"

#include "kincal/compensation/branch.hpp"
#include "kincal/compensation/controller_program.hpp"
#include "kincal/io/controllers.hpp"
#include "kincal/model/joint_convention.hpp"

using namespace kincal;

namespace {

py::dict target_dict(const ControllerTarget& t) {
  py::dict d;
  d["q_deg"] = t.q_deg;
  d["pose"] = std::vector<double>{t.pose.xyz[0], t.pose.xyz[1], t.pose.xyz[2], t.pose.abc[0], t.pose.abc[1], t.pose.abc[2]};
  d["kuka_s"] = t.kuka_s;
  d["kuka_t"] = t.kuka_t;
  d["abb_conf"] = t.abb_conf;
  d["fanuc_config"] = t.fanuc_config;
  return d;
}

ControllerTarget target_of(const py::dict& d) {
  ControllerTarget t;
  if (d.contains("q_deg")) t.q_deg = d["q_deg"].cast<Vec6>();
  if (d.contains("pose")) {
    const auto p = d["pose"].cast<std::vector<double>>();
    if (p.size() != 6) throw InputError("pose needs x,y,z,a,b,c");
    t.pose = Pose6{Vec3(p[0], p[1], p[2]), Vec3(p[3], p[4], p[5])};
  }
  if (d.contains("kuka_s")) t.kuka_s = d["kuka_s"].cast<int>();
  if (d.contains("kuka_t")) t.kuka_t = d["kuka_t"].cast<int>();
  if (d.contains("abb_conf")) t.abb_conf = d["abb_conf"].cast<std::array<int, 4>>();
  if (d.contains("fanuc_config")) t.fanuc_config = d["fanuc_config"].cast<std::string>();
  return t;
}

}  // namespace

void define_controllers(py::module_& m) {
  m.def(
      "controller_targets",
      [](const Robot& r, const RowMatrix& q, const std::string& targets, const std::string& format) {
        std::vector<Vec6> qs;
        for (Eigen::Index i = 0; i < q.rows(); ++i) qs.push_back(q.row(i).transpose());
        py::list out;
        for (const auto& t : controller_targets(r, qs, target_kind_named(targets),
                                                controller_format_named(format), {}))
          out.append(target_dict(t));
        return out;
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("targets") = "filtered", py::arg("format") = "krl",
      "The targets of compensated joints (N x 6): with filtered, the nominal FK pose and the branch data, checked");
  m.def(
      "branch_data",
      [](const Robot& r, const Vec6& q) {
        ControllerTarget t;
        t.q_deg = q;
        set_branch_data(r, t);
        const ArmClass a = arm_class(r, q);
        py::dict d = target_dict(t);  // with the arm's classification the branch data come from
        d.attr("update")(py::dict(py::arg("behind") = a.behind, py::arg("elbow_up") = a.elbow_up,
                                  py::arg("wrist_negative") = a.wrist_negative, py::arg("x_a1") = a.x_a1,
                                  py::arg("elbow_sin") = a.elbow_sin));
        return d;
      },
      py::arg("robot"), py::arg("q_deg"), "KUKA S/T, ABB confdata, FANUC configuration of the nominal robot at q_deg");
  m.def(
      "select_branch",
      [](const Robot& r, const std::string& format, const py::dict& target) -> py::object {
        std::string why;
        const auto q = select_branch(r, controller_format_named(format), target_of(target), &why);
        if (!q) return py::str(why);
        return py::cast(Vec6(*q));
      },
      py::arg("robot"), py::arg("format"), py::arg("target"),
      "The joints the controller's nominal model takes for a filtered target (a dict with pose and branch data); "
      "a str saying why when none or several");
  m.def(
      "write_controller_program",
      [](const std::string& out, const py::list& targets, const std::string& format, const std::string& kind,
         const std::string& name, std::optional<double> speed, std::optional<double> zone, int max_per_file) {
        WriterOptions w;
        w.format = controller_format_named(format);
        w.targets = target_kind_named(kind);
        w.name = name;
        if (speed) w.speed = *speed;
        if (zone) w.zone = *zone;
        w.max_targets_per_file = max_per_file;
        std::vector<ControllerTarget> t;
        for (const auto& d : targets) t.push_back(target_of(d.cast<py::dict>()));
        std::vector<std::pair<std::string, std::string>> files;
        for (const auto& f : write_controller_program(out, t, w)) files.emplace_back(f.path, f.text);
        return files;
      },
      py::arg("out"), py::arg("targets"), py::arg("format"), py::arg("targets_kind") = "joints", py::arg("name") = "",
      py::arg("speed") = py::none(), py::arg("zone") = py::none(), py::arg("max_targets_per_file") = 0,
      "The files (path, text) of a program in a controller's language; nothing is written");
  m.def(
      "joints_to_controller",
      [](const Robot& r, Eigen::MatrixXd q) {
        if (q.cols() != r.nominal()->dof()) throw InputError("joints_to_controller: one column per joint");
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> a = q;
        for (Eigen::Index i = 0; i < a.rows(); ++i) joints_to_controller(r.nominal()->spec(), a.row(i).data(), int(a.cols()));
        return Eigen::MatrixXd(a);
      },
      py::arg("robot"), py::arg("q_deg"), "The model's joint angles (N x dof, deg) as the controller numbers them");
  m.def(
      "joints_from_controller",
      [](const Robot& r, Eigen::MatrixXd q) {
        if (q.cols() != r.nominal()->dof()) throw InputError("joints_from_controller: one column per joint");
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> a = q;
        for (Eigen::Index i = 0; i < a.rows(); ++i) joints_from_controller(r.nominal()->spec(), a.row(i).data(), int(a.cols()));
        return Eigen::MatrixXd(a);
      },
      py::arg("robot"), py::arg("q_deg"), "The controller's joint numbers (N x dof, deg) as the model's angles");
  m.def(
      "joint_convention", [](const Robot& r) { return r.nominal()->spec().joint_convention; }, py::arg("robot"),
      "The robot's joint convention: '' (the model's own angles) or 'fanuc'");
}
