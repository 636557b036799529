#include "kincal/ik/ik.hpp"
#include "kincal/io/model_json.hpp"
#include "kincal/model/model.hpp"
#include "kincal/model/robots.hpp"
#include <random>
#include <kdl/chain.hpp>

#include "test_util.hpp"

#include <gtest/gtest.h>

using namespace kincal;

TEST(Model, Kr500HasThirtyGeometricAndFiveComplianceParameters) {
  const Model m(kr500_spec());
  EXPECT_EQ(m.dof(), 6);
  EXPECT_EQ(4 * m.dof() + 6, 30);
  EXPECT_EQ(m.compliance_count(), 5);  // axis 1 is vertical: no gravity torque on it
  EXPECT_FALSE(m.gravity_loaded(0));
  const IkSolver ik(m);
  EXPECT_TRUE(ik.structure().spherical_wrist_parallel_23) << ik.structure().reason;
  EXPECT_EQ(m.kdl_chain().getNrOfJoints(), 6u);
}

// perturbed_spec: one seed with and without compliance is one robot, its geometry and tool the same to
// the bit (the compliances are drawn at compliance 0 too, and dropped; before the thirty-first session a
// spec without compliance skipped those draws, and joints 3-6 of the kr500 moved by up to 2.7 mm).
TEST(Model, PerturbedSpecWithAndWithoutComplianceIsOneGeometry) {
  const Model nominal(kr500_spec());
  for (const unsigned seed : {1u, 7u, test::test_seed(9)}) {
    SCOPED_TRACE(seed);
    const ModelSpec rigid = perturbed_spec(kr500_spec(), seed, 1.0, 0.05, 0.0);
    const ModelSpec soft = perturbed_spec(kr500_spec(), seed, 1.0, 0.05, 0.003);
    for (int j = 0; j < nominal.dof(); ++j) {
      EXPECT_EQ(rigid.joints[j].axis, soft.joints[j].axis);
      EXPECT_EQ(rigid.joints[j].point, soft.joints[j].point);
      EXPECT_EQ(rigid.joints[j].compliance_deg_per_knm, kr500_spec().joints[j].compliance_deg_per_knm);
      EXPECT_EQ(soft.joints[j].compliance_deg_per_knm > 0, nominal.gravity_loaded(j));
    }
    EXPECT_EQ(rigid.tool.xyz, soft.tool.xyz);
    EXPECT_EQ(rigid.tool.abc, soft.tool.abc);
  }
}

TEST(Model, JsonRoundTripIsExact) {
  KINCAL_SEED_TRACE(3);
  auto nom = std::make_shared<Model>(kr500_spec());
  auto cal = std::make_shared<Model>(perturbed_spec(kr500_spec(), test::test_seed(3), 1.0, 0.05, 0.003));
  const Robot r{nom, cal};
  const std::string a = robot_to_json(r);
  const Robot back = robot_from_json(a, "mem.json");
  EXPECT_EQ(robot_to_json(back), a);
  ASSERT_TRUE(back.identified());
  for (int j = 0; j < 6; ++j) {
    EXPECT_EQ(back.calibrated()->spec().joints[j].point, cal->spec().joints[j].point);  // bit-exact
    EXPECT_EQ(back.calibrated()->spec().joints[j].axis, cal->spec().joints[j].axis);
    EXPECT_EQ(back.calibrated()->spec().joints[j].compliance_deg_per_knm, cal->spec().joints[j].compliance_deg_per_knm);
  }
  EXPECT_EQ(back.calibrated()->spec().tool.abc, cal->spec().tool.abc);
}

