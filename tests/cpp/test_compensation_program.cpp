// The compensation of one pose in a program (solve_pose: nominal IK start, corrected start, Newton):
// convergence within five iterations on random reachable poses, and no iteration on a nominal model.
#include "kincal/compensation/pose.hpp"
#include "kincal/compensation/program.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using namespace kincal;

namespace {

struct Stats {
  int poses = 0, within5 = 0, failed = 0;
  double worst_mm = 0, worst_deg = 0;
};

// Truth: a kr500 with 1 mm / 0.05 deg geometric errors and joint compliance (seed 5). Desired
// poses are where that robot goes at random configurations inside the limits (1 deg margin) and
// more than min_sing_deg from its singularities, so every pose is reachable. No noise.
Stats run(bool finite_difference, bool corrected_start, double min_sing_deg, int n, unsigned robot_seed = 5,
          unsigned pose_seed = 31) {
  auto nom = std::make_shared<Model>(kr500_spec());
  auto cal = std::make_shared<Model>(perturbed_spec(kr500_spec(), test::test_seed(robot_seed), 1.0, 0.05, 0.003));
  const Robot robot{nom, cal};
  ProgramOptions opt;
  opt.corrected_start = corrected_start;
  opt.comp.finite_difference = finite_difference;
  opt.comp.epsilon = 1e-18;  // |F| < 1e-9: the accuracy asked for (the paper's 1e-15 is the default)
  opt.comp.max_iterations = 30;
  std::mt19937_64 rng(test::test_seed(pose_seed));
  Stats st;
  while (st.poses < n) {
    const Vec6 q = test::random_q(*nom, rng, 1.0);
    if (test::singularity_distance_deg(*nom, q) < min_sing_deg) continue;
    const Pose6 target = iso_to_pose(fk_compliant(*cal, VecQ(q * kDeg)));
    ++st.poses;
    const PoseSolution s = solve_pose(robot, opt, target, q);
    if (!s.ok()) {
      ++st.failed;
      continue;
    }
    st.within5 += s.iterations <= 5;
    const Vec6 f = pose_deviation(*cal, s.q_deg, target);
    st.worst_mm = std::max(st.worst_mm, f.head<3>().norm());
    st.worst_deg = std::max(st.worst_deg, f.tail<3>().norm());
  }
  return st;
}

// The iteration stops on its own evaluation of F and the check evaluates F again by pose_deviation
// (fk_model): the two round apart. Each rounds the FK (the ulp of 3000 mm is 4.5e-13 mm) and the
// actual joint angles q + d(q) (with compliance or joint effects; an ulp of an angle between 2 and 4
// rad is 4.4e-16 rad, which moves the tool 1.3e-12 mm at the kr500's 3 m reach), and the chord steps
// and the commands' fixed point converge linearly, so the last iterate may stop just under 1e-9 mm:
// the position is checked to 1e-9 mm plus 5e-12. Measured over KINCAL_TEST_SEED 1-40 (the three tests
// below, 11 runs of 5000 poses per seed): at most 1.88e-12 mm above 1e-9 at 0390887 (seed 33) and
// 1.38e-12 since the twenty-sixth session (seed 10). Until then the allowance was 1e-12 (the FK's
// rounding alone), which seed 33 exceeded on 0390887 already; until the twenty-fifth session it was 0.
constexpr double kFkRoundingMm = 5e-12;

double expect_999(const Stats& s, const char* what, double at_least = 0.999) {
  const double rate = static_cast<double>(s.within5) / s.poses;
  std::printf("%s: %d poses, %.4f%% within 5 iterations, %d failed, worst %.5e mm %.2e deg\n", what, s.poses,
              100 * rate, s.failed, s.worst_mm, s.worst_deg);
  EXPECT_GE(rate, at_least) << what;
  EXPECT_LT(s.worst_mm, 1e-9 + kFkRoundingMm) << what;
  EXPECT_LT(s.worst_deg, 1e-9) << what;
  return rate;
}

// The same on five calibrated robots (each its own errors and poses): a robot's rate depends on how
// many of its poses fall 1-2 deg from the elbow's singularity, where some take 6-7 iterations (16
// robots, KINCAL_TEST_SEED 0-15: 99.70-100%, median 99.96%; the slow poses of the 99.70% robot all lay
// 1.07-1.79 deg from it). Claimed: 99.9% in the median of the five, and no robot below 99.5%.
void expect_999_over_robots(bool finite_difference, const char* what) {
  std::vector<double> rates;
  for (unsigned k = 0; k < 5; ++k)
    rates.push_back(expect_999(run(finite_difference, true, 1.0, test::count(5000), 5 + 100 * k, 31 + 100 * k), what,
                               0.995));
  std::nth_element(rates.begin(), rates.begin() + 2, rates.end());
  EXPECT_GE(rates[2], 0.999) << what << ": the median robot";
}

}  // namespace

TEST(Compensation, AnalyticConvergesWithinFiveIterations) {
  KINCAL_SEED_TRACE(5, 31, 105, 131);
  expect_999_over_robots(false, "analytic, corrected start, >1 deg from singularities");
}

TEST(Compensation, FiniteDifferenceConvergesWithinFiveIterations) {
  KINCAL_SEED_TRACE(5, 31, 105, 131);
  expect_999_over_robots(true, "finite differences, corrected start, >1 deg");
}

// The paper's start (nominal IK solution, no correction): Newton's basin shrinks near the
// stretched-arm singularity; at more than 10 deg from every singularity it still meets 99.9%.
TEST(Compensation, PaperStartAwayFromSingularities) {
  KINCAL_SEED_TRACE(5, 31);
  expect_999(run(false, false, 10.0, test::count(5000)), "analytic, paper start, >10 deg");
  expect_999(run(true, false, 10.0, test::count(5000)), "finite differences, paper start, >10 deg");
}

TEST(Compensation, NominalModelNeedsNoIteration) {
  auto nom = std::make_shared<Model>(kr500_spec());
  const Robot robot{nom, nom};
  Vec6 q;
  q << 10, -70, 95, 20, 40, -10;
  const Pose6 target = iso_to_pose(fk(*nom, VecQ(q * kDeg)));
  const PoseSolution s = solve_pose(robot, ProgramOptions{}, target, q);
  ASSERT_TRUE(s.ok()) << s.error;
  EXPECT_EQ(s.iterations, 0);
  EXPECT_LT((s.q_deg - q).norm(), 1e-9);
}
