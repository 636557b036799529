#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/robots.hpp"

#include "test_util.hpp"

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <algorithm>

using namespace kincal;

namespace {

// The pose determines the angles only as well as the Jacobian is conditioned: where two branches
// nearly meet, the rounding of the pose (1e-12 rad) moves the solution by about c / sigma_min, sigma_min
// the smallest singular value of the geometric Jacobian (rows in mm and rad per rad). Seed 38 of
// AnyOffsetsRoundTrip draws a random wrist at sigma_min 5.8e-6: its two wrist solutions 0.13 deg
// apart, the generator found 4.7e-6 deg off (c = 4.8e-13 rad), the pose reproduced to 2e-10 mm. So
// the generator is asked for to 1e-6 deg times kDetermined / sigma_min where sigma_min is below
// kDetermined (where c / sigma_min stays below 3e-8 deg), to 1e-6 deg elsewhere, and never to more
// than 0.01 deg.
constexpr double kDetermined = 1e-3;

// Checks that every solution reproduces the pose and that the generating configuration is among them
// (to 1e-6 deg, widened near a singularity as above; ++widened where it is).
void check_round_trip(const Model& m, const IkSolver& ik, const Vec6& q, double& worst_p, double& worst_r,
                      int& widened) {
  Eigen::Isometry3d tool;
  Jac jac;
  fk_jacobian(m, VecQ(q * kDeg), tool, jac);
  const double sigma_min = Eigen::JacobiSVD<Jac>(jac).singularValues().minCoeff();
  widened += sigma_min < kDetermined;
  // (at most 0.01 deg, far below the gap between branches that rounding cannot tell apart)
  const double tol_deg = std::min(1e-2, 1e-6 * std::max(1.0, kDetermined / sigma_min));
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
    found = found || d < tol_deg;
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
  test::add_joints(s, pts, axes);
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
  int widened = 0;
  const int n = test::count(5000);
  for (int i = 0; i < n; ++i) check_round_trip(m, ik, test::random_q(m, rng), wp, wr, widened);
  EXPECT_LE(50 * widened, n);
  EXPECT_LT(wp, 1e-9);  // mm
  EXPECT_LT(wr, 1e-9);  // rad
}

TEST(Ik, AnyOffsetsRoundTrip) {
  KINCAL_SEED_TRACE(22);
  std::mt19937_64 rng(test::test_seed(22));
  double wp = 0, wr = 0;
  int robots = 0, inexact23 = 0, widened = 0;
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
      check_round_trip(m, ik, q, wp, wr, widened);
    }
  }
  EXPECT_EQ(robots, 200);
  EXPECT_GT(inexact23, 20);  // both paths of the elbow taken
  EXPECT_LT(widened, 200);   // of 10,000 configurations: 46-94 at seeds 1-45
  std::printf("FK(IK(T)) - T on 200 random robots: %.2e mm, %.2e rad; the generator asked for to a widened "
              "tolerance at %d of 10000 configurations (near a singularity)\n", wp, wr, widened);
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

namespace {

// A random ortho-parallel robot (the class IkSolver solves by plane rotations): axis 1 normal to
// axis 2, axis 3 = +-axis 2, a wrist with the flip (axis 5 normal to axis 4, axis 6 = +-axis 4), any
// offsets, any base placement, axis signs and limits (some narrower than a turn, some wider).
ModelSpec random_ortho_robot(std::mt19937_64& rng) {
  std::normal_distribution<double> nd(0, 1);
  std::uniform_real_distribution<double> ud(0, 1);
  auto rv = [&] { return Vec3(nd(rng), nd(rng), nd(rng)); };
  auto sgn = [&] { return nd(rng) > 0 ? 1.0 : -1.0; };
  const Mat3 r0 = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  const Vec3 o = rv() * 200;
  const Vec3 w1 = r0 * Vec3::UnitZ() * sgn(), w2 = r0 * Vec3::UnitY() * sgn();
  const Vec3 p2 = o + r0 * Vec3(300 * ud(rng), 0, 300 + 500 * ud(rng));
  const Vec3 p3 = p2 + r0 * Vec3(400 * nd(rng), 100 * nd(rng), 400 * nd(rng));
  const Vec3 wc = p3 + rv() * 500;
  const Vec3 w4 = rv().normalized(), w5 = w4.cross(rv()).normalized(), w6 = sgn() * w4;
  const Vec3 pts[6] = {o, p2, p3, wc, wc, wc};
  const Vec3 axes[6] = {w1, w2, sgn() * w2, w4, w5, w6};
  ModelSpec s;
  s.name = "random_ortho";
  double lo[6], hi[6];
  for (int j = 0; j < 6; ++j) {
    lo[j] = -20 - 330 * ud(rng);
    hi[j] = 20 + 330 * ud(rng);
  }
  test::add_joints(s, pts, axes, lo, hi);
  s.tool.xyz = wc + rv() * 200;
  s.tool.abc = Vec3(nd(rng) * 60, nd(rng) * 30, nd(rng) * 60);
  s.gravity = Vec3::Zero();
  return s;
}

// What solve promises of each angle, checked without its code: within the limits exactly when
// flagged; inside, no other whole turn (|k| <= 2) inside is nearer the reference; outside, in
// [-180, 180].
void check_shifts(const Model& m, const IkSolutions& s, const Vec6& ref) {
  for (int i = 0; i < s.count; ++i) {
    bool inside = true;
    for (int j = 0; j < 6; ++j) {
      const auto& js = m.spec().joints[j];
      const double q = s.sol[i].q_deg[j];
      inside = inside && q >= js.lower_deg - 1e-9 && q <= js.upper_deg + 1e-9;
    }
    ASSERT_EQ(inside, s.sol[i].within_limits) << "solution " << i;
    for (int j = 0; j < 6; ++j) {
      const auto& js = m.spec().joints[j];
      const double q = s.sol[i].q_deg[j];
      if (!inside) {
        if (q >= js.lower_deg - 1e-9 && q <= js.upper_deg + 1e-9) continue;  // another joint is out
        EXPECT_LE(std::abs(q), 180 + 1e-9) << "solution " << i << " joint " << j;
        continue;
      }
      for (int k = -3; k <= 3; ++k) {
        const double c = q + 360.0 * k;
        if (k == 0 || c < js.lower_deg - 1e-9 || c > js.upper_deg + 1e-9 || std::abs(c - q) > 720 + 1e-6) continue;
        EXPECT_GE(std::abs(c - ref[j]), std::abs(q - ref[j]) - 1e-9) << "solution " << i << " joint " << j;
      }
    }
  }
}

}  // namespace

