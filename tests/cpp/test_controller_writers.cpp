// The four controller writers (kincal/io/controllers.hpp: KUKA KRL .src + .dat, ABB RAPID .mod, FANUC LS
// .ls, URScript .script), tested in C++: joint and filtered Cartesian targets written to the test's
// temporary directory and read back by the project's own readers (read_native_program, read_declarations:
// cpp/src/io/*_reader.cpp), the values compared with what was written, and the key lines of each language.
//
// Truth: the targets handed to the writer. Joints: random configurations of the nominal kr500 inside its
// limits (seeded); filtered targets: their nominal FK with the branch data of the joints
// (controller_targets). Tolerances: the printed precision of each writer (controller_writers.hpp), half a
// unit of the last printed decimal: KRL and RAPID joints 6 decimals of a degree, LS 4, URScript 10 decimals
// of a radian; positions KRL, RAPID and LS 4 decimals of a mm, URScript 8 decimals of a metre; orientations
// KRL ABC 6 decimals of a degree, RAPID quaternions 9 decimals, LS W P R 4 decimals of a degree, URScript
// rotation vectors 10 decimals of a radian.
#include "kincal/compensation/branch.hpp"
#include "kincal/compensation/controller_program.hpp"
#include "kincal/io/controllers.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include "test_files.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <regex>
#include <string>
#include <vector>

using namespace kincal;

namespace {

const ControllerFormat kFormats[] = {ControllerFormat::Krl, ControllerFormat::Rapid, ControllerFormat::FanucLs,
                                     ControllerFormat::UrScript};

std::string ext_of(ControllerFormat f) {
  return f == ControllerFormat::Krl     ? ".src"
         : f == ControllerFormat::Rapid   ? ".mod"
         : f == ControllerFormat::FanucLs ? ".ls"
                                          : ".script";
}

/// Half a unit of the last decimal a writer prints of a joint (deg).
double joint_tolerance_deg(ControllerFormat f) {
  return f == ControllerFormat::FanucLs ? 5e-5 : f == ControllerFormat::UrScript ? 5e-11 / kDeg : 5e-7;
}

/// n random configurations of the nominal kr500 inside its limits (2 deg margin), more than 3 deg from its
/// singularities (a filtered target's branch data must fix the joints), drawn from seed.
std::vector<Vec6> random_joints(const Model& m, unsigned seed, int n) {
  std::mt19937_64 rng(test::test_seed(seed));
  std::vector<Vec6> q;
  while (static_cast<int>(q.size()) < n) {
    const Vec6 x = test::random_q(m, rng, 2.0);
    if (test::singularity_distance_deg(m, x) > 3.0) q.push_back(x);
  }
  return q;
}

std::vector<ControllerTarget> joint_targets(const std::vector<Vec6>& q) {
  std::vector<ControllerTarget> t(q.size());
  for (size_t i = 0; i < q.size(); ++i) t[i].q_deg = q[i];
  return t;
}

/// Every number of a text, in order (an optional sign, digits, a decimal part, an exponent).
std::vector<double> numbers_in(const std::string& s) {
  static const std::regex num(R"([-+]?\d+(\.\d*)?([eE][-+]?\d+)?)");
  std::vector<double> v;
  for (auto it = std::sregex_iterator(s.begin(), s.end(), num); it != std::sregex_iterator(); ++it)
    v.push_back(std::strtod(it->str().c_str(), nullptr));
  return v;
}

/// The joints of a written joint program, in the order of its motions. RAPID through the project's declaration
/// reader (read_declarations: the jointtarget values the MoveAbsJ name); the project reads no module-local KRL
/// declaration (only GLOBAL ones and $config.dat: what other programs may name) nor LS and URScript joint
/// positions (its readers keep joints as written): those by regular expressions here.
std::vector<Vec6> joints_read_back(ControllerFormat f, const std::vector<OutputFile>& files) {
  std::vector<Vec6> out;
  const auto vec = [](const std::vector<double>& v) {
    Vec6 q = Vec6::Constant(std::nan(""));
    for (size_t j = 0; j < 6 && j < v.size(); ++j) q[static_cast<Eigen::Index>(j)] = v[j];
    return q;
  };
  const auto each = [](const std::string& text, const std::regex& re,
                       const std::function<void(const std::smatch&)>& f) {
    for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it) f(*it);
  };
  if (f == ControllerFormat::Rapid) {
    const Declarations d = read_declarations({files.at(0).path}, f);
    each(files[0].text, std::regex(R"(MoveAbsJ (jt\d+)\\NoEOffs)"), [&](const std::smatch& m) {
      const Declaration* decl = d.find(m[1]);
      ASSERT_NE(decl, nullptr) << m[1];
      EXPECT_EQ(decl->type, "JOINTTARGET");
      out.push_back(vec(numbers_in(decl->value)));  // [[q1, .., q6], [9E9, ..]]
    });
    return out;
  }
  for (const OutputFile& o : files) {
    if (f == ControllerFormat::Krl) {
      if (o.path.find(".src") == std::string::npos) continue;
      std::map<std::string, Vec6> decl;  // the .dat beside the .src
      const std::string dat = read_text_file(o.path.substr(0, o.path.size() - 4) + ".dat");
      each(dat, std::regex(R"(\nDECL E6AXIS (XP\d+)=\{A1 (\S+),A2 (\S+),A3 (\S+),A4 (\S+),A5 (\S+),A6 (\S+),E1 )"),
           [&](const std::smatch& m) {
             Vec6 q;
             for (int j = 0; j < 6; ++j) q[j] = std::strtod(m[j + 2].str().c_str(), nullptr);
             decl[m[1]] = q;
           });
      each(o.text, std::regex(R"(\nPTP (XP\d+))"), [&](const std::smatch& m) {
        ASSERT_TRUE(decl.count(m[1])) << m[1];
        out.push_back(decl[m[1]]);
      });
    } else if (f == ControllerFormat::FanucLs) {
      const std::regex pos(R"(J1=\s*(\S+) deg,\s*J2=\s*(\S+) deg,\s*J3=\s*(\S+) deg,\s*)"
                           R"(J4=\s*(\S+) deg,\s*J5=\s*(\S+) deg,\s*J6=\s*(\S+) deg)");
      each(o.text, pos,
           [&](const std::smatch& m) {
             Vec6 q;
             for (int j = 0; j < 6; ++j) q[j] = std::strtod(m[j + 1].str().c_str(), nullptr);
             out.push_back(q);
           });
    } else {
      each(o.text, std::regex(R"(movej\(\[([^\]]*)\])"),
           [&](const std::smatch& m) { out.push_back(vec(numbers_in(m[1])) / kDeg); });
    }
  }
  return out;
}

