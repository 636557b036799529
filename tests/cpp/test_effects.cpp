// The effects a model carries, through every consumer: the registry, model JSON version 2, FK and
// its Jacobian, Newton compensation (FK(compensate(p)) = p with every effect), programs (backlash
// directions from the commanded motion, temperature), B = +-90 deg poses and branch changes.
#include "kincal/compensation/pose.hpp"
#include "kincal/effects/effects.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/io/model_json.hpp"
#include "kincal/identify/identify.hpp"
#include "kincal/compensation/program.hpp"
#include "kincal/compensation/stream.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <cstdio>
#include <fstream>

#include "test_util.hpp"

#include <gtest/gtest.h>

using namespace kincal;

namespace {


// Truth of these tests: kr500 with 1 mm / 0.05 deg geometric errors and compliance 0.003 deg/kNm
// (seed 11), transmission error on joints 2 and 3 (harmonics 1, 2 and, on joint 3, 3), backlash
// of 0.01-0.02 deg on joints 1, 2 and 4 (negative: the joint lags behind the command, as a gear's
// play makes it), a joint_map of order 5 on joint 5 (0.004-0.012 deg per order), thermal expansion
// 12e-6 per deg C about 20 C.
ModelSpec effects_spec(bool thermal = true) {
  ModelSpec s = perturbed_spec(kr500_spec(), test::test_seed(11), 1.0, 0.05, 0.003);
  const double d = kDeg;
  s.effects.push_back({Effect{"transmission_error", 1, {1, 2}}, {0.02 * d, -0.01 * d, 0.005 * d, 0.008 * d}});
  s.effects.push_back({Effect{"transmission_error", 2, {1, 2, 3}},
                       {-0.015 * d, 0.01 * d, 0.004 * d, -0.006 * d, 0.003 * d, 0.002 * d}});
  s.effects.push_back({Effect{"backlash", 0, {}}, {-0.01 * d}});
  s.effects.push_back({Effect{"backlash", 1, {}}, {-0.02 * d}});
  s.effects.push_back({Effect{"backlash", 3, {}}, {-0.015 * d}});
  s.effects.push_back({joint_map(4, 5), {0.012 * d, -0.004 * d, 0.006 * d, 0.008 * d, -0.005 * d, 0.004 * d,
                                         0.007 * d, -0.006 * d, 0.004 * d, 0.005 * d}});
  if (thermal) s.effects.push_back({Effect{"thermal_expansion", -1, {}}, {12e-6}});
  s.t_ref_c = 20.0;
  return s;
}

EffectContext random_context(std::mt19937_64& rng) {
  EffectContext c;
  c.dir.resize(6);
  for (int j = 0; j < 6; ++j) c.dir[j] = rng() % 2 ? 1.0 : -1.0;
  c.temperature_c = std::uniform_real_distribution<double>(15, 35)(rng);
  return c;
}

double rot_deg(const Mat3& a, const Mat3& b) { return test::rot_dist(a, b) / kDeg; }

}  // namespace

