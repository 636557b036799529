// The joint ranges a model was fitted on (model/coverage.hpp): the shortest arc holding the fitted
// angles, the 1 deg margin, the model JSON's fitted_joint_ranges_deg, and the joints whose periodic
// effects rows of angles take outside them.
#include "kincal/identify/simulate.hpp"
#include "kincal/io/model_json.hpp"
#include "kincal/model/coverage.hpp"
#include "kincal/model/robots.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace kincal;

namespace {

std::vector<JointRange> ranges_of(const std::vector<double>& one_joint) {
  return joint_ranges(one_joint.data(), one_joint.size(), 1);
}

}  // namespace

TEST(Coverage, RangeIsTheCircleLessItsWidestGap) {
  std::vector<double> a;
  for (int i = 0; i <= 27; ++i) a.push_back(-180.0 + 5.0 * i);  // -180..-45
  EXPECT_DOUBLE_EQ(ranges_of(a)[0][0], -180.0);
  EXPECT_DOUBLE_EQ(ranges_of(a)[0][1], -45.0);
  for (double& x : a) x -= 128.0;  // -308..-173: the same as 52..187 on the circle
  EXPECT_NEAR(ranges_of(a)[0][0], 52.0, 1e-12);
  EXPECT_NEAR(ranges_of(a)[0][1], 187.0, 1e-12);
  const JointRange across = ranges_of({170.0, 175.0, 180.0, -175.0, -170.0})[0];  // across +-180
  EXPECT_NEAR(across[0], 170.0, 1e-12);
  EXPECT_NEAR(across[1], 190.0, 1e-12);
  std::vector<double> full;
  for (int i = 0; i < 80; ++i) full.push_back(-360.0 + 9.0 * i);  // steps of 9 deg: the whole turn
  EXPECT_EQ(ranges_of(full)[0], (JointRange{-180.0, 180.0}));
  std::vector<double> turn;
  for (int i = 0; i < 40; ++i)
    if (i != 24 && i != 25) turn.push_back(-180.0 + 9.0 * i);  // one turn less 36 and 45: a gap of 27 deg
  EXPECT_NEAR(ranges_of(turn)[0][0], 54.0, 1e-12);
  EXPECT_NEAR(ranges_of(turn)[0][1], 54.0 + 360.0 - 27.0, 1e-12);
  EXPECT_EQ(ranges_of({30.0})[0], (JointRange{30.0, 30.0}));
  EXPECT_EQ(ranges_of({30.0, std::nan(""), 40.0})[0], (JointRange{30.0, 40.0}));  // not finite: left out
  EXPECT_THROW(ranges_of({std::nan("")}), InputError);  // a joint with no angle at all
  EXPECT_TRUE(ranges_of({}).empty());                   // no rows: unknown
  // -180 less an ulp is -180 on the circle (fmod's -tiny + 360 rounds to 360)
  const JointRange edge = ranges_of({std::nextafter(-180.0, -200.0), -100.0})[0];
  EXPECT_EQ(edge, (JointRange{-180.0, -100.0}));
}

TEST(Coverage, OutsideCountsTurnsAndTheMargin) {
  const JointRange r{-180.0, -45.0};
  EXPECT_FALSE(outside_range(-180.5, r));  // within 1 deg
  EXPECT_FALSE(outside_range(-44.5, r));
  EXPECT_TRUE(outside_range(-43.0, r));
  EXPECT_TRUE(outside_range(-181.5, r));
  EXPECT_FALSE(outside_range(180.0, r));   // = -180
  EXPECT_FALSE(outside_range(315.0, r));   // = -45
  EXPECT_FALSE(outside_range(-405.0, r));  // = -45
  EXPECT_TRUE(outside_range(52.0, r));
  EXPECT_FALSE(outside_range(52.0, JointRange{-180.0, 180.0}));
  EXPECT_FALSE(outside_range(std::nan(""), r));
}