using test::error_of;

/// Whether the lines appear in the text in this order (each a whole line).
bool lines_in_order(const std::string& text, const std::vector<std::string>& lines) {
  std::vector<std::string> have;
  for (size_t at = 0; at < text.size();) {
    const size_t nl = std::min(text.find('\n', at), text.size());
    have.push_back(text.substr(at, nl - at));
    at = nl + 1;
  }
  size_t k = 0;
  for (const std::string& l : lines) {
    while (k < have.size() && have[k] != l) ++k;
    if (k++ == have.size()) return false;
  }
  return true;
}

}  // namespace

// Joint targets: every language's values read back equal the written joints to half a unit of the printed
// decimal; the project's reader sees one joint motion per target, none of them a Cartesian target.
TEST(ControllerWriters, JointTargetsReadBack) {
  KINCAL_SEED_TRACE(71);
  const Model nom(kr500_spec());
  const std::vector<Vec6> q = random_joints(nom, 71, 6);
  for (ControllerFormat f : kFormats) {
    SCOPED_TRACE(format_name(f));
    WriterOptions w;
    w.format = f;
    const std::string out = ::testing::TempDir() + "wj" + ext_of(f);
    const auto files = write_controller_program(out, joint_targets(q), w);
    write_files_atomic(files);
    const std::vector<Vec6> back = joints_read_back(f, files);
    ASSERT_EQ(back.size(), q.size());
    double worst = 0;
    for (size_t i = 0; i < q.size(); ++i) worst = std::max(worst, (back[i] - q[i]).cwiseAbs().maxCoeff());
    EXPECT_LE(worst, joint_tolerance_deg(f) * (1 + 1e-6)) << "rounding to the printed decimals, no more";
    const NativeProgram p = read_native_program(files[0].path, f);
    EXPECT_TRUE(p.targets.empty());
    EXPECT_TRUE(p.unresolved.empty());
    ASSERT_EQ(p.motions.size(), q.size());
    for (const NativeMotion& m : p.motions) {
      EXPECT_EQ(m.kind, 'J');
      EXPECT_EQ(m.target, -1);  // joints, kept as written
    }
  }
}

