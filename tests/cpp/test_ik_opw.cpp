// The closed-form IK against opw_kinematics (benchmarks/third_party/opw_kinematics, Apache-2.0, the
// benchmark's peer) on the six example robots its authors ship (opw_parameters_examples.h of
// github.com/Jmeyer1292/opw_kinematics at 8a32bda: ABB IRB 2400/10, 2600-12/1.65, 4600-60/2.05,
// FANUC R-2000iB/200R, KUKA KR 6 R700 sixx, Staubli TX40, the last with a lateral offset b; their
// values below, in mm). Each robot is built as a kincal model in opw's own zero and directions
// (offsets 0, signs +1: the geometry is what is compared), checked by FK against opw's forward, then
// both IKs solve the same targets: every kincal solution is one of opw's, and every opw solution that
// reaches the target is one of kincal's.
#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>
#include <opw_kinematics/opw_kinematics.h>

#include <random>

using namespace kincal;

namespace {

struct Opw {
  const char* name;
  double a1, a2, b, c1, c2, c3, c4;  // mm
};

const Opw kRobots[] = {
    {"ABB IRB 2400/10", 100, -135, 0, 615, 705, 755, 85},      {"FANUC R-2000iB/200R", 720, -225, 0, 600, 1075, 1280, 235},
    {"KUKA KR 6 R700 sixx", 25, -35, 0, 400, 315, 365, 80},   {"Staubli TX40", 0, 0, 35, 320, 225, 225, 65},
    {"ABB IRB 2600-12/1.65", 150, -115, 0, 445, 700, 795, 85}, {"ABB IRB 4600-60/2.05", 175, -175, 0, 495, 900, 960, 135},
};

opw_kinematics::Parameters<double> params(const Opw& r) {
  opw_kinematics::Parameters<double> p;
  p.a1 = r.a1, p.a2 = r.a2, p.b = r.b, p.c1 = r.c1, p.c2 = r.c2, p.c3 = r.c3, p.c4 = r.c4;
  return p;  // offsets 0, signs +1
}

// opw's zero: axis 1 = z through the origin, axes 2, 3 along y through (a1, 0, c1) and (a1, 0, c1 + c2),
// the wrist centre at (a1 + a2, b, c1 + c2 + c3) with axes 4, 6 along z and 5 along y, the flange c4 above it.
ModelSpec model(const Opw& r) {
  const Vec3 wc(r.a1 + r.a2, r.b, r.c1 + r.c2 + r.c3);
  const Vec3 pts[6] = {Vec3::Zero(), Vec3(r.a1, 0, r.c1), Vec3(r.a1, 0, r.c1 + r.c2), wc, wc, wc};
  const Vec3 axes[6] = {Vec3::UnitZ(), Vec3::UnitY(), Vec3::UnitY(), Vec3::UnitZ(), Vec3::UnitY(), Vec3::UnitZ()};
  ModelSpec s;
  s.name = r.name;
  test::add_joints(s, pts, axes);
  s.tool.xyz = wc + Vec3(0, 0, r.c4);
  s.tool.abc = Vec3::Zero();
  s.gravity = Vec3::Zero();
  return s;
}

double angle_gap_deg(double a_deg, double b_rad) { return std::abs(std::remainder(a_deg - b_rad / kDeg, 360.0)); }

}  // namespace

TEST(IkOpw, TheSixExampleRobotsOfOpwKinematicsGiveItsSolutions) {
  KINCAL_SEED_TRACE(24);
  std::mt19937_64 rng(test::test_seed(24));
  std::uniform_real_distribution<double> u(-170, 170);
  for (const Opw& r : kRobots) {
    SCOPED_TRACE(r.name);
    const Model m(model(r));
    const IkSolver ik(m);
    ASSERT_TRUE(ik.structure().ortho_parallel) << ik.structure().reason;
    const auto p = params(r);
    int poses = 0, solutions = 0, opw_reaching = 0;
    double worst_fk = 0, worst_gap = 0;
    while (poses < 500) {
      std::array<double, 6> th;
      for (double& t : th) t = u(rng) * kDeg;
      if (std::abs(std::sin(th[4])) < std::sin(2 * kDeg)) continue;  // the wrist singularity
      Vec6 q;
      for (int j = 0; j < 6; ++j) q[j] = th[static_cast<size_t>(j)] / kDeg;
      const Eigen::Isometry3d t = fk(m, VecQ(q * kDeg));
      const Eigen::Isometry3d f = opw_kinematics::forward(p, th);
      worst_fk = std::max(worst_fk, (t.translation() - f.translation()).norm());
      worst_fk = std::max(worst_fk, test::rot_dist(t.linear(), f.linear()));
      const IkSolutions s = ik.solve(t);
      ASSERT_EQ(s.status, IkStatus::Ok);
      if (test::near_singular(s, 2.0)) continue;  // opw's arccosines lose digits there
      ++poses;
      const auto o = opw_kinematics::inverse(p, t);
      for (int i = 0; i < s.count; ++i) {  // each of ours is one of opw's
        double best = 1e9;
        for (const auto& os : o) {
          double g = 0;
          for (int j = 0; j < 6; ++j) g = std::max(g, std::isfinite(os[j]) ? angle_gap_deg(s.sol[i].q_deg[j], os[j]) : 1e9);
          best = std::min(best, g);
        }
        worst_gap = std::max(worst_gap, best);
        ++solutions;
      }
      for (const auto& os : o) {  // each of opw's that reaches the target is one of ours
        bool finite = true;
        for (double v : os) finite = finite && std::isfinite(v);
        if (!finite) continue;
        const Eigen::Isometry3d to = opw_kinematics::forward(p, os);
        if ((to.translation() - t.translation()).norm() > 1e-6 || test::rot_dist(to.linear(), t.linear()) > 1e-9) continue;
        ++opw_reaching;
        double best = 1e9;
        for (int i = 0; i < s.count; ++i) {
          double g = 0;
          for (int j = 0; j < 6; ++j) g = std::max(g, angle_gap_deg(s.sol[i].q_deg[j], os[static_cast<size_t>(j)]));
          best = std::min(best, g);
        }
        EXPECT_LT(best, 1e-7) << "an opw solution kincal does not give";
      }
    }
    std::printf("%-22s FK vs opw %.1e; %d kincal solutions on %d poses, worst gap to opw's %.1e deg; %d opw solutions reach\n",
                r.name, worst_fk, solutions, poses, worst_gap, opw_reaching);
    EXPECT_LT(worst_fk, 1e-9);
    EXPECT_LT(worst_gap, 1e-7);
    EXPECT_EQ(solutions, opw_reaching);  // the same solution sets
  }
}