TEST(Coverage, ModelJsonCarriesTheRangesAndRejectsBadOnes) {
  KINCAL_SEED_TRACE(3);
  const ModelSpec s = perturbed_spec(kr500_spec(), test::test_seed(3), 1.0, 0.05, 0.003);
  Campaign c;
  c.fitted_deg = {{-170.0, 160.0}, {-120.0, -60.0}, {-80.0, 130.0}, {25.0, 370.0}, {-100.0, 100.0}, {-180.0, 180.0}};
  const Robot r{std::make_shared<Model>(kr500_spec()), std::make_shared<Model>(s), c};
  const std::string text = robot_to_json(r);
  EXPECT_NE(text.find("fitted_joint_ranges_deg"), std::string::npos);
  const Robot back = robot_from_json(text, "m.json");
  EXPECT_EQ(back.campaign().fitted_deg, c.fitted_deg);  // the campaign's: the angles it saw
  auto bad = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    try {
      robot_from_json(t, "m.json");
      ADD_FAILURE() << "accepted " << to;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("m.json: campaign.fitted_joint_ranges_deg"), std::string::npos) << e.what();
    }
  };
  bad("-120.0,\n        -60.0", "200.0,\n        210.0");   // lo beyond 180
  bad("-120.0,\n        -60.0", "-60.0,\n        -120.0");  // hi below lo
  bad("-120.0,\n        -60.0", "\"a\",\n        -60.0");   // not a number
  bad("[\n        -170.0,\n        160.0\n      ],", "");  // five ranges for six joints
}

TEST(Coverage, ExtrapolatedNamesTheJointsOfPeriodicEffectsOnly) {
  KINCAL_SEED_TRACE(3);
  const double d = kDeg;
  ModelSpec s = with_effects(perturbed_spec(kr500_spec(), test::test_seed(3), 1.0, 0.05, 0.003),
                             {{Effect{"transmission_error", 1, {1, 2}}, {0.02 * d, 0, 0, 0.01 * d}},
                              {Effect{"backlash", 2, {}}, {0.01 * d}}},
                             20.0);
  // q1 = row index - 10 (-10..9), q2 = 0 (joint 2 carries a transmission error), q3 = 200 (backlash only)
  std::vector<double> q;
  for (int i = 0; i < 20; ++i) q.insert(q.end(), {i - 10.0, 0.0, 200.0, 0.0, 0.0, 0.0});
  EXPECT_TRUE(extrapolated(s, {}, q.data(), 20, 6).empty());  // no ranges: nothing claimed
  std::vector<JointRange> fitted(6, JointRange{-50.0, 50.0});
  fitted[1] = {-30.0, -3.0};  // joint 2's rows at 0 deg: every one outside (3 deg away)
  fitted[2] = {-30.0, 30.0};  // joint 3 outside too, but backlash does not depend on the angle
  const auto e = extrapolated(s, fitted, q.data(), 20, 6);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].joint, 2);
  EXPECT_EQ(e[0].effects, "transmission_error(joint 2)");
  EXPECT_EQ(e[0].rows, 20u);
  EXPECT_EQ(e[0].first, 0u);
  EXPECT_EQ(extrapolation_message(e[0], 20, "poses compensated"),
            "joint 2 is outside the -30..-3 deg its transmission_error(joint 2) was fitted on (angles modulo 360 deg) "
            "at 20 of 20 poses compensated (100%): the effect is extrapolated there, not measured");
  Extrapolation most = e[0];
  most.rows = 1999;  // 99.95%: not "100%"
  EXPECT_NE(extrapolation_message(most, 2000, "rows").find("at 1999 of 2000 rows (99.9%)"), std::string::npos);
  most.rows = 1;  // 0.05%: not "0%"
  EXPECT_NE(extrapolation_message(most, 2000, "rows").find("at 1 of 2000 rows (0.1%)"), std::string::npos);
}