TEST(Effects, RegistryNamesEveryEffectOnce) {
  std::vector<std::string> names;
  for (const auto& k : effect_kinds()) names.push_back(k.name);
  EXPECT_EQ(names, (std::vector<std::string>{"joint_compliance", "transmission_error", "backlash", "thermal_expansion",
                                             "drift", "joint_map", "link_deflection"}));
  EXPECT_EQ(effect_kind("drift").needs, "time_s");
  EXPECT_EQ(Effect{"drift"}.file_units()[3], "deg/h");
  EXPECT_EQ(effect_kind("backlash").needs, "dir");
  EXPECT_EQ(effect_kind("link_deflection").domain, "fivebar");
  EXPECT_THROW(effect_kind("gear_wobble"), InputError);
  const Effect te{"transmission_error", 2, {1, 2, 5}};
  EXPECT_EQ(te.size(), 6);
  EXPECT_EQ(te.parameter_names()[4], "te_sin5");
  EXPECT_EQ(te.file_units()[0], "deg");
  EXPECT_THROW(check_effect(Effect{"backlash", 7, {}}, 6, ""), InputError);
  EXPECT_THROW(check_effect(Effect{"link_deflection", 0, {}}, 6, ""), InputError);
  EXPECT_THROW(check_effect(Effect{"transmission_error", 0, {2, 2}}, 6, ""), InputError);
  // joint_map: every order 1..K, parameters map_sin1, map_cos1, ..., in degrees in files
  const Effect jm = joint_map(3, 4);
  EXPECT_EQ(jm.order(), 4);
  EXPECT_EQ(jm.size(), 8);
  EXPECT_EQ(jm.label(), "joint_map(joint 4)");
  EXPECT_EQ(jm.parameter_names()[6], "map_sin4");
  EXPECT_EQ(jm.file_units()[7], "deg");
  EXPECT_NO_THROW(check_effect(jm, 6, ""));
  EXPECT_THROW(check_effect(Effect{"joint_map", 0, {1, 3}}, 6, ""), InputError);
  EXPECT_THROW(check_effect(Effect{"joint_map", 0, {}}, 6, ""), InputError);
  EXPECT_THROW(check_effect(joint_map(6, 2), 6, ""), InputError);
  EXPECT_FALSE(joint_map(3, 4) == joint_map(3, 5));
  EXPECT_FALSE(joint_map(3, 2) == (Effect{"transmission_error", 3, {1, 2}}));
  EXPECT_EQ((Effect{"backlash", 3, {}}.order()), 0);
  // the harmonic basis against libm: sin(k q), cos(k q) and their derivatives
  double b[6], db[6];
  joint_basis(te, 0.7, 0.0, b, db);
  const int k[3] = {1, 2, 5};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(b[2 * i], std::sin(k[i] * 0.7), 1e-14);
    EXPECT_NEAR(b[2 * i + 1], std::cos(k[i] * 0.7), 1e-14);
    EXPECT_NEAR(db[2 * i], k[i] * std::cos(k[i] * 0.7), 1e-13);
    EXPECT_NEAR(db[2 * i + 1], -k[i] * std::sin(k[i] * 0.7), 1e-13);
  }
  // a five-bar link's length basis lives in its effect's file: cos t1, sin t1, cos t2, sin t2
  double lb[4];
  link_basis(Effect{"link_deflection", 2, {}}, 0.3, -1.1, lb);
  EXPECT_DOUBLE_EQ(lb[0], std::cos(0.3));
  EXPECT_DOUBLE_EQ(lb[1], std::sin(0.3));
  EXPECT_DOUBLE_EQ(lb[2], std::cos(-1.1));
  EXPECT_DOUBLE_EQ(lb[3], std::sin(-1.1));
  EXPECT_EQ(test::error_of([&] { link_basis(te, 0.3, -1.1, lb); }),
            "transmission_error is no link-length effect (it has no link basis)");
}

