// The branch data of filtered Cartesian targets (compensation/branch.cpp) in C++: the KUKA Status and Turn,
// ABB confdata and FANUC configuration of a configuration, their text, the difference between two, the
// controller's selection among the nominal IK solutions (with the unwrapping of turned joints) and the border
// tolerance for a taught joint read back across its border.
//
// Truth: the controllers' documented definitions (branch.hpp), evaluated here from the kr500's own
// geometry without the library's arm classification: the wrist centre's x in the A1 system (axis 1 turned
// back to 0) negative is "behind" (KUKA overhead); the elbow is up when A3 is above the angle phi at which
// axes 2, 3 and the wrist centre line up (KUKA: A3 >= phi; phi = atan2(55, 1025) for the kr500); the wrist
// by the sign of A5; KUKA T bit i when A(i+1) < 0; ABB quadrants floor(q / 90) of A1, A4, A6 and cfx = 4
// behind + 2 elbow down + 1 A5 negative; FANUC F (A5 > 0) / N, U / D, T / B and the turns floor((q + 180) /
// 360) of J1, J4, J6.
#include "kincal/compensation/branch.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

using namespace kincal;

namespace {

const ControllerFormat kBranchFormats[] = {ControllerFormat::Krl, ControllerFormat::Rapid, ControllerFormat::FanucLs};

Robot nominal_kr500() {
  auto m = std::make_shared<Model>(kr500_spec());
  return Robot{m, m};
}

double wrap180(double q) { return q - 360.0 * std::floor((q + 180.0) / 360.0); }

/// The kr500's stretched elbow: A3 where axes 2, 3 and the wrist centre line up (deg).
const double kPhi = std::atan2(55.0, 1025.0) / kDeg;

struct Truth {
  bool behind, elbow_up, wrist_negative;
  double x_a1;  // mm
};

Truth truth_of(const Robot& r, const Vec6& q) {
  const Model& m = *r.nominal();
  Vec6 q0 = q;
  q0[0] = 0;  // the A1 system: axis 1 turned back
  const Vec3 wc0 = r.ik().structure().wrist_center;  // at the zero configuration
  const Vec3 wc = fk(m, VecQ(q0 * kDeg)) * (m.tool().inverse() * wc0);
  Truth t;
  t.x_a1 = wc.x() - m.point(0).x();  // the kr500's wrist centre lies along +x at zero: x of the A1 system
  t.behind = t.x_a1 < 0;
  t.elbow_up = wrap180(q[2] - kPhi) > 0;
  t.wrist_negative = wrap180(q[4]) < 0;
  return t;
}

int floor_div(double q, double d) { return static_cast<int>(std::floor(q / d)); }

// the distance (deg) of a configuration from every border its branch data have: a sign change (KUKA T),
// a quadrant (ABB), a turn (FANUC), the elbow at phi and the wrist at 0
double border_distance(const Vec6& q) {
  double d = std::abs(wrap180(q[2] - kPhi));
  for (int j = 0; j < 6; ++j) d = std::min(d, std::abs(q[j] - 90.0 * std::round(q[j] / 90.0)));
  return d;
}

}  // namespace

// set_branch_data and branch_text against the documented definitions on random configurations of the kr500
// inside its limits (both arms, both elbows, both wrists, turned A4 and A6), away from every border by
// 1e-3 deg and from the shoulder singularity by 1 mm.
TEST(Branch, BranchDataAreTheControllersDefinitions) {
  KINCAL_SEED_TRACE(81);
  const Robot r = nominal_kr500();
  std::mt19937_64 rng(test::test_seed(81));
  int checked = 0, behind = 0, down = 0, negative = 0;
  while (checked < test::count(2000)) {
    const Vec6 q = test::random_q(*r.nominal(), rng);
    const Truth t = truth_of(r, q);
    if (border_distance(q) < 1e-3 || std::abs(t.x_a1) < 1.0) continue;
    ++checked;
    behind += t.behind, down += !t.elbow_up, negative += t.wrist_negative;
    ControllerTarget c;
    c.q_deg = q;
    set_branch_data(r, c);
    int kuka_t = 0;
    for (int j = 0; j < 6; ++j) kuka_t |= (q[j] < 0) << j;
    const int s = (t.behind ? 1 : 0) | (t.elbow_up ? 2 : 0) | (t.wrist_negative ? 4 : 0);
    const int cfx = (t.behind ? 4 : 0) | (t.elbow_up ? 0 : 2) | (t.wrist_negative ? 1 : 0);
    const auto turn = [](double v) { return std::to_string(static_cast<int>(std::floor((v + 180.0) / 360.0))); };
    const std::string fanuc = std::string(t.wrist_negative ? "N" : "F") + " " + (t.elbow_up ? "U" : "D") + " " +
                              (t.behind ? "B" : "T") + ", " + turn(q[0]) + ", " + turn(q[3]) + ", " + turn(q[5]);
    ASSERT_EQ(c.kuka_s, s) << q.transpose();
    ASSERT_EQ(c.kuka_t, kuka_t) << q.transpose();
    ASSERT_EQ(branch_text(ControllerFormat::Krl, c), "S " + std::to_string(s) + ", T " + std::to_string(kuka_t));
    ASSERT_EQ(branch_text(ControllerFormat::Rapid, c),
              "cfx " + std::to_string(cfx) + ", cf1 " + std::to_string(floor_div(q[0], 90)) + ", cf4 " +
                  std::to_string(floor_div(q[3], 90)) + ", cf6 " + std::to_string(floor_div(q[5], 90)))
        << q.transpose();
    ASSERT_EQ(branch_text(ControllerFormat::FanucLs, c), fanuc) << q.transpose();
    const ArmClass a = arm_class(r, q);
    ASSERT_NEAR(a.x_a1, t.x_a1, 1e-6);
  }
  // the draws covered every class
  EXPECT_GT(behind, 0);
  EXPECT_GT(down, 0);
  EXPECT_GT(negative, 0);
  EXPECT_LT(behind, checked);
}

