#include "kincal/kinematics/kinematics.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

using namespace kincal;

namespace {

Eigen::Isometry3d kdl_fk(const Model& m, const VecQ& q) {
  KDL::ChainFkSolverPos_recursive s(m.kdl_chain());
  KDL::JntArray a(6);
  for (int i = 0; i < 6; ++i) a(i) = q[i];
  KDL::Frame f;
  s.JntToCart(a, f);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) t.linear()(i, j) = f.M(i, j);
    t.translation()[i] = f.p[i];
  }
  return t;
}

}  // namespace

// Truth: KDL's recursive FK and Jacobian solvers on the same chain: the nominal kr500 and UR10
// (exactly parallel and intersecting axes), both with errors of 2 mm / 0.5 deg, and both with axes
// tilted by only 1e-9 deg (nearly parallel axes, where the evaluator's link decomposition degenerates).
TEST(Kinematics, FkAndJacobianMatchKdl) {
  KINCAL_SEED_TRACE(11, 2, 3, 4, 5, 6, 7);
  std::mt19937_64 rng(test::test_seed(11));
  const int n = test::count(2000);
  double dp = 0, dr = 0, dj = 0;
  for (unsigned seed = 0; seed < 8; ++seed) {
    const ModelSpec base = seed % 2 ? ur10_spec() : kr500_spec();
    const Model m(seed < 2 ? base : perturbed_spec(base, test::test_seed(seed), 2.0, seed < 6 ? 0.5 : 1e-9));
    KDL::ChainJntToJacSolver js(m.kdl_chain());
    for (int i = 0; i < n; ++i) {
      const VecQ q = test::random_q(m, rng) * kDeg;
      const Eigen::Isometry3d a = fk(m, q), b = kdl_fk(m, q);
      dp = std::max(dp, (a.translation() - b.translation()).norm());
      dr = std::max(dr, test::rot_dist(a.linear(), b.linear()));
      Eigen::Isometry3d t;
      Jac j;
      fk_jacobian(m, q, t, j);
      KDL::JntArray ka(6);
      for (int k = 0; k < 6; ++k) ka(k) = q[k];
      KDL::Jacobian kj(6);
      js.JntToJac(ka, kj);
      dj = std::max(dj, (j - kj.data).cwiseAbs().maxCoeff());
      ASSERT_LT((t.translation() - a.translation()).norm(), 1e-12);
    }
  }
  std::printf("FK vs KDL: %.2e mm, %.2e rad; Jacobian %.2e\n", dp, dr, dj);
  EXPECT_LT(dp, 1e-9);   // mm
  EXPECT_LT(dr, 1e-12);  // rad
  EXPECT_LT(dj, 1e-9);
}

TEST(Kinematics, GravityTorqueOfAHorizontalArm) {
  // one joint about y at the origin, 10 kg at 1000 mm along x: torque about +y = m g L (N mm)
  ModelSpec s;
  JointSpec j;
  j.axis = Vec3::UnitY();
  j.mass_kg = 10;
  j.com = Vec3(1000, 0, 0);
  s.joints = {j};
  s.tool.xyz = Vec3(1000, 0, 0);
  const Model m(s);
  VecQ tau;
  VecQ q = VecQ::Zero(1);
  gravity_torque(m, q, tau);
  // weight along -z at +x: (r x F) . y = (z F_x - x F_z) = 1000 * 98.1
  EXPECT_NEAR(tau[0], 10 * 9.81 * 1000, 1e-9);
  q[0] = kPi / 2;  // arm pointing down (-z): no torque
  gravity_torque(m, q, tau);
  EXPECT_NEAR(tau[0], 0, 1e-9);
}