TEST(Effects, ModelJsonVersion3RoundTripAndVersion1Reads) {
  KINCAL_SEED_TRACE(11, 3);
  auto nom = std::make_shared<Model>(kr500_spec());
  auto cal = std::make_shared<Model>(effects_spec());
  const std::string text = robot_to_json(Robot{nom, cal});
  EXPECT_NE(text.find("\"version\": 3"), std::string::npos);
  const Robot back = robot_from_json(text, "t.json");
  ASSERT_EQ(back.calibrated()->spec().effects.size(), cal->spec().effects.size());
  for (size_t i = 0; i < cal->spec().effects.size(); ++i) {
    EXPECT_TRUE(back.calibrated()->spec().effects[i].effect == cal->spec().effects[i].effect);
    for (size_t k = 0; k < cal->spec().effects[i].p.size(); ++k)
      EXPECT_NEAR(back.calibrated()->spec().effects[i].p[k], cal->spec().effects[i].p[k], 1e-18);
  }
  for (int j = 0; j < 6; ++j)
    EXPECT_EQ(back.calibrated()->spec().joints[j].compliance_deg_per_knm, cal->spec().joints[j].compliance_deg_per_knm);
  // a version 1 file (no effects, no reference temperature; the campaign's placement in the
  // model's section) still reads
  std::string v1 = robot_to_json(Robot{nom, std::make_shared<Model>(perturbed_spec(kr500_spec(), test::test_seed(3)))});
  v1.replace(v1.find("\"version\": 3"), 12, "\"version\": 1");
  const size_t campaign = v1.find(",\n  \"campaign\"");
  ASSERT_NE(campaign, std::string::npos);
  v1.erase(campaign, v1.find("\n  }", campaign) + 4 - campaign);
  for (size_t at = v1.find("\"gravity_m_s2\""); at != std::string::npos; at = v1.find("\"gravity_m_s2\"", at + 80))
    v1.insert(at, "\"base_in_instrument\": {\"xyz_mm\": [1, 2, 3], \"abc_deg\": [0, 0, 90]},\n    ");
  const Robot r1 = robot_from_json(v1, "v1.json");
  EXPECT_TRUE(r1.calibrated()->spec().effects.empty());
  EXPECT_EQ(r1.campaign().base_in_instrument.xyz, Vec3(1, 2, 3));  // the calibrated section's
  // joint_map is written with its order and read back from it; without it, an error naming where
  EXPECT_NE(text.find("\"order\": 5"), std::string::npos);
  std::string no_order = text;
  no_order.replace(no_order.find("\"order\": 5"), 10, "\"orders\": 5");
  try {
    robot_from_json(no_order, "o.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("o.json: calibrated.effects["), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("order"), std::string::npos) << e.what();
  }
  // a wrong unit is an error naming where
  std::string bad = text;
  bad.replace(bad.find("\"unit\": \"deg\""), 13, "\"unit\": \"rad\"");
  try {
    robot_from_json(bad, "bad.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: calibrated.effects["), std::string::npos) << e.what();
  }
}

TEST(Effects, ContextIsCheckedByName) {
  KINCAL_SEED_TRACE(11);
  const Model m(effects_spec());
  EffectContext c;
  try {
    fk_model(m, VecQ::Zero(6), c);
  } catch (const InputError&) {
  }
  EXPECT_THROW(check_context(m, c, ""), InputError);
  c.dir = VecQ::Ones(6);
  try {
    check_context(m, c, "x: ");
    FAIL() << "the temperature is missing";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("temperature"), std::string::npos);
  }
  c.temperature_c = 25;
  EXPECT_NO_THROW(check_context(m, c, ""));
}

// The whole model's Jacobian (compliance, transmission error, backlash, thermal) against central
// differences of fk_model, and the compensation's F Jacobian for both residuals.
TEST(Effects, JacobiansMatchFiniteDifferences) {
  KINCAL_SEED_TRACE(11, 41);
  const Model m(effects_spec());
  std::mt19937_64 rng(test::test_seed(41));
  double worst = 0, worst_f = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec6 q = test::random_q(m, rng, 1.0);
    const EffectContext c = random_context(rng);
    Eigen::Isometry3d t;
    Jac j;
    fk_jacobian_model(m, q * kDeg, c, t, j);
    // (1e-4 rad: truncation ~1e-8 relative; at 1e-6 the rounding of 3000 mm positions, 2e-16 x 3000 / 2e-6 =
    // 3e-7 mm/rad, reached 1e-6 on columns below 1 mm/rad on some seeds)
    const double h = 1e-4;
    for (int k = 0; k < 6; ++k) {
      VecQ qp = q * kDeg, qm = q * kDeg;
      qp[k] += h;
      qm[k] -= h;
      const Eigen::Isometry3d tp = fk_model(m, qp, c), tm = fk_model(m, qm, c);
      const Vec3 dv = (tp.translation() - tm.translation()) / (2 * h);
      const Eigen::AngleAxisd aa(tp.linear() * tm.linear().transpose());
      const Vec3 dw = aa.angle() * aa.axis() / (2 * h);
      worst = std::max(worst, (dv - j.col(k).head<3>()).norm() / std::max(1.0, dv.norm()));
      worst = std::max(worst, (dw - j.col(k).tail<3>()).norm());
    }
    for (Residual res : {Residual::RotationVector, Residual::Abc}) {
      Vec6 qt = q;
      qt[0] += 2, qt[4] += 1;  // a desired pose near, not at, the current one
      const Pose6 desired = iso_to_pose(fk_model(m, qt * kDeg, c));
      if (res == Residual::Abc && std::abs(desired.abc[1]) > 80) continue;
      const Mat6 jf = pose_deviation_jacobian(m, q, desired, res, c);
      for (int k = 0; k < 6; ++k) {
        Vec6 qp = q, qm = q;
        qp[k] += 1e-5, qm[k] -= 1e-5;
        const Vec6 col = (pose_deviation(m, qp, desired, res, c) - pose_deviation(m, qm, desired, res, c)) / 2e-5;
        worst_f = std::max(worst_f, (col - jf.col(k)).cwiseAbs().maxCoeff() / std::max(1.0, col.cwiseAbs().maxCoeff()));
      }
    }
  }
  std::printf("whole-model Jacobian vs central differences: %.2e; F Jacobians: %.2e\n", worst, worst_f);
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worst_f, 1e-6);
}