// The controller's selection (select_branch: the nominal IK solution whose branch data are the target's, the
// turned joints unwrapped by the T bits, the quadrants or the turn numbers) brings back the configuration the
// target was made of, in each of the three languages: random configurations inside the limits, more than
// 2 deg from the singularities and 1e-3 deg from the borders; the pose the nominal FK of the configuration.
TEST(Branch, SelectionBringsBackTheTaughtConfiguration) {
  KINCAL_SEED_TRACE(82);
  const Robot r = nominal_kr500();
  std::mt19937_64 rng(test::test_seed(82));
  double worst = 0;
  int checked = 0;
  while (checked < test::count(500)) {
    const Vec6 q = test::random_q(*r.nominal(), rng);
    if (border_distance(q) < 1e-3 || test::singularity_distance_deg(*r.nominal(), q) < 2.0) continue;
    ++checked;
    ControllerTarget t;
    t.q_deg = q;
    t.pose = iso_to_pose(fk(*r.nominal(), VecQ(q * kDeg)));
    set_branch_data(r, t);
    for (ControllerFormat f : kBranchFormats) {
      std::string why;
      const auto sel = select_branch(r, f, t, &why);
      ASSERT_TRUE(sel.has_value()) << format_name(f) << ": " << why << " at " << q.transpose();
      worst = std::max(worst, (*sel - q).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LT(worst, 1e-6);  // deg: the same solution (the IK's round trip is 1e-9 mm)
}

// branch_difference names what changed: the same configuration nothing; A4 a turn away (q4 - 360) the turn of
// A4 in every language; the flipped wrist (q4 + 180, -q5, q6 + 180, the same pose) the arm choice; another
// elbow (another IK solution of the pose) the arm choice.
TEST(Branch, DifferenceNamesTheArmAndTheTurns) {
  const Robot r = nominal_kr500();
  Vec6 q;
  q << 10, -70, 100, 30, -40, 60;  // elbow up, wrist negative: S 6, T 18
  ControllerTarget taught;
  taught.q_deg = q;
  set_branch_data(r, taught);
  EXPECT_EQ(branch_text(ControllerFormat::Krl, taught), "S 6, T 18");
  EXPECT_EQ(branch_text(ControllerFormat::Rapid, taught), "cfx 1, cf1 0, cf4 0, cf6 0");
  EXPECT_EQ(branch_text(ControllerFormat::FanucLs, taught), "N U T, 0, 0, 0");
  Vec6 turned = q, flipped = q;
  turned[3] -= 360;
  flipped[3] += 180, flipped[4] = -flipped[4], flipped[5] += 180;
  ASSERT_LT((fk(*r.nominal(), VecQ(flipped * kDeg)).matrix() - fk(*r.nominal(), VecQ(q * kDeg)).matrix()).norm(), 1e-9);
  // another elbow: the nominal solution of the pose with the elbow down
  const IkSolutions all = r.ik().solve(fk(*r.nominal(), VecQ(q * kDeg)), IkOptions(q));
  int other = -1;
  for (int k = 0; k < all.count; ++k)
    if (!truth_of(r, all.sol[k].q_deg).elbow_up && !truth_of(r, all.sol[k].q_deg).behind) other = k;
  ASSERT_GE(other, 0);
  for (ControllerFormat f : kBranchFormats) {
    SCOPED_TRACE(format_name(f));
    BranchDifference d = branch_difference(r, f, taught, q);
    EXPECT_FALSE(d.arm);
    EXPECT_TRUE(d.turns.empty());
    d = branch_difference(r, f, taught, turned);
    EXPECT_FALSE(d.arm);
    EXPECT_EQ(d.turns, std::vector<int>{3});
    d = branch_difference(r, f, taught, flipped);
    EXPECT_TRUE(d.arm);
    d = branch_difference(r, f, taught, all.sol[static_cast<size_t>(other)].q_deg);
    EXPECT_TRUE(d.arm);
  }
  // A1 from 10 to -10 deg: KUKA's T bit 0 and ABB's cf1 (quadrant 0 to -1) change, FANUC's turn of J1 (0) does not
  Vec6 a1 = q;
  a1[0] = -10;
  EXPECT_EQ(branch_difference(r, ControllerFormat::Krl, taught, a1).turns, std::vector<int>{0});
  EXPECT_EQ(branch_difference(r, ControllerFormat::Rapid, taught, a1).turns, std::vector<int>{0});
  EXPECT_TRUE(branch_difference(r, ControllerFormat::FanucLs, taught, a1).turns.empty());  // the same turn 0
}

// A joint taught exactly on a border (A1 = 0: KUKA T bit 0 clear, ABB cf1 0) and read back from the printed
// pose 2e-6 deg across it (the pose of A1 = -2e-6): the controller's exact selection (tolerance 0) takes KUKA's
// A1 >= 0 at its word, a whole turn away (359.999998 deg), and finds no ABB solution in quadrant 0; with a
// border tolerance of 1e-4 deg both take the taught side's neighbour, A1 = -2e-6.
TEST(Branch, BorderToleranceUnwrapsAJointReadBackAcrossItsBorder) {
  const Robot r = nominal_kr500();
  Vec6 q;
  q << 0, -65, 90, -30, -60, -40;
  ControllerTarget t;
  t.q_deg = q;
  set_branch_data(r, t);
  EXPECT_EQ(t.kuka_t & 1, 0);
  EXPECT_EQ(t.abb_conf[0], 0);
  Vec6 read = q;
  read[0] = -2e-6;
  t.pose = iso_to_pose(fk(*r.nominal(), VecQ(read * kDeg)));
  std::string why;
  const auto krl_exact = select_branch(r, ControllerFormat::Krl, t, &why, 0);
  ASSERT_TRUE(krl_exact.has_value()) << why;
  EXPECT_NEAR((*krl_exact)[0], 360.0 - 2e-6, 1e-7);
  EXPECT_FALSE(select_branch(r, ControllerFormat::Rapid, t, &why, 0).has_value());
  EXPECT_EQ(why, "no solution has the target's branch data");
  for (ControllerFormat f : {ControllerFormat::Krl, ControllerFormat::Rapid}) {
    const auto sel = select_branch(r, f, t, &why, 1e-4);
    ASSERT_TRUE(sel.has_value()) << format_name(f) << ": " << why;
    EXPECT_LT((*sel - read).cwiseAbs().maxCoeff(), 1e-7) << format_name(f) << ": " << sel->transpose();
  }
  // FANUC's turn border is at +-180 deg: A6 taught at 180 (turn 1), read back at 180 + 2e-6 - 360 = -179.999998
  Vec6 q6 = q;
  q6[5] = 180;
  ControllerTarget t6;
  t6.q_deg = q6;
  set_branch_data(r, t6);
  Vec6 read6 = q6;
  read6[5] = 180 - 2e-6;  // turn 0 by the numbers
  t6.pose = iso_to_pose(fk(*r.nominal(), VecQ(read6 * kDeg)));
  const auto fanuc = select_branch(r, ControllerFormat::FanucLs, t6, &why, 0);
  ASSERT_TRUE(fanuc.has_value()) << why;
  // the turn number is written after the letters: the selection adds its 360 deg to the wrapped angle
  EXPECT_NEAR((*fanuc)[5], wrap180(read6[5]) + 360.0 * std::floor((q6[5] + 180.0) / 360.0), 1e-7);
}

// The same at FANUC's turn border (+-180 deg, a multiple of 90): J6 taught at 180 (turn 1) read back from its
// printed pose at 179.999998, J4 taught at -180 (turn 0) read back at -180.000002. With a border tolerance of
// 1e-4 deg the selection is to take the taught side's neighbour (branch.hpp: "a joint that close to a border
// counts on either side of it"), 179.999998 and -180.000002, as KUKA's and ABB's do above.
TEST(Branch, FanucBorderToleranceAtTheTurnBorder) {
  const Robot r = nominal_kr500();
  Vec6 q;
  q << 0, -65, 90, -180, -60, 180;
  ControllerTarget t;
  t.q_deg = q;
  set_branch_data(r, t);
  ASSERT_EQ(branch_text(ControllerFormat::FanucLs, t), "N U T, 0, 0, 1");
  Vec6 read = q;
  read[3] = -180 - 2e-6;
  read[5] = 180 - 2e-6;
  t.pose = iso_to_pose(fk(*r.nominal(), VecQ(read * kDeg)));
  std::string why;
  const auto sel = select_branch(r, ControllerFormat::FanucLs, t, &why, 1e-4);
  ASSERT_TRUE(sel.has_value()) << why;
  EXPECT_LT((*sel - read).cwiseAbs().maxCoeff(), 1e-7) << sel->transpose();
}

// Branch data need the closed form's structure: a robot without it (the UR10) is refused, naming why.
TEST(Branch, RobotWithoutTheClosedFormIsRefused) {
  auto m = std::make_shared<Model>(ur10_spec());
  const Robot r{m, m};
  try {
    arm_class(r, Vec6::Zero());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("axes 2 and 3 are parallel"), std::string::npos) << e.what();
  }
}
