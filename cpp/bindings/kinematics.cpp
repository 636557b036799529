#include "common.hpp"

#include "kincal/ik.hpp"
#include "kincal/kinematics.hpp"

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

using namespace kincal;

namespace {

using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

const Model& pick(const Robot& r, bool calibrated) { return calibrated ? *r.calibrated : *r.nominal; }

void check_q(const Model& m, const Rows& q) {
  if (q.cols() != m.dof())
    throw InputError("joint angles have " + std::to_string(q.cols()) + " columns, the robot has " +
                     std::to_string(m.dof()) + " joints");
  if (!q.allFinite()) throw InputError("joint angles contain NaN or infinite values");
}

}  // namespace

void define_kinematics(py::module_& m) {
  m.def(
      "abc_to_rotation", [](const Eigen::Vector3d& abc) { return Eigen::Matrix3d(abc_to_rotation(abc)); },
      py::arg("abc_deg"), "Rotation matrix of KUKA ABC angles (deg): Rz(a) Ry(b) Rx(c)");
  m.def(
      "rotation_to_abc", [](const Eigen::Matrix3d& r) { return Eigen::Vector3d(rotation_to_abc(r)); },
      py::arg("rotation"), "KUKA ABC angles (deg) of a rotation matrix (the inverse of abc_to_rotation)");
  m.def(
      "fk",
      [](const Robot& r, const Rows& q_deg, bool calibrated, bool instrument) {
        const Model& md = pick(r, calibrated);
        check_q(md, q_deg);
        Rows out(q_deg.rows(), 6);
        for (Eigen::Index i = 0; i < q_deg.rows(); ++i) {
          const VecQ q = q_deg.row(i).transpose() * kDeg;
          Eigen::Isometry3d t = fk_compliant(md, q);
          if (instrument) t = md.base_in_instrument() * t;
          const Pose6 p = iso_to_pose(t);
          out.row(i) << p.xyz.transpose(), p.abc.transpose();
        }
        return out;
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true, py::arg("instrument") = false,
      "Tool poses x,y,z,a,b,c (mm, deg) for joint angles in degrees (N x dof)");
  m.def(
      "fk_matrix",
      [](const Robot& r, const Eigen::VectorXd& q_deg, bool calibrated) {
        const Model& md = pick(r, calibrated);
        check_q(md, q_deg.transpose());
        const VecQ q = q_deg * kDeg;
        return Eigen::Matrix4d(fk_compliant(md, q).matrix());
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true);
  m.def(
      "jacobian",
      [](const Robot& r, const Eigen::VectorXd& q_deg, bool calibrated) {
        const Model& md = pick(r, calibrated);
        check_q(md, q_deg.transpose());
        Eigen::Isometry3d t;
        Jac j;
        fk_jacobian_compliant(md, VecQ(q_deg * kDeg), t, j);
        return Eigen::MatrixXd(j);
      },
      py::arg("robot"), py::arg("q_deg"), py::arg("calibrated") = true,
      "6 x dof geometric Jacobian at the tool point (mm/rad over rad/rad), base frame");
  m.def(
      "gravity_torque",
      [](const Robot& r, const Eigen::VectorXd& q_deg, bool calibrated) {
        const Model& md = pick(r, calibrated);
        check_q(md, q_deg.transpose());
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
        const Model& md = pick(r, calibrated);
        check_q(md, q_deg.transpose());
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
      [](const Robot& r, const Eigen::Matrix<double, 6, 1>& pose, py::object ref) {
        const Model& md = *r.nominal;
        if (!md.ik_structure().spherical_wrist_parallel_23)
          throw InputError("robot '" + md.spec().name + "' has no closed-form IK: " + md.ik_structure().reason);
        if (!pose.allFinite()) throw InputError("pose contains NaN or infinite values");
        std::vector<double> rv;
        if (!ref.is_none()) rv = ref.cast<std::vector<double>>();
        const IkSolutions s =
            ik_all(md, pose_to_iso(Pose6{pose.head<3>(), pose.tail<3>()}), rv.size() == 6 ? rv.data() : nullptr);
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
}