// FK(compensate(p)) = p with every effect: random reachable poses of the truth (more than 1 deg
// from its singularities), random directions and temperatures; Newton from the nominal IK.
TEST(Effects, CompensationInvertsEveryEffect) {
  KINCAL_SEED_TRACE(11, 42);
  auto nom = std::make_shared<Model>(kr500_spec());
  auto cal = std::make_shared<Model>(effects_spec());
  const Robot robot{nom, cal};
  ProgramOptions opt;
  opt.comp.epsilon = 1e-20;
  opt.comp.max_iterations = 30;
  std::mt19937_64 rng(test::test_seed(42));
  int n = 0, ok = 0;
  double worst_mm = 0, worst_deg = 0;
  while (n < test::count(2000)) {
    const Vec6 q = test::random_q(*nom, rng, 2.0);
    if (test::singularity_distance_deg(*nom, q) < 1.0) continue;
    const EffectContext c = random_context(rng);
    const Eigen::Isometry3d want = fk_model(*cal, q * kDeg, c);
    ++n;
    const PoseSolution s = solve_pose(robot, opt, iso_to_pose(want), q, c);
    if (!s.ok()) continue;
    ++ok;
    const Eigen::Isometry3d got = fk_model(*cal, s.q_deg * kDeg, c);
    worst_mm = std::max(worst_mm, (got.translation() - want.translation()).norm());
    worst_deg = std::max(worst_deg, rot_deg(got.linear(), want.linear()));
  }
  std::printf("every effect: %d of %d poses compensated, worst %.2e mm %.2e deg\n", ok, n, worst_mm, worst_deg);
  EXPECT_GE(ok, n - n / 500);  // as the rigid model's convergence test: poses at the limits may fail
  EXPECT_LT(worst_mm, 1e-9);
  EXPECT_LT(worst_deg, 1e-9);
}

// A tool pose with B = +-90 deg (tool horizontal) is an ordinary pose for the rotation-vector
// residual; the paper's ABC residual stops there. Poses: reachable ones with |B| > 80 deg turned to
// B = +-90 exactly.
TEST(Effects, PosesAtBPlusMinus90Compensate) {
  KINCAL_SEED_TRACE(11, 44);
  auto nom = std::make_shared<Model>(kr500_spec());
  auto cal = std::make_shared<Model>(effects_spec(false));
  const Robot robot{nom, cal};
  EffectContext c;
  c.dir = VecQ::Ones(6);
  std::mt19937_64 rng(test::test_seed(44));
  int done = 0, paper_stopped = 0;
  while (done < 20) {
    const Vec6 q = test::random_q(*nom, rng, 10.0);
    if (test::singularity_distance_deg(*nom, q) < 5.0) continue;
    Pose6 p = iso_to_pose(fk(*nom, q * kDeg));
    if (std::abs(p.abc[1]) < 80) continue;
    p.abc[1] = p.abc[1] > 0 ? 90.0 : -90.0;
    // reachable: the turned pose has a nominal solution inside the limits, 10 deg from the singularities
    // (turning B by up to 10 deg at the TCP moves the wrist centre by up to 0.6 m with the head's 3.5 m tool,
    // out of reach near its edge; and 5 deg from the stretched arm the compliant robot, sagging 7 mm under
    // the head, may not reach what the nominal one does)
    const IkSolutions turned = robot.ik().solve(pose_to_iso(p), IkOptions(q));
    const int near = turned.nearest(q.data());
    if (near < 0 || test::singularity_distance_deg(*nom, turned.sol[near].q_deg) < 10.0) continue;
    ProgramOptions opt;
    opt.comp.epsilon = 1e-20;
    const PoseSolution s = solve_pose(robot, opt, p, q, c);
    ASSERT_TRUE(s.ok()) << s.error;
    const Eigen::Isometry3d got = fk_model(*cal, s.q_deg * kDeg, c);
    EXPECT_LT((got.translation() - p.xyz).norm(), 1e-9);
    EXPECT_LT(rot_deg(got.linear(), abc_to_rotation(p.abc)), 1e-9);
    ProgramOptions paper = opt;
    paper.comp.residual = Residual::Abc;
    // the ABC rates are singular there: the paper's Newton stops at the singularity or wanders off
    if (!solve_pose(robot, paper, p, q, c).ok()) ++paper_stopped;
    ++done;
  }
  std::printf("20 poses at B = +-90 deg compensated; the ABC residual failed on %d\n", paper_stopped);
  EXPECT_GE(paper_stopped, 15);
}