// The torque alone (two vector recursions in the joints' frames) against the torque the derivative
// path computes (the chain walked with rotation matrices, moment arms in the base frame): the kr500
// and UR10 with their masses and a payload, a tilted gravity, and a kr500 with random link masses and
// centres (seeded), 500 configurations each. Truth: the walk's torque; agreement to 1e-9 relative.
TEST(Kinematics, GravityTorqueAloneEqualsTheWalksTorque) {
  KINCAL_SEED_TRACE(8, 9);
  std::mt19937_64 rng(test::test_seed(8));
  std::uniform_real_distribution<double> u(-1, 1);
  ModelSpec tilted = kr500_spec();
  tilted.gravity = Vec3(1.2, -0.7, -9.7);
  ModelSpec random_masses = kr500_spec();
  for (JointSpec& j : random_masses.joints) {
    j.mass_kg = 50 + 200 * (1 + u(rng));
    j.com = Vec3(300 * u(rng), 300 * u(rng), 300 * u(rng));
  }
  ModelSpec ur10 = ur10_spec();
  for (const ModelSpec& spec : {kr500_spec(), ur10, tilted, random_masses}) {
    const Model m(spec);
    std::mt19937_64 rq(test::test_seed(9));
    double worst = 0, largest = 0;
    for (int i = 0; i < 500; ++i) {
      const VecQ q = test::random_q(m, rq) * kDeg;
      VecQ alone, walked;
      MatQ d;
      gravity_torque(m, q, alone);
      gravity_torque(m, q, walked, &d);
      ASSERT_EQ(alone.size(), walked.size());
      worst = std::max(worst, (alone - walked).norm() / (1 + walked.norm()));
      largest = std::max(largest, walked.cwiseAbs().maxCoeff());
    }
    std::printf("gravity torque alone vs walked: worst %.1e relative, largest torque %.0f N mm\n", worst, largest);
    EXPECT_GT(largest, 1e5);  // the robots carry masses: the comparison is not of zeros
    EXPECT_LT(worst, 1e-9);
  }
}

// Every analytic derivative against central finite differences.
TEST(Kinematics, DerivativesMatchFiniteDifferences) {
  KINCAL_SEED_TRACE(4, 12);
  const Model m(perturbed_spec(kr500_spec(), test::test_seed(4), 1.0, 0.05, 0.003));
  ASSERT_TRUE(m.has_compliance());
  std::mt19937_64 rng(test::test_seed(12));
  const double h = 1e-6;
  for (int i = 0; i < 200; ++i) {
    const VecQ q = test::random_q(m, rng) * kDeg;
    VecQ tau;
    MatQ dtau;
    gravity_torque(m, q, tau, &dtau);
    Eigen::Isometry3d t;
    Jac jc;
    fk_jacobian_compliant(m, q, t, jc);
    for (int k = 0; k < 6; ++k) {
      VecQ qp = q, qm = q;
      qp[k] += h;
      qm[k] -= h;
      VecQ tp, tm;
      gravity_torque(m, qp, tp);
      gravity_torque(m, qm, tm);
      const VecQ fd = (tp - tm) / (2 * h);
      EXPECT_LT((fd - dtau.col(k)).norm(), 1e-5 * (1 + dtau.norm())) << "dtau/dq" << k;
      const Eigen::Isometry3d a = fk_compliant(m, qp), b = fk_compliant(m, qm);
      const Vec3 dv = (a.translation() - b.translation()) / (2 * h);
      const Eigen::AngleAxisd aa(a.linear() * b.linear().transpose());
      const Vec3 dw = aa.axis() * aa.angle() / (2 * h);
      EXPECT_LT((dv - jc.block<3, 1>(0, k)).norm(), 1e-4) << "linear column " << k;
      EXPECT_LT((dw - jc.block<3, 1>(3, k)).norm(), 1e-7) << "angular column " << k;
    }
  }
}

