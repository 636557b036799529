#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/robots.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

using namespace kincal;

namespace {

// Checks that every solution reproduces the pose and that the generating configuration is among them.
void check_round_trip(const Model& m, const IkSolver& ik, const Vec6& q, double& worst_p, double& worst_r) {
  const Eigen::Isometry3d t = fk(m, VecQ(q * kDeg));
  const IkSolutions s = ik.solve(t, IkOptions(q));
  ASSERT_EQ(s.status, IkStatus::Ok);
  ASSERT_GE(s.count, 1);
  ASSERT_LE(s.count, 8);
  bool found = false;
  for (int i = 0; i < s.count; ++i) {
    ASSERT_TRUE(s.sol[i].q_deg.allFinite());
    const Eigen::Isometry3d ti = fk(m, VecQ(s.sol[i].q_deg * kDeg));
    worst_p = std::max(worst_p, (ti.translation() - t.translation()).norm());
    worst_r = std::max(worst_r, test::rot_dist(ti.linear(), t.linear()));
    double d = 0;
    for (int j = 0; j < 6; ++j) d = std::max(d, std::abs(std::remainder(s.sol[i].q_deg[j] - q[j], 360.0)));
    found = found || d < 1e-6;
  }
  EXPECT_TRUE(found) << "the generating configuration is not among the " << s.count << " solutions";
}

// A random robot of the class: axes 2 and 3 parallel, axes 4, 5, 6 through one point, any offsets;
// with orthogonal_wrist, axis 5 normal to axes 4 and 6 and these parallel (or opposite) at zero, the
// wrist of industrial robots, whose second wrist solution the IK takes as the flip of the first.
// With scaled_axes, the axes of joints 2 and 3 are given with different lengths, so that after the
// model's normalisation they are parallel only to rounding (the IK's general path, not its shortcut
// for bitwise-parallel axes).
ModelSpec random_robot(std::mt19937_64& rng, bool orthogonal_wrist = false, bool scaled_axes = false) {
  std::normal_distribution<double> nd(0, 1);
  auto rv = [&] { return Vec3(nd(rng), nd(rng), nd(rng)); };
  ModelSpec s;
  s.name = "random";
  Vec3 w1 = rv().normalized(), w2 = rv().normalized();
  const Vec3 wc = rv() * 600;
  const Vec3 pts[6] = {rv() * 300, rv() * 300, rv() * 500, wc, wc, wc};
  Vec3 axes[6] = {w1, w2, (nd(rng) > 0 ? 1 : -1) * w2, rv().normalized(), rv().normalized(), rv().normalized()};
  if (scaled_axes) {
    axes[1] *= 2.5;
    axes[2] *= 0.7;
  }
  if (orthogonal_wrist) {
    axes[4] = axes[3].cross(rv()).normalized();
    axes[5] = (nd(rng) > 0 ? 1 : -1) * axes[3];
  }
  for (int j = 0; j < 6; ++j) {
    JointSpec js;
    js.point = pts[j];
    js.axis = axes[j];
    js.lower_deg = -360;
    js.upper_deg = 360;
    s.joints.push_back(js);
  }
  s.tool.xyz = wc + rv() * 200;
  s.tool.abc = Vec3(nd(rng) * 60, nd(rng) * 30, nd(rng) * 60);
  s.gravity = Vec3::Zero();
  return s;
}

}  // namespace

TEST(Ik, Kr500AllSolutionsRoundTrip) {
  KINCAL_SEED_TRACE(21);
  const Model m(kr500_spec());
  const IkSolver ik(m);
  std::mt19937_64 rng(test::test_seed(21));
  double wp = 0, wr = 0;
  for (int i = 0, n = test::count(5000); i < n; ++i) check_round_trip(m, ik, test::random_q(m, rng), wp, wr);
  EXPECT_LT(wp, 1e-9);  // mm
  EXPECT_LT(wr, 1e-9);  // rad
}

TEST(Ik, AnyOffsetsRoundTrip) {
  KINCAL_SEED_TRACE(22);
  std::mt19937_64 rng(test::test_seed(22));
  double wp = 0, wr = 0;
  int robots = 0, inexact23 = 0;
  for (int r = 0; r < 200; ++r) {
    const bool orthogonal = r % 2 == 1;  // half with the flip-symmetric wrist, half with any wrist
    const Model m(random_robot(rng, orthogonal, r % 4 >= 2));
    const IkSolver ik(m);
    ASSERT_TRUE(ik.structure().spherical_wrist_parallel_23) << ik.structure().reason;
    ASSERT_EQ(ik.structure().wrist_flip, orthogonal);
    inexact23 += ik.constants().sigma23 == 0;
    ++robots;
    for (int i = 0; i < 50; ++i) {
      Vec6 q;
      for (int j = 0; j < 6; ++j) q[j] = std::uniform_real_distribution<double>(-180, 180)(rng);
      check_round_trip(m, ik, q, wp, wr);
    }
  }
  EXPECT_EQ(robots, 200);
  EXPECT_GT(inexact23, 20);  // both paths of the elbow taken
  std::printf("FK(IK(T)) - T on 200 random robots: %.2e mm, %.2e rad\n", wp, wr);
  EXPECT_LT(wp, 1e-9);
  EXPECT_LT(wr, 1e-9);
}

TEST(Ik, OutOfReachAndSingularPosesGiveClearAnswers) {
  const Model m(kr500_spec());
  const IkSolver ik(m);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Vec3(9000, 0, 1000);
  const IkSolutions s = ik.solve(far);
  EXPECT_EQ(s.status, IkStatus::OutOfReach);
  EXPECT_EQ(s.count, 0);
  // the wrist singularity q5 = 0: solutions exist, are finite, reproduce the pose and are flagged
  Vec6 q;
  q << 10, -80, 100, 30, 0, -20;
  const Eigen::Isometry3d t = fk(m, VecQ(q * kDeg));
  const IkSolutions w = ik.solve(t, IkOptions(q));
  ASSERT_EQ(w.status, IkStatus::Ok);
  int flagged = 0;
  for (int i = 0; i < w.count; ++i) {
    ASSERT_TRUE(w.sol[i].q_deg.allFinite());
    flagged += w.sol[i].wrist_singular;
    const Eigen::Isometry3d ti = fk(m, VecQ(w.sol[i].q_deg * kDeg));
    EXPECT_LT((ti.translation() - t.translation()).norm(), 1e-9);
    EXPECT_LT(test::rot_dist(ti.linear(), t.linear()), 1e-9);
  }
  EXPECT_GT(flagged, 0);
}

TEST(Ik, NearestSolutionFollowsTheReference) {
  const Model m(kr500_spec());
  Vec6 q;
  q << 20, -60, 80, 40, 50, -30;
  const IkSolutions s = IkSolver(m).solve(fk(m, VecQ(q * kDeg)), IkOptions(q));
  const int k = s.nearest(q.data());
  ASSERT_GE(k, 0);
  EXPECT_LT((s.sol[k].q_deg - q).norm(), 1e-9);
}