// Filtered targets: the project's reader gives back every pose (program frame = robot base: tool 0, base 0,
// UF 0) to the printed precision and the branch data as written; the first motion is a joint motion, the
// others straight lines; and the controller's selection from the read-back target (select_branch on the
// nominal model) is the configuration the target was made of.
TEST(ControllerWriters, FilteredTargetsReadBackWithTheirBranchData) {
  KINCAL_SEED_TRACE(72, 9);
  const Robot robot = test::kr500_calibrated();
  const std::vector<Vec6> q = random_joints(*robot.nominal(), 72, 6);
  for (ControllerFormat f : kFormats) {
    SCOPED_TRACE(format_name(f));
    WriterOptions w;
    w.format = f;
    w.targets = TargetKind::Filtered;
    const std::vector<ControllerTarget> t = controller_targets(robot, q, TargetKind::Filtered, f, {});
    const std::string out = ::testing::TempDir() + "wf" + ext_of(f);
    const auto files = write_controller_program(out, t, w);
    write_files_atomic(files);
    const NativeProgram p = read_native_program(files[0].path, f);
    ASSERT_TRUE(p.unresolved.empty());
    ASSERT_EQ(p.motions.size(), t.size());
    const double mm = f == ControllerFormat::UrScript ? 5e-6 : 5e-5;
    const double deg = f == ControllerFormat::Krl ? 2e-6 : f == ControllerFormat::Rapid ? 1e-6
                       : f == ControllerFormat::FanucLs ? 2e-4 : 1e-7;
    for (size_t i = 0; i < t.size(); ++i) {
      SCOPED_TRACE("target " + std::to_string(i + 1));
      const NativeMotion& m = p.motions[i];
      EXPECT_EQ(m.kind, i == 0 ? 'J' : 'L');
      ASSERT_GE(m.target, 0);
      const NativeTarget& back = p.targets[static_cast<size_t>(m.target)];
      EXPECT_TRUE(back.frame.isApprox(Eigen::Isometry3d::Identity(), 1e-15));
      EXPECT_LE((back.pose.xyz - t[i].pose.xyz).cwiseAbs().maxCoeff(), mm * (1 + 1e-6));
      EXPECT_LE(test::rot_dist(abc_to_rotation(back.pose.abc), abc_to_rotation(t[i].pose.abc)) / kDeg, deg);
      if (f == ControllerFormat::UrScript) {
        EXPECT_FALSE(back.taught.has_value());  // a UR controller takes no branch data
        continue;
      }
      ASSERT_TRUE(back.taught.has_value());
      EXPECT_EQ(branch_text(f, *back.taught), branch_text(f, t[i]));
      ControllerTarget read = *back.taught;
      read.pose = back.pose;
      std::string why;
      const auto sel = select_branch(robot, f, read, &why, 1e-4);
      ASSERT_TRUE(sel.has_value()) << why;
      // the same solution: a pose printed to 1e-4 mm / 1e-4 deg moves A4 and A6 by up to 1e-4 / sin A5 deg (2e-3 at
      // 3 deg from the wrist singularity); the other solutions are degrees away
      EXPECT_LT((*sel - q[i]).cwiseAbs().maxCoeff(), 1e-2) << sel->transpose() << " vs " << q[i].transpose();
    }
  }
}