// The model's frames in one pass (the sines and cosines of q shared by the gravity torque and the
// walk, theta's from them by the small angle theta - q) against fk_frames at joint_angles: a kr500
// with 1 mm / 0.05 deg errors and compliance 0.003 deg/kN m, with transmission error (harmonics 1, 2)
// and backlash on joints 1-3 (seed 10), 2000 random configurations each: every frame's axis and
// origin and the tool pose agree to rounding (3.5e-12 mm measured; rotations scaled by 1000 mm), held
// to 1e-9; and a compliance 33x larger (angles 0.02-0.04 rad from q at the largest), where the pass
// takes sincos of theta itself beyond 0.01 rad.
TEST(Kinematics, ActualFramesInOnePassEqualTheFramesAtTheActualAngles) {
  KINCAL_SEED_TRACE(10);
  const ModelSpec effects = test::every_effect_spec(test::test_seed(10));
  ModelSpec soft = perturbed_spec(kr500_spec(), test::test_seed(10), 1.0, 0.05, 0.1);
  std::mt19937_64 rng(test::test_seed(10));
  for (const ModelSpec& spec : {effects, soft}) {
    const Model m(spec);
    double worst = 0, largest_step = 0;
    for (int i = 0; i < 2000; ++i) {
      const VecQ q = test::random_q(m, rng) * kDeg;
      EffectContext ctx;
      ctx.dir = VecQ::Constant(6, i % 2 ? 1.0 : -1.0);
      ChainFrames a, b;
      fk_frames_actual(m, q, ctx, a);
      const VecQ theta = joint_angles(m, q, ctx);
      fk_frames(m, theta, b);
      largest_step = std::max(largest_step, (theta - q).cwiseAbs().maxCoeff());
      ASSERT_EQ(a.n, b.n);
      worst = std::max(worst, (a.tool.translation() - b.tool.translation()).norm());
      worst = std::max(worst, (a.tool.linear() - b.tool.linear()).norm() * 1000);
      for (int j = 0; j < a.n; ++j) worst = std::max({worst, (a.z[j] - b.z[j]).norm() * 1000, (a.o[j] - b.o[j]).norm()});
    }
    std::printf("frames in one pass: worst %.1e mm (rotations x 1000 mm), largest theta - q %.4f rad\n", worst,
                largest_step);
    EXPECT_LT(worst, 1e-9);
    EXPECT_GT(largest_step, spec.joints[1].compliance_deg_per_knm > 0.01 ? 0.01 : 1e-4);  // both paths taken
  }
}

// A model's spec with a joint map of order 3 on joint 4 and a transmission error of harmonics 1 and
// 12 (amplitudes 1e-3 rad) on joint 5 added: higher orders, whose series reach less far.
static ModelSpec with_more_effects(ModelSpec spec) {
  spec.effects.push_back({joint_map(3, 3), {3e-4, -2e-4, 1e-4, 2e-4, -5e-5, 7e-5}});
  spec.effects.push_back({Effect{"transmission_error", 4, {1, 12}}, {1e-3, -1e-3, 1e-3, 1e-3}});
  return spec;
}

// JointAnglesNear (the commands' fixed point in compensation: the gravity torque from the
// reference's sines and cosines turned to q, the harmonic joint effects by their Taylor series of
// degree 5 about the reference, backlash from it) against joint_angles at q itself. A kr500 with
// 1 mm / 0.05 deg errors, compliance 0.003 deg/kN m, transmission error (harmonics 1, 2) and
// backlash on joints 1-3 (seed 13); the same with a joint map of order 3 on joint 4 and a
// transmission error of harmonics 1 and 12 (amplitudes 1e-3 rad) on joint 5; and a compliance 33x
// larger. 300 references each, q at steps of 1e-6..3e-2 rad from them in random directions: the
// series' remainder bound (sum k^6 |p| / 720 |d|^6) is below its 1e-18 rad for the small steps and
// above it for order 12 from 1e-3 rad on (4.1 |d|^6), the turned sines and cosines hold to 0.01 rad:
// both ways are taken. Every angle agrees to rounding (measured: printed), held to 1e-14 rad, by the
// operator() and by at6 (compensation's fixed-size form).
TEST(Kinematics, JointAnglesNearAReferenceEqualJointAngles) {
  KINCAL_SEED_TRACE(13);
  const ModelSpec effects = test::every_effect_spec(test::test_seed(13));
  const ModelSpec more = with_more_effects(effects);
  const ModelSpec soft = perturbed_spec(kr500_spec(), test::test_seed(13), 1.0, 0.05, 0.1);
  std::mt19937_64 rng(test::test_seed(13));
  std::normal_distribution<double> normal;
  for (const ModelSpec& spec : {effects, more, soft}) {
    const Model m(spec);
    double worst = 0;
    for (int i = 0; i < 300; ++i) {
      const VecQ ref = test::random_q(m, rng) * kDeg;
      EffectContext ctx;
      ctx.dir = VecQ::Constant(6, i % 2 ? 1.0 : -1.0);
      const JointAnglesNear near(m, ref, ctx);
      for (double step : {0.0, 1e-6, 1e-5, 1e-4, 1e-3, 5e-3, 3e-2}) {
        VecQ dir(6);
        for (int j = 0; j < 6; ++j) dir[j] = normal(rng);
        const VecQ q = ref + step * dir / dir.cwiseAbs().maxCoeff();
        const VecQ exact = joint_angles(m, q, ctx);
        worst = std::max(worst, (near(q) - exact).cwiseAbs().maxCoeff());
        worst = std::max(worst, (VecQ(near.at6(q)) - exact).cwiseAbs().maxCoeff());  // the fixed-size form
      }
    }
    std::printf("joint angles near a reference: worst %.1e rad\n", worst);
    EXPECT_LT(worst, 1e-14);
  }
}