// Point-to-point: poses whose nearest branch's compensated solution leaves a joint limit (the
// nominal solution sits 0.05 deg inside the limit of q2 or q3, the calibrated robot has 0.2 deg
// axis errors), where another branch's compensated solution is inside the limits.
TEST(Effects, BranchChangesToStayWithinLimits) {
  KINCAL_SEED_TRACE(12, 43);
  auto nom = std::make_shared<Model>(kr500_spec());
  auto cal = std::make_shared<Model>(perturbed_spec(kr500_spec(), test::test_seed(12), 1.0, 0.2, 0.003));
  const Robot robot{nom, cal};
  std::mt19937_64 rng(test::test_seed(43));
  CompensationOptions co;
  co.epsilon = 1e-20;
  int tried = 0;
  for (int i = 0; i < 4000 && tried < 20; ++i) {
    Vec6 q = test::random_q(*nom, rng, 5.0);
    const int j = 1 + i % 2;
    const auto& js = nom->spec().joints[j];
    q[j] = i % 4 < 2 ? js.upper_deg - 0.05 : js.lower_deg + 0.05;
    if (test::singularity_distance_deg(*nom, q) < 5.0) continue;
    const Pose6 p = iso_to_pose(fk(*nom, q * kDeg));
    // the nearest branch alone leaves the limits; some other branch does not
    const CompensationResult alone = compensate(*cal, p, q, co);
    if (alone.status != CompStatus::Converged || cal->within_limits_deg(alone.q_deg)) continue;
    const IkSolutions all = robot.ik().solve(pose_to_iso(p), IkOptions(q));
    bool other = false;
    for (int k = 0; k < all.count; ++k) {
      const CompensationResult r = compensate(*cal, p, all.sol[k].q_deg, co);
      other = other || (r.status == CompStatus::Converged && cal->within_limits_deg(r.q_deg));
    }
    if (!other) continue;
    ++tried;
    ProgramOptions opt;
    opt.comp.epsilon = 1e-20;
    opt.corrected_start = false;  // Newton from the nearest branch itself, as "alone"
    const PoseSolution s = solve_pose(robot, opt, p, q, EffectContext());
    ASSERT_TRUE(s.ok()) << s.error;
    EXPECT_TRUE(s.branch_changed());
    EXPECT_TRUE(cal->within_limits_deg(s.q_deg));
    const Eigen::Isometry3d got = fk_compliant(*cal, s.q_deg * kDeg);
    EXPECT_LT((got.translation() - p.xyz).norm(), 1e-9);
    // with --keep-branch the program stops at that pose instead
  }
  std::printf("%d poses whose nearest branch leaves the limits once compensated: solved on another branch\n", tried);
  EXPECT_GE(tried, 10);
}