// The key lines of each language for three joint targets with a zone and a speed: KRL DEF / PTP .. C_DIS /
// END and DEFDAT / DECL E6AXIS / ENDDAT; RAPID MODULE / CONST jointtarget / PROC main / MoveAbsJ / ENDPROC /
// ENDMODULE with its zonedata; FANUC LS /PROG / /MN / /POS / /END with CNT and the last FINE; URScript def / movej
// with its blend radius / end. The last motion of each stops exactly (no zone).
TEST(ControllerWriters, KeySyntaxLines) {
  std::vector<Vec6> q(3);
  q[0] << 10, -70, 100, 30, -40, 60;
  q[1] << -15.1234564, -80, 95, -200, -35, 190;
  q[2] << 20, -60, 110, 150, -50, -250;
  WriterOptions w;
  w.zone = 10;
  w.speed = 35;
  const std::string dir = ::testing::TempDir();
  w.format = ControllerFormat::Krl;
  auto f = write_controller_program(dir + "keys.src", joint_targets(q), w);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].path, dir + "keys.src");
  EXPECT_EQ(f[1].path, dir + "keys.dat");
  const std::vector<std::string> src = {"&ACCESS RVP",      "&REL 1",        "DEF keys( )",   "BAS(#INITMOV,0)",
                                        "BAS(#VEL_PTP,35.0)", "$APO.CDIS=10.000", "PTP XP1 C_DIS", "PTP XP2 C_DIS",
                                        "PTP XP3",            "END"};
  EXPECT_TRUE(lines_in_order(f[0].text, src)) << f[0].text;
  const std::vector<std::string> dat = {
      "DEFDAT keys",
      "DECL E6AXIS XP2={A1 -15.123456,A2 -80.000000,A3 95.000000,A4 -200.000000,A5 -35.000000,A6 190.000000,"
      "E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}",
      "ENDDAT"};
  EXPECT_TRUE(lines_in_order(f[1].text, dat)) << f[1].text;
  w.format = ControllerFormat::Rapid;
  f = write_controller_program(dir + "keys.mod", joint_targets(q), w);
  ASSERT_EQ(f.size(), 1u);
  const std::vector<std::string> mod = {
      "MODULE keys",
      "  CONST zonedata kc_zone:=[FALSE,10.000,15.000,15.000,1.5000,15.000,1.5000];",
      "  CONST jointtarget jt1:=[[10.000000,-70.000000,100.000000,30.000000,-40.000000,60.000000],"
      "[9E9,9E9,9E9,9E9,9E9,9E9]];",
      "  PROC main()",
      "    VelSet 35.0,7000;",
      "    MoveAbsJ jt1\\NoEOffs,v7000,kc_zone,tool0;",
      "    MoveAbsJ jt3\\NoEOffs,v7000,fine,tool0;",
      "  ENDPROC",
      "ENDMODULE"};
  EXPECT_TRUE(lines_in_order(f[0].text, mod)) << f[0].text;
  w.format = ControllerFormat::FanucLs;
  w.zone = 50;
  f = write_controller_program(dir + "keys.ls", joint_targets(q), w);
  ASSERT_EQ(f.size(), 1u);
  const std::vector<std::string> ls = {"/PROG  KEYS",
                                       "/ATTR",
                                       "LINE_COUNT\t= 3;",
                                       "/MN",
                                       "   1:  J P[1] 35% CNT50    ;",
                                       "   3:  J P[3] 35% FINE    ;",
                                       "/POS",
                                       "P[2]{",
                                       "   GP1:",
                                       "\tUF : 0, UT : 1,",
                                       "\tJ1=   -15.1235 deg,\tJ2=   -80.0000 deg,\tJ3=    95.0000 deg,",
                                       "};",
                                       "/END"};
  EXPECT_TRUE(lines_in_order(f[0].text, ls)) << f[0].text;
  w.format = ControllerFormat::UrScript;
  w.zone = 10;
  f = write_controller_program(dir + "keys.script", joint_targets(q), w);
  ASSERT_EQ(f.size(), 1u);
  // the joints in rad; v: 35% of 180 deg/s in rad/s; r: 10 mm in m, 0 at the last
  const std::vector<std::string> script = {
      "def keys():",
      "  movej([0.1745329252, -1.2217304764, 1.7453292520, 0.5235987756, -0.6981317008, 1.0471975512], a=1.4, "
      "v=1.0996, r=0.0100)",
      "  movej([0.3490658504, -1.0471975512, 1.9198621772, 2.6179938780, -0.8726646260, -4.3633231300], a=1.4, "
      "v=1.0996, r=0.0000)",
      "end"};
  EXPECT_TRUE(lines_in_order(f[0].text, script)) << f[0].text;
}