// The band of the joint angles' derivative that JointAnglesNear gives at its reference (the
// preconditioner of compensation's fixed point: the gravity torque's derivative by the joints' own
// frames, symmetric, and the harmonic effects' from their series) against joint_angles' derivative at
// the same angles (by the walk in the base frame): the two kr500 models above and a ur10 with the
// same errors, 300 random references each. The walk takes the arms as differences of first moments
// about the base origin (S - M o: 1e6 kg mm for arms of 1e3 mm), so the two agree to rounding
// relative to the largest entry: 1.1e-12 and 7.6e-13 on the kr500s, 3.7e-10 on the ur10 (whose
// derivative is 1e-5 at most), held to 1e-9; the angles themselves to 1e-14 rad.
TEST(Kinematics, JointAnglesBandAtTheReferenceIsTheDerivativesBand) {
  KINCAL_SEED_TRACE(14);
  const ModelSpec effects = test::every_effect_spec(test::test_seed(14));
  const ModelSpec more = with_more_effects(effects);
  const ModelSpec ur10 = perturbed_spec(ur10_spec(), test::test_seed(14), 1.0, 0.05, 0.003);
  std::mt19937_64 rng(test::test_seed(14));
  for (const ModelSpec& spec : {effects, more, ur10}) {
    const Model m(spec);
    double worst = 0, worst_angle = 0;
    for (int i = 0; i < 300; ++i) {
      const VecQ ref = test::random_q(m, rng) * kDeg;
      EffectContext ctx;
      ctx.dir = VecQ::Constant(6, i % 2 ? 1.0 : -1.0);
      const JointAnglesNear near(m, ref, ctx);
      JointBand band;
      const VecQ theta = near.at_reference(band);
      const auto &lo = band.lower, &dg = band.diag, &up = band.upper;
      MatQ dqd;
      const VecQ exact = joint_angles(m, ref, ctx, &dqd);
      const double scale = (dqd - MatQ::Identity(6, 6)).cwiseAbs().maxCoeff();
      for (int j = 0; j < 6; ++j) {
        worst = std::max(worst, std::abs(dg[j] - (dqd(j, j) - 1)) / scale);
        if (j > 0) worst = std::max(worst, std::abs(lo[j] - dqd(j, j - 1)) / scale);
        if (j < 5) worst = std::max(worst, std::abs(up[j] - dqd(j, j + 1)) / scale);
      }
      EXPECT_EQ(lo[0], 0.0);
      EXPECT_EQ(up[5], 0.0);
      worst_angle = std::max(worst_angle, (theta - exact).cwiseAbs().maxCoeff());
    }
    std::printf("band of the joint angles' derivative: worst %.1e relative, angles %.1e rad\n", worst, worst_angle);
    EXPECT_LT(worst, 1e-9);
    EXPECT_LT(worst_angle, 1e-14);
  }
}