TEST(Model, TcpKeyRoundTripsAndWarnsOnlyWhenNominal) {
  KINCAL_SEED_TRACE(3);
  // the model file's top-level "tcp" (where the calibrated tool frame comes from) is read and written
  // back; only "nominal" gives kincal-compensate's warning; a model without the key says nothing
  auto nom = std::make_shared<Model>(kr500_spec());
  for (const std::string tcp : {"nominal", "measured", "tool-targets"}) {
    ModelSpec s = perturbed_spec(kr500_spec(), test::test_seed(3), 1.0, 0.05, 0.003);
    s.tcp = tcp;
    const std::string a = robot_to_json(Robot{nom, std::make_shared<Model>(s)});
    EXPECT_NE(a.find("\"tcp\": \"" + tcp + "\""), std::string::npos);
    const Robot back = robot_from_json(a, "m.json");
    EXPECT_EQ(back.calibrated()->spec().tcp, tcp);
    EXPECT_EQ(robot_to_json(back), a);
    EXPECT_EQ(tcp_warning(back, "m.json").empty(), tcp != "nominal");
  }
  const Robot plain{nom, nom};
  EXPECT_EQ(robot_to_json(plain).find("\"tcp\""), std::string::npos);
  EXPECT_EQ(tcp_warning(plain, "kr500"), "");
  std::string bad = robot_to_json(plain);
  bad.insert(bad.find('{') + 1, "\"tcp\": \"guessed\",");
  try {
    robot_from_json(bad, "bad.json");
    ADD_FAILURE() << "an unknown tcp accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: tcp: \"guessed\" is not one of"), std::string::npos) << e.what();
  }
}

TEST(Model, ErrorsNameTheSourceAndCause) {
  try {
    load_robot("kr9000");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown robot 'kr9000'"), std::string::npos);
  }
  try {
    robot_from_json("{\n  \"format\": \"kincal-model\",\n  \"version\": 1,\n  x\n}", "m.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("m.json:4:"), std::string::npos) << e.what();
  }
  try {
    robot_from_json(R"({"format": "kincal-model", "version": 7, "nominal": {}})", "v.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("version 7"), std::string::npos) << e.what();
  }
  ModelSpec s = kr500_spec();
  s.joints[0].compliance_deg_per_knm = 1;  // axis along gravity has no torque to comply with
  EXPECT_THROW(Model{s}, InputError);
  s = kr500_spec();
  s.joints[2].axis = Vec3(0, 0, 0);
  EXPECT_THROW(Model{s}, InputError);
}

TEST(Model, AbcConvention) {
  KINCAL_SEED_TRACE(5);
  // R = Rz(a) Ry(b) Rx(c): a rotation about z alone moves x towards y
  const Mat3 r = abc_to_rotation(Vec3(90, 0, 0));
  EXPECT_NEAR((r * Vec3::UnitX() - Vec3::UnitY()).norm(), 0, 1e-15);
  std::mt19937 rng(test::test_seed(5));
  for (int i = 0; i < 1000; ++i) {
    const Vec3 abc(std::uniform_real_distribution<double>(-179, 179)(rng),
                   std::uniform_real_distribution<double>(-89, 89)(rng),
                   std::uniform_real_distribution<double>(-179, 179)(rng));
    EXPECT_NEAR((rotation_to_abc(abc_to_rotation(abc)) - abc).norm(), 0, 1e-9);
  }
}

// Near B = +-90 deg only a - c (or a + c) is determined, from entries of size cos b: the rotation
// the ABC angles give back must still be the one they came from, however close to the pole
// (the angles themselves may differ). Truth: a, c drawn in +-179 deg, b = +-(90 - delta) for
// delta from 0 to 1e-2 deg, each entry of the rotation then off by up to 2e-15 as a forward
// kinematics chain leaves it; a b 1e-10 deg from the pole once made a - c wrong by 0.005 deg.
TEST(Model, AbcNearThePoleGivesTheSameRotation) {
  KINCAL_SEED_TRACE(11);
  std::mt19937 rng(test::test_seed(11));
  std::uniform_real_distribution<double> ang(-179, 179), fk_rounding(-2e-15, 2e-15);
  double worst = 0;
  for (double delta : {0.0, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2}) {
    for (double sign : {1.0, -1.0}) {
      for (int k = 0; k < 50; ++k) {
        Mat3 r = abc_to_rotation(Vec3(ang(rng), sign * (90.0 - delta), ang(rng)));
        for (int e = 0; e < 9; ++e) r(e / 3, e % 3) += fk_rounding(rng);
        const Mat3 back = abc_to_rotation(rotation_to_abc(r));
        worst = std::max(worst, Eigen::AngleAxisd(r.transpose() * back).angle() / kDeg);
      }
    }
  }
  EXPECT_LT(worst, 1e-5);  // deg
}