// A program longer than max_targets_per_file is split into parts NAME_1 .. NAME_k (KRL and FANUC LS) that the
// main program calls in turn; read back part after part, the joints are the program's, in order.
TEST(ControllerWriters, LongProgramsAreSplitIntoParts) {
  KINCAL_SEED_TRACE(73);
  const Model nom(kr500_spec());
  const std::vector<Vec6> q = random_joints(nom, 73, 5);
  for (ControllerFormat f : {ControllerFormat::Krl, ControllerFormat::FanucLs}) {
    SCOPED_TRACE(format_name(f));
    WriterOptions w;
    w.format = f;
    w.max_targets_per_file = 2;
    const auto files = write_controller_program(::testing::TempDir() + "split" + ext_of(f), joint_targets(q), w);
    write_files_atomic(files);
    ASSERT_EQ(files.size(), f == ControllerFormat::Krl ? 8u : 4u);  // the main program and 3 parts
    const std::string& main = files[0].text;
    if (f == ControllerFormat::Krl) {
      EXPECT_TRUE(lines_in_order(main, {"DEF split( )", "split_1( )", "split_2( )", "split_3( )", "END"})) << main;
      EXPECT_EQ(files[2].path, ::testing::TempDir() + "split_1.src");
    } else {
      EXPECT_TRUE(lines_in_order(main, {"/PROG  SPLIT", "   1:  CALL SPLIT_1    ;", "   3:  CALL SPLIT_3    ;",
                                        "/END"}))
          << main;
      EXPECT_EQ(files[1].path, ::testing::TempDir() + "SPLIT_1.ls");
    }
    const std::vector<OutputFile> parts(files.begin() + (f == ControllerFormat::Krl ? 2 : 1), files.end());
    const std::vector<Vec6> back = joints_read_back(f, parts);
    ASSERT_EQ(back.size(), q.size());
    for (size_t i = 0; i < q.size(); ++i)
      EXPECT_LE((back[i] - q[i]).cwiseAbs().maxCoeff(), joint_tolerance_deg(f) * (1 + 1e-6)) << i;
  }
}

// The writers' limits: each refusal is an InputError naming the cause, and nothing is returned to write.
TEST(ControllerWriters, BadNamesAndOptionsAreRefused) {
  const std::vector<ControllerTarget> t = joint_targets({Vec6::Zero()});
  const std::string dir = ::testing::TempDir();
  const auto err = [&](const std::string& out, ControllerFormat f, const std::function<void(WriterOptions&)>& set) {
    WriterOptions w;
    w.format = f;
    set(w);
    return error_of([&] { write_controller_program(out, t, w); });
  };
  const auto none = [](WriterOptions&) {};
  EXPECT_NE(err(dir + "x.src", ControllerFormat::Krl, [](WriterOptions& w) { w.name = "other"; })
                .find("a KRL module is named by its files"),
            std::string::npos);
  EXPECT_NE(err(dir + "abcdefghijklmnopqrstuvwxy.src", ControllerFormat::Krl, none)  // 25 characters
                .find("longer than the 24 characters"),
            std::string::npos);
  EXPECT_EQ(err(dir + "abcdefghijklmnopqrstuvwx.src", ControllerFormat::Krl, none), "(no error)");  // 24: taken
  EXPECT_NE(err(dir + "1prog.mod", ControllerFormat::Rapid, none).find("must start with a letter"), std::string::npos);
  EXPECT_NE(err(dir + "my-prog.script", ControllerFormat::UrScript, none).find("only letters, digits and '_'"),
            std::string::npos);
  EXPECT_NE(err(dir + "p.ls", ControllerFormat::FanucLs, [](WriterOptions& w) { w.zone = 101; })
                .find("CNT value 0..100"),
            std::string::npos);
  EXPECT_NE(err(dir + "p.mod", ControllerFormat::Rapid, [](WriterOptions& w) { w.speed = 150; }).find("--speed"),
            std::string::npos);
  EXPECT_NE(err(dir + "p.script", ControllerFormat::UrScript, [](WriterOptions& w) { w.zone = -1; }).find("--zone"),
            std::string::npos);
  WriterOptions w;
  w.format = ControllerFormat::Rapid;
  EXPECT_NE(error_of([&] { write_controller_program(dir + "p.mod", {}, w); }).find("no targets to write"),
            std::string::npos);
  std::vector<ControllerTarget> nan = t;
  nan[0].q_deg[2] = std::nan("");
  EXPECT_NE(error_of([&] { write_controller_program(dir + "p.mod", nan, w); }).find("not a finite number"),
            std::string::npos);
  // the formats by name and by extension
  EXPECT_EQ(controller_format_named("fanuc-ls"), ControllerFormat::FanucLs);
  EXPECT_EQ(controller_format_of_path("a/B.MODX"), ControllerFormat::Rapid);
  EXPECT_EQ(controller_format_of_path("prog.ngc"), ControllerFormat::Gcode);
  EXPECT_NE(error_of([] { controller_format_named("vplus"); }).find("not a format"), std::string::npos);
  // the target kinds by name: any other word refused (it once fell back to joint targets silently)
  EXPECT_EQ(target_kind_named("joints"), TargetKind::Joints);
  EXPECT_EQ(target_kind_named("filtered"), TargetKind::Filtered);
  EXPECT_EQ(error_of([] { target_kind_named("filterd"); }), "--targets filterd: joints or filtered");
}
