#include "common.hpp"

#include "kincal/compensation/program.hpp"
#include "kincal/core/rigid.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <optional>

using namespace kincal;

namespace {


// The calibrated or nominal model of r, once the joint angles q (rows of dof columns) are checked
// against it.
const Model& checked_model(const Robot& r, bool calibrated, const RowMatrix& q) {
  const Model& m = calibrated ? *r.calibrated() : *r.nominal();
  if (q.cols() != m.dof())
    throw InputError("joint angles have " + std::to_string(q.cols()) + " columns, the robot has " +
                     std::to_string(m.dof()) + " joints");
  if (!q.allFinite()) throw InputError("joint angles contain NaN or infinite values");
  return m;
}

// The effects' context of row i: its directions (when given) and temperature (when given).
EffectContext context_of(const Model& m, const std::optional<RowMatrix>& dir, const std::optional<Eigen::VectorXd>& temp,
                         Eigen::Index i) {
  EffectContext c;
  if (dir) c.dir = dir->row(i).transpose();
  if (temp) c.temperature_c = (*temp)[i];
  check_context(m, c, "row " + std::to_string(i) + ": ");
  return c;
}

void check_context_arrays(const Model& m, const RowMatrix& q, const std::optional<RowMatrix>& dir,
                          const std::optional<Eigen::VectorXd>& temp) {
  if (dir && (dir->rows() != q.rows() || dir->cols() != m.dof()))
    throw InputError("dir needs one row of " + std::to_string(m.dof()) + " signs per configuration");
  if (temp && temp->size() != q.rows()) throw InputError("temperature_c needs one value per configuration");
}

}  // namespace