// The ortho-parallel form (plane rotations) against the vector form of the same subproblems on
// 10,000 poses of the kr500 and 10,000 of 50 random ortho-parallel robots, away from the singularities
// (|q5| > 1 deg, wrist centre more than 1 mm from axis 1, the two shoulder and the two elbow
// solutions more than 1 deg apart), each with a random reference within the
// limits and with the generating configuration as reference, all branches and the nearest branch:
// the same count, flags and angles to 1e-9 deg on the kr500 (1e-7 on the random robots, see below).
// At a tie (a candidate exactly half a turn from the
// reference, as the shoulder's other solution is from the generating q1) the two forms may round
// to either turn: there the angles agree modulo 360 and are equally near the reference.
TEST(Ik, OrthoParallelFormEqualsTheVectorForm) {
  KINCAL_SEED_TRACE(23);
  std::mt19937_64 rng(test::test_seed(23));
  std::vector<ModelSpec> robots = {kr500_spec()};
  for (int r = 0; r < 50; ++r) robots.push_back(random_ortho_robot(rng));
  long compared = 0, angles = 0, ties = 0;
  double worst = 0, worst_random = 0;
  for (size_t r = 0; r < robots.size(); ++r) {
    const Model m(robots[r]);
    const IkSolver fast(m), vec(m, IkForm::PadenKahan);
    ASSERT_TRUE(fast.structure().ortho_parallel) << "robot " << r << ": " << fast.structure().reason;
    ASSERT_FALSE(vec.structure().ortho_parallel);
    const int poses = r == 0 ? test::count(10000) : test::count(10000) / 50;
    for (int n = 0; n < poses;) {
      const Vec6 q = test::random_q(m, rng);
      if (std::abs(std::remainder(q[4], 360.0)) < 1.0 && robots[r].joints[4].axis.cross(robots[r].joints[3].axis).norm() > 0.5)
        continue;  // the wrist singularity (q5 = 0 where axes 4 and 6 align at zero)
      const Eigen::Isometry3d t = fk(m, VecQ(q * kDeg));
      const Vec3 wc = t * (m.tool().inverse() * fast.structure().wrist_center);
      const Vec3 w1 = m.axis(0), p1 = m.point(0);
      if (((wc - p1) - w1 * w1.dot(wc - p1)).norm() < 1.0) continue;  // the shoulder singularity
      const IkSolutions one = fast.solve(t, IkOptions(q));
      if (test::near_singular(one, 1.0)) continue;  // each form's rounding is magnified there
      ++n;
      const Vec6 random_ref = test::random_q(m, rng);
      // a reference beyond the limits: the solves' general path to degrees (IkSolver::to_degrees)
      const Vec6 far_ref = random_ref + Vec6::Constant(400.0);
      for (const Vec6& ref : {q, random_ref, far_ref}) {
        for (Branches b : {Branches::All, Branches::NearestReference}) {
          const IkSolutions a = fast.solve(t, IkOptions(ref, b)), v = vec.solve(t, IkOptions(ref, b));
          ASSERT_EQ(a.status, v.status);
          ASSERT_EQ(a.count, v.count) << "robot " << r;
          check_shifts(m, a, ref);
          for (int i = 0; i < a.count; ++i) {
            EXPECT_EQ(a.sol[i].within_limits, v.sol[i].within_limits);
            EXPECT_EQ(a.sol[i].wrist_singular, v.sol[i].wrist_singular);
            EXPECT_EQ(a.sol[i].approximate, v.sol[i].approximate);
            for (int j = 0; j < 6; ++j) {
              const double d = a.sol[i].q_deg[j] - v.sol[i].q_deg[j];
              ++angles;
              if (std::abs(d) > 180) {  // a tie: equally near the reference, the same angle
                ++ties;
                EXPECT_LT(std::abs(std::remainder(d, 360.0)), 1e-7) << "robot " << r << " solution " << i << " joint " << j;
                EXPECT_NEAR(std::abs(a.sol[i].q_deg[j] - ref[j]), std::abs(v.sol[i].q_deg[j] - ref[j]), 1e-7);
                continue;
              }
              (r == 0 ? worst : worst_random) = std::max(r == 0 ? worst : worst_random, std::abs(d));
            }
          }
          ++compared;
        }
      }
    }
  }
  std::printf("ortho-parallel vs vector form: %ld solves, worst %.2e deg on the kr500, %.2e deg on the random "
              "robots, %ld ties in %ld angles\n", compared, worst, worst_random, ties, angles);
  EXPECT_LT(worst, 1e-9);
  // the random robots' tilted axes leave poses near two singularities at once (an elbow 6 deg from
  // folded and a wrist 2 deg from aligned): there both forms' 1e-11 deg on q2 grow to 1e-9 deg on q4
  EXPECT_LT(worst_random, 1e-7);
  EXPECT_LT(ties, angles / 100);  // ties are the exception
}