// Backlash directions in programs: the sign of each joint's change, held while it stands still.
TEST(Effects, MotionDirections) {
  std::vector<Vec6> q(5, Vec6::Zero());
  q[1][0] = 1, q[2][0] = 1, q[3][0] = 0.5, q[4][0] = 0.5 + 1e-9;
  q[1][1] = -1;
  const auto d = motion_directions(q, {});
  EXPECT_EQ(d[0][0], 1.0);   // the direction of the first motion
  EXPECT_EQ(d[2][0], 1.0);   // held while it stands still
  EXPECT_EQ(d[3][0], -1.0);  // turned around
  EXPECT_EQ(d[4][0], -1.0);  // a change below kStillDeg is standing still
  EXPECT_EQ(d[0][1], -1.0);
  EXPECT_EQ(d[0][2], 1.0);  // never moves: +1
  const auto d2 = motion_directions(q, {-1});
  EXPECT_EQ(d2[0][0], -1.0);
  EXPECT_EQ(d2[1][0], 1.0);
}

// A back-and-forth program compensated with every effect runs on the same model (the directions
// its commanded motion really has, the program's temperature) to the desired poses; the stream
// (given the initial directions) equals the file.
TEST(Effects, ProgramWithBacklashRunsToTheDesiredPoses) {
  KINCAL_SEED_TRACE(11);
  auto nom = std::make_shared<Model>(kr500_spec());
  auto cal = std::make_shared<Model>(effects_spec());
  const Robot robot{nom, cal};
  std::vector<Pose6> poses;
  std::vector<std::string> where;
  for (int i = 0; i < 60; ++i) {
    const double s = (i < 30 ? i : 59 - i) * 10.0;  // out along y and back
    poses.push_back(Pose6{Vec3(2000.0, -300.0 + s, 700.0 + 0.5 * s), Vec3(180.0, 0.0, 180.0)});
    where.push_back("line " + std::to_string(i + 2));
  }
  ProgramOptions opt;
  opt.comp.epsilon = 1e-20;
  opt.temperature_c = 27.5;
  const ProgramResult res = compensate_poses(robot, poses, where, opt);
  const auto dirs = motion_directions(res.q_deg, {});
  double worst = 0;
  int reversals = 0;
  for (size_t i = 0; i < poses.size(); ++i) {
    EffectContext c;
    c.dir = dirs[i];
    c.temperature_c = 27.5;
    EXPECT_EQ(Vec6(c.dir), res.dir[i]);
    if (i > 0) reversals += (dirs[i] - dirs[i - 1]).cwiseAbs().sum() > 0;
    const Eigen::Isometry3d got = fk_model(*cal, res.q_deg[i] * kDeg, c);
    worst = std::max(worst, (got.translation() - poses[i].xyz).norm());
  }
  std::printf("back and forth with every effect: worst %.2e mm on the model, %d direction changes\n", worst, reversals);
  EXPECT_LT(worst, 1e-9);
  EXPECT_GE(reversals, 1);
  // the stream equals the file when told the first pose's directions
  ProgramOptions so = opt;
  so.initial_direction.assign(res.dir[0].data(), res.dir[0].data() + 6);
  StreamCompensator sc(robot, so);
  char buf[512];
  const std::string hdr = "x,y,z,a,b,c";
  sc.process(hdr.data(), hdr.size(), buf, sizeof buf);
  for (size_t i = 0; i < poses.size(); ++i) {
    char line[256];
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", poses[i].xyz[0], poses[i].xyz[1],
                  poses[i].xyz[2], poses[i].abc[0], poses[i].abc[1], poses[i].abc[2]);
    const size_t n = sc.process(line, std::strlen(line), buf, sizeof buf);
    double v[6];
    ASSERT_EQ(std::sscanf(std::string(buf, n).c_str(), "%lf,%lf,%lf,%lf,%lf,%lf", v, v + 1, v + 2, v + 3, v + 4, v + 5), 6);
    for (int j = 0; j < 6; ++j) EXPECT_NEAR(v[j], res.q_deg[i][j], 1e-9);
  }
  // without the initial directions a stream cannot start: a clear error
  EXPECT_THROW(StreamCompensator(robot, opt), InputError);
}