namespace {

void define_kinematics_frames(py::module_& m) {
  m.def(
      "abc_to_rotation", [](const Eigen::Vector3d& abc) { return Eigen::Matrix3d(abc_to_rotation(abc)); },
      py::arg("abc_deg"), "Rotation matrix of KUKA ABC angles (deg): Rz(a) Ry(b) Rx(c)");
  m.def(
      "rotation_to_abc", [](const Eigen::Matrix3d& r) { return Eigen::Vector3d(rotation_to_abc(r)); },
      py::arg("rotation"), "KUKA ABC angles (deg) of a rotation matrix (the inverse of abc_to_rotation)");
  m.def(
      "fk",
      [](const Robot& r, const RowMatrix& q_deg, bool calibrated, bool instrument, const std::optional<RowMatrix>& dir,
         const std::optional<Eigen::VectorXd>& temperature_c) {
        const Model& md = checked_model(r, calibrated, q_deg);
        check_context_arrays(md, q_deg, dir, temperature_c);
        RowMatrix out(q_deg.rows(), 6);
        for (Eigen::Index i = 0; i < q_deg.rows(); ++i) {
          const VecQ q = q_deg.row(i).transpose() * kDeg;
          Eigen::Isometry3d t = fk_model(md, q, context_of(md, dir, temperature_c, i));
          if (instrument) t = campaign_of(r, calibrated).base() * t;
          const Pose6 p = iso_to_pose(t);
          out.row(i) << p.xyz.transpose(), p.abc.transpose();
        }
        return out;
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true, py::arg("instrument") = false,
      py::arg("dir") = py::none(), py::arg("temperature_c") = py::none(),
      "Tool poses x,y,z,a,b,c (mm, deg) for joint angles in degrees (N x dof), every effect of the model\n"
      "acting: dir (N x dof signs, backlash) and temperature_c (N, thermal expansion) when it needs them");
  m.def(
      "rigid_fit",
      [](const RowMatrix& a, const RowMatrix& b) {
        if (a.cols() != 3 || b.cols() != 3 || a.rows() != b.rows())
          throw InputError("rigid_fit: two point sets of the same count, x,y,z each");
        return Eigen::Matrix4d(rigid_fit(a.transpose(), b.transpose()).matrix());
      },
      py::arg("a"), py::arg("b"),
      "The rigid transform (4 x 4) that best maps the points a (n x 3) onto b (Horn); a translation only\n"
      "when the points do not span a plane");
  m.def(
      "motion_directions",
      [](const RowMatrix& q_deg, const std::vector<double>& initial) {
        if (q_deg.cols() != 6) throw InputError("motion_directions: joint programs of 6 joints");
        std::vector<Vec6> q(q_deg.rows());
        for (Eigen::Index i = 0; i < q_deg.rows(); ++i) q[i] = q_deg.row(i).transpose();
        const auto d = motion_directions(q, initial);
        RowMatrix out(q_deg.rows(), 6);
        for (Eigen::Index i = 0; i < q_deg.rows(); ++i) out.row(i) = d[i].transpose();
        return out;
      },
      py::arg("q_deg"), py::arg("initial") = std::vector<double>{},
      "Each joint's direction of motion into each pose of a joint program (sign of its change, held while\n"
      "it stands still; the first pose's from initial, or the direction of the first motion)");
  m.def(
      "fk_matrix",
      [](const Robot& r, const Eigen::VectorXd& q_deg, bool calibrated) {
        const Model& md = checked_model(r, calibrated, q_deg.transpose());
        const VecQ q = q_deg * kDeg;
        return Eigen::Matrix4d(fk_compliant(md, q).matrix());
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true);
  m.def(
      "jacobian",
      [](const Robot& r, const Eigen::VectorXd& q_deg, bool calibrated, const std::optional<Eigen::VectorXd>& dir,
         std::optional<double> temperature_c) {
        const Model& md = checked_model(r, calibrated, q_deg.transpose());
        EffectContext c;
        if (dir) c.dir = *dir;
        if (temperature_c) c.temperature_c = *temperature_c;
        check_context(md, c, "");
        Eigen::Isometry3d t;
        Jac j;
        fk_jacobian_model(md, VecQ(q_deg * kDeg), c, t, j);
        return Eigen::MatrixXd(j);
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true, py::arg("dir") = py::none(),
      py::arg("temperature_c") = py::none(),
      "6 x dof geometric Jacobian at the tool point (mm/rad over rad/rad), base frame");
}

void define_kinematics_solvers(py::module_& m) {
  m.def(
      "gravity_torque",
      [](const Robot& r, const Eigen::VectorXd& q_deg, bool calibrated) {
        const Model& md = checked_model(r, calibrated, q_deg.transpose());
        VecQ tau;
        MatQ d;
        gravity_torque(md, VecQ(q_deg * kDeg), tau, &d);
        return std::make_pair(Eigen::VectorXd(tau / 1000.0), Eigen::MatrixXd(d / 1000.0));
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true,
      "Gravity torque per joint (N m) and its derivative d tau / d q (N m per rad)");
  m.def(
      "kdl_fk",
      [](const Robot& r, const Eigen::VectorXd& q_deg, bool calibrated) {
        const Model& md = checked_model(r, calibrated, q_deg.transpose());
        KDL::ChainFkSolverPos_recursive s(md.kdl_chain());
        KDL::JntArray q(md.dof());
        for (int i = 0; i < md.dof(); ++i) q(i) = q_deg[i] * kDeg;
        KDL::Frame f;
        s.JntToCart(q, f);
        Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) t(i, j) = f.M(i, j);
          t(i, 3) = f.p[i];
        }
        return t;
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true, "KDL's own FK (reference)");
  m.def(
      "ik_all",
      [](const Robot& r, const Vec6& pose, py::object ref) {
        const IkSolver& ik = r.ik();
        if (!ik.structure().spherical_wrist_parallel_23)
          throw InputError("robot '" + r.nominal()->spec().name + "' has no closed-form IK: " + ik.structure().reason);
        if (!pose.allFinite()) throw InputError("pose contains NaN or infinite values");
        std::vector<double> rv;
        if (!ref.is_none()) rv = ref.cast<std::vector<double>>();
        const IkSolutions s = ik.solve(pose_to_iso(Pose6{pose.head<3>(), pose.tail<3>()}),
                                       IkOptions(rv.size() == 6 ? rv.data() : nullptr));
        py::list out;
        for (int i = 0; i < s.count; ++i) {
          py::dict d;
          d["q_deg"] = Eigen::VectorXd(s.sol[i].q_deg);
          d["within_limits"] = s.sol[i].within_limits;
          d["wrist_singular"] = s.sol[i].wrist_singular;
          d["shoulder_singular"] = s.sol[i].shoulder_singular;
          out.append(d);
        }
        return out;
      },
      py::arg("robot"), py::arg("pose"), py::arg("ref_deg") = py::none(),
      "Every closed-form IK solution of the nominal model for a pose x,y,z,a,b,c; [] when out of reach");
  m.def(
      "ik_nearest",
      [](const Robot& r, const Vec6& pose, const Vec6& ref) -> std::optional<int> {
        if (!pose.allFinite() || !ref.allFinite()) throw InputError("pose or reference contains NaN or infinite values");
        const IkSolutions s = r.ik().solve(pose_to_iso(Pose6{pose.head<3>(), pose.tail<3>()}), IkOptions(ref));
        const int k = s.nearest(ref.data());
        if (k < 0) return std::nullopt;
        return k;
      },
      py::arg("robot"), py::arg("pose"), py::arg("ref_deg"),
      "Index in ik_all(robot, pose, ref_deg) of the solution within the limits nearest ref_deg; None when none");
}

}  // namespace

void define_kinematics(py::module_& m) {
  define_kinematics_frames(m);
  define_kinematics_solvers(m);
}
