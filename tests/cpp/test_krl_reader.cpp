// KUKA KRL programs read in: the constructs of the controller's manual (issue 30). The backup under
// tests/data/programs/krl/KRC (re-created, see its README) and small programs written here.
#include "kincal/compensation/branch.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include "test_files.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <tuple>

namespace kincal {
namespace {

const std::string kBackup = [] {
  const std::string here = __FILE__;
  return here.substr(0, here.find_last_of("/\\")) + "/../data/programs/krl/KRC/R1/";
}();
const std::string kConfig = kBackup + "System/$config.dat";
std::string program(const std::string& name) { return kBackup + "Program/" + name; }

Declarations backup_declarations() {
  return read_declarations({kConfig, program("pick.src"), program("pick.dat"), program("weld.src"), program("weld.dat"),
                            program("service.src"), program("service.dat")},
                           ControllerFormat::Krl);
}

// A program NAME.src (and NAME.dat when dat is not empty) in the test's temporary directory.
std::string krl(const std::string& name, const std::string& src, const std::string& dat = "") {
  if (!dat.empty()) test::tmp(name + ".dat", "DEFDAT " + name + "\n" + dat + "ENDDAT\n");
  return test::tmp(name + ".src", "DEF " + name + "( )\n" + src + "END\n");
}

using test::error_of;

const std::string kPose = "X 2000.0,Y -600.0,Z 520.0,A 0.0,B 90.0,C 0.0";
const std::string kTools =  // tool 1, tool 2, base 1, base 2 in a $config.dat
    "DEFDAT $CONFIG\nTOOL_DATA[1]={X 240.0,Y 0.0,Z 35.0,A 0.0,B 0.0,C 0.0}\n"
    "$TOOL_DATA[2]={X 310.0,Y 60.0,Z 0.0,A 0.0,B 0.0,C 30.0}\nBASE_DATA[1]={X 100.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0}\n"
    "BASE_DATA[2]={X 0.0,Y 200.0,Z 0.0,A 90.0,B 0.0,C 0.0}\nENDDAT\n";
Declarations tools() {
  return read_declarations({test::tmp("$config.dat", kTools)}, ControllerFormat::Krl);
}

TEST(KrlReader, KrlInlineTargetFollowedByItsApproximation) {
  // issue 30's bug: "LIN {..,C -168.9433} C_DIS" was refused ("C '-168.9433} C_DI' is not a number"); every
  // approximation (C_PTP, C_DIS, C_VEL, C_ORI) and CIRC's CA angle stand after the target, outside its span
  const std::string lin = "LIN {X 2000.0,Y -600.0,Z 520.0,A 4.0,B 85.0,C -168.9433} C_DIS";
  const std::string path = krl("approx", "PTP {" + kPose + "} C_PTP\n" + lin + "\nLIN XP2 C_VEL\nCIRC XP1, XP2, CA 90.0 C_ORI\n",
                               "DECL E6POS XP1={" + kPose + "}\nDECL E6POS XP2={X 2000.0,Y -500.0,Z 520.0,A 0.0,B 90.0,C 0.0}\n");
  const NativeProgram p = read_native_program(path, ControllerFormat::Krl);
  ASSERT_EQ(p.motions.size(), 5u);
  ASSERT_EQ(p.targets.size(), 4u);
  EXPECT_DOUBLE_EQ(p.targets[1].pose.abc[2], -168.9433);
  EXPECT_EQ(p.lines[0][2].substr(p.targets[1].begin, p.targets[1].end - p.targets[1].begin),
            "{X 2000.0,Y -600.0,Z 520.0,A 4.0,B 85.0,C -168.9433}");
  EXPECT_EQ(p.motions[1].tail, " C_DIS");
  EXPECT_EQ(p.motions[0].kind, 'J');
  EXPECT_EQ(p.motions[2].kind, 'L');
  EXPECT_EQ(p.motions[3].kind, 'C');
  EXPECT_EQ(p.motions[4].target, 2);  // XP2 again: CIRC's end point
  EXPECT_TRUE(p.unresolved.empty());
  EXPECT_NE(error_of([&] { read_native_program(krl("bad", "LIN XP1, XP2\n", "DECL E6POS XP1={" + kPose + "}\n"), ControllerFormat::Krl); })
                .find("bad.src:2: 'XP2' after the target of LIN"),
            std::string::npos);
}

TEST(KrlReader, KrlSplineMotionsWithWith) {
  // KSS 8 SPTP/SLIN/SCIRC: the target before WITH; the WITH list's $TOOL = STOOL2(FP), $BASE = SBASE(FP.BASE_NO)
  // give that motion its frames (for it alone); C_SPL after the list
  const std::string with = " WITH $VEL = SVEL_CP(0.2, , LCPDAT1), $TOOL = STOOL2(FP1), $BASE = SBASE(FP1.BASE_NO), "
                           "$IPO_MODE = SIPO_MODE(FP1.IPO_FRAME)";
  const std::string path = krl("spl", "SPTP XP1" + with + " C_SPL\nSLIN XP2" + with + "\nSCIRC XP1, XP2" + with + "\nSLIN XP2\n",
                               "DECL E6POS XP1={" + kPose + "}\nDECL E6POS XP2={X 2000.0,Y -500.0,Z 520.0,A 0.0,B 90.0,C 0.0}\n"
                               "DECL FDAT FP1={TOOL_NO 2,BASE_NO 1,IPO_FRAME #BASE,POINT2[] \" \",TQ_STATE FALSE}\n");
  const NativeProgram p = read_native_program(path, ControllerFormat::Krl, tools());
  ASSERT_EQ(p.motions.size(), 5u);
  EXPECT_EQ(std::string() + p.motions[0].kind + p.motions[1].kind + p.motions[2].kind + p.motions[3].kind + p.motions[4].kind, "JLCCL");
  EXPECT_EQ(p.motions[0].tail, with + " C_SPL");
  EXPECT_EQ(p.targets[0].frames_named, "TOOL_DATA[2], BASE_DATA[1]");
  EXPECT_NEAR(p.targets[0].tool.translation().x(), 310.0, 1e-12);
  EXPECT_NEAR(p.targets[0].frame.translation().x(), 100.0, 1e-12);
  EXPECT_EQ(p.motions[3].target, 1);
  // the last SLIN has no WITH: the program's frames (tool 0, base 0) hold, so XP2 gets a copy there
  ASSERT_EQ(p.targets.size(), 3u);
  EXPECT_EQ(p.targets[2].copy_of, 1);
  EXPECT_EQ(p.targets[2].frames_named, "");
}

TEST(KrlReader, KrlSplineBlock) {
  // SPLINE ... ENDSPLINE of SPL ('O': a spline through its points), SLIN ('L'), SCIRC ('C'); PTP_SPLINE ...
  // ENDSPLINE of SPTP ('J'); the block's WITH frames apply to its segments; misplaced segments are refused
  const std::string dat = "DECL E6POS XP1={" + kPose + "}\nDECL E6POS XP2={X 2000.0,Y -500.0,Z 520.0,A 0.0,B 90.0,C 0.0}\n";
  const std::string path = krl("block",
                               "SPLINE WITH $TOOL = TOOL_DATA[1], $BASE = BASE_DATA[2]\n  SPL XP1\n  SPL {" + kPose +
                                   "} WITH $VEL.CP = 0.1\n  SLIN XP2 C_SPL\n  SCIRC XP1, XP2\nENDSPLINE C_SPL\n"
                                   "PTP_SPLINE\n  SPTP XP1\n  SPTP XP2 C_SPL\nENDSPLINE\n",
                               dat);
  const NativeProgram p = read_native_program(path, ControllerFormat::Krl, tools());
  std::string kinds;
  for (const NativeMotion& m : p.motions) kinds += m.kind;
  EXPECT_EQ(kinds, "OOLCCJJ");
  EXPECT_EQ(p.targets[0].frames_named, "TOOL_DATA[1], BASE_DATA[2]");
  EXPECT_EQ(p.targets[p.motions[5].target].frames_named, "");  // after ENDSPLINE: the program's frames again
  for (const auto& [src, message] : std::vector<std::pair<std::string, std::string>>{
           {"SPL XP1\n", "x.src:2: SPL outside a SPLINE ... ENDSPLINE block"},
           {"SPLINE\nSPTP XP1\nENDSPLINE\n", "x.src:3: SPTP inside a SPLINE block (SPL, SLIN, SCIRC only)"},
           {"PTP_SPLINE\nSLIN XP1\nENDSPLINE\n", "x.src:3: SLIN inside a PTP_SPLINE block (SPTP only)"},
           {"SPLINE\nSPL XP1\n", "x.src:2: SPLINE is not closed by ENDSPLINE"},
           {"ENDSPLINE\n", "x.src:2: ENDSPLINE without SPLINE"}}) {
    const std::string e = error_of([&] { read_native_program(krl("x", src, dat), ControllerFormat::Krl); });
    EXPECT_NE(e.find(message), std::string::npos) << e;
  }
}

TEST(KrlReader, KrlEveryRelativeMotionAndRunTimeTargetIsUnresolved) {
  // every _REL motion, $POS_ACT, the geometric operator, an expression, a name declared nowhere, a target the
  // program assigns: listed with why, never compensated, never an error here
  const std::vector<std::string> rel = {"PTP_REL {A1 10.0}", "LIN_REL {Z 10.0} C_DIS", "CIRC_REL {X 5.0}, {X 10.0}",
                                        "SPTP_REL {A1 10.0}", "SLIN_REL {Z 10.0} WITH $VEL.CP = 0.1", "SCIRC_REL {X 5.0}, {X 10.0}"};
  std::string src;
  for (const std::string& r : rel) src += r + "\n";
  src += "LIN $POS_ACT\nLIN XP1:{X 0.0,Y 0.0,Z 10.0,A 0.0,B 0.0,C 0.0}\nLIN XSOMEWHERE\nXP2.Z = 650.0\nLIN XP2\n"
         "LIN {Z 100.0}\nLIN XP3\n";
  const NativeProgram p = read_native_program(
      krl("rt", src, "DECL E6POS XP1={" + kPose + "}\nDECL E6POS XP2={" + kPose + "}\nDECL E6POS XP3\n"), ControllerFormat::Krl);
  ASSERT_EQ(p.unresolved.size(), rel.size() + 6);
  for (size_t k = 0; k < rel.size(); ++k) {
    const std::string kw = rel[k].substr(0, rel[k].find(' '));
    EXPECT_EQ(p.unresolved[k].why, "a relative motion (" + kw + "): its target depends on where the robot is");
    EXPECT_EQ(p.unresolved[k].where, where(::testing::TempDir() + "rt.src", static_cast<int>(k + 2)));
    EXPECT_EQ(p.unresolved[k].text, rel[k]);
  }
  const std::vector<std::string> why = {"a system variable ($POS_ACT): where the robot is at run time",
                                        "a geometric operator (XP1:{X 0.0,Y 0.0,Z 10.0,A 0.0,B 0.0,C 0.0}): computed at run time",
                                        "declared nowhere", "assigned in the program: computed at run time",
                                        "an aggregate without X: the rest is where the robot is at run time",
                                        "declared without a value: set at run time"};
  for (size_t k = 0; k < why.size(); ++k) EXPECT_EQ(p.unresolved[rel.size() + k].why, why[k]);
  EXPECT_TRUE(p.targets.empty());
  for (const NativeMotion& m : p.motions) EXPECT_EQ(m.target, -1);
}

TEST(KrlReader, KrlConfigDatDeclarations) {
  // a backup's declarations: every one of $config.dat (E6AXIS XHOME, E6POS, FDAT, TOOL_DATA[n] and $TOOL_DATA[n],
  // BASE_DATA[n]), of the other data lists only DECL GLOBAL; the first declaration of a name wins
  const Declarations d = backup_declarations();
  const Declaration* home = d.find("xhome");
  ASSERT_TRUE(home);
  EXPECT_EQ(home->type, "E6AXIS");
  EXPECT_EQ(home->path, kConfig);
  EXPECT_EQ(home->line, 10);
  for (const char* name : {"TOOL_DATA[1]", "TOOL_DATA[2]", "BASE_DATA[1]", "BASE_DATA[2]"}) {
    ASSERT_TRUE(d.find(name)) << name;
    EXPECT_EQ(d.find(name)->type, "FRAME");
  }
  EXPECT_EQ(d.find("TOOL_DATA[2]")->value, "{X 310.0,Y 60.0,Z 0.0,A 0.0,B 0.0,C 30.0}");
  EXPECT_EQ(d.find("TOOL_DATA[2]")->line, 18);
  EXPECT_EQ(d.find("XSERVICE")->type, "E6POS");
  EXPECT_EQ(d.find("XPARK")->type, "E6POS");  // $config.dat: global without GLOBAL
  EXPECT_EQ(d.find("FHOME")->type, "FDAT");
  ASSERT_TRUE(d.find("XSEAM_START"));  // DECL GLOBAL in weld.dat
  EXPECT_EQ(d.find("XSEAM_START")->path, program("weld.dat"));
  EXPECT_FALSE(d.find("XCHECK"));  // service.dat's own
  EXPECT_FALSE(d.find("TOOL_DATA[3]"));
  // $config.dat's $TOOL_DATA[n] form; a name assigned in a .src is set at run time
  const Declarations t = read_declarations({test::tmp("$config.dat", kTools), krl("assigns", "XG = XG\n"),
                                            test::tmp("g.dat", "DEFDAT g PUBLIC\nDECL GLOBAL E6POS XG={" + kPose + "}\nENDDAT\n")},
                                           ControllerFormat::Krl);
  EXPECT_EQ(t.find("TOOL_DATA[2]")->line, 3);
  EXPECT_TRUE(t.find("XG")->run_time);
}

TEST(KrlReader, KrlKss5InlineFormsGiveEachMotionItsToolAndBase) {
  // pick.src: KSS 5 inline forms, FDAT_ACT=FPn applied by BAS(#PTP_PARAMS / #CP_PARAMS): tool 1 on base 1, then
  // tool 2 on base 2; XHOME from $config.dat stays joints; XP1, used again on base 2, gets a copy XP1_1
  const NativeProgram p = read_native_program(program("pick.src"), ControllerFormat::Krl, backup_declarations());
  ASSERT_EQ(p.paths.size(), 2u);  // pick.src and pick.dat ($config.dat: nothing compensated there)
  std::vector<std::string> names, frames;
  for (const NativeTarget& t : p.targets) names.push_back(t.name), frames.push_back(t.frames_named);
  EXPECT_EQ(names, (std::vector<std::string>{"XP1", "XP2", "XP3", "XP4", "XP5", "XP6", "XP7", "XP1_1"}));
  const std::string t1 = "TOOL_DATA[1], BASE_DATA[1]", t2 = "TOOL_DATA[2], BASE_DATA[2]";
  EXPECT_EQ(frames, (std::vector<std::string>{t1, t1, t1, t2, t2, t2, t2, t2}));
  EXPECT_NEAR(p.targets[0].tool.translation().x(), 240.0, 1e-12);
  EXPECT_NEAR(p.targets[3].frame.translation().y(), 350.0, 1e-12);
  EXPECT_EQ(p.motions.front().target, -1);  // PTP XHOME
  EXPECT_EQ(p.motions.front().kind, 'J');
  EXPECT_TRUE(p.unresolved.empty());
  for (const NativeMotion& m : p.motions) EXPECT_EQ(m.file, 0);
}

TEST(KrlReader, KrlContextTargetsAreCompensatedInTheirDeclaringFile) {
  // service.src: XSERVICE and XPARK ($config.dat) and XSEAM_START (weld.dat, DECL GLOBAL) are compensated where
  // they are declared: those files join the program; $TOOL = TOOL_DATA[1], BAS(#TOOL,2), $TOOL = $NULLFRAME
  const NativeProgram p = read_native_program(program("service.src"), ControllerFormat::Krl, backup_declarations());
  ASSERT_EQ(p.paths.size(), 4u);
  EXPECT_EQ(p.paths[2], kConfig);
  EXPECT_EQ(p.paths[3], program("weld.dat"));
  std::map<std::string, const NativeTarget*> by;
  for (const NativeTarget& t : p.targets) by[t.name] = &t;
  ASSERT_EQ(p.targets.size(), 5u);  // XSERVICE, the inline LIN, XCHECK, XSEAM_START, XPARK
  EXPECT_EQ(by["XSERVICE"]->file, 2);
  EXPECT_EQ(by["XSERVICE"]->line, 31);
  EXPECT_EQ(p.lines[2][30].substr(by["XSERVICE"]->begin, 5), "{X 12");
  EXPECT_EQ(by["XSERVICE"]->frames_named, "TOOL_DATA[1], BASE_DATA[2]");
  EXPECT_EQ(by["XSEAM_START"]->file, 3);
  EXPECT_EQ(by["XSEAM_START"]->frames_named, "TOOL_DATA[2], BASE_DATA[1]");
  EXPECT_EQ(by["XCHECK"]->file, 1);
  EXPECT_EQ(by["XPARK"]->frames_named, "");
  EXPECT_TRUE(by["XPARK"]->tool.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(by[""]->file, 0);
  ASSERT_TRUE(by["XSEAM_START"]->joint_edits.size() == 1);
  EXPECT_EQ(by["XSEAM_START"]->joint_edits[0].file, 3);
  EXPECT_EQ(p.lines[3][by["XSEAM_START"]->joint_edits[0].line - 1].substr(by["XSEAM_START"]->joint_edits[0].begin, 5), "E6POS");
}

TEST(KrlReader, KrlMissingToolDataIsAnError) {
  // a tool or base number with no TOOL_DATA / BASE_DATA entry: an error at the motion naming the entry
  const std::string e = error_of([] {
    read_native_program(krl("t3", "BAS(#TOOL,3)\nLIN {" + kPose + "}\n"), ControllerFormat::Krl, tools());
  });
  EXPECT_NE(e.find("t3.src:3: the motion's tool TOOL_DATA[3] is not declared: give the backup's $config.dat or --declarations"),
            std::string::npos)
      << e;
  const std::string b = error_of([] { read_native_program(krl("b", "$BASE = BASE_DATA[1]\nLIN {" + kPose + "}\n"), ControllerFormat::Krl); });
  EXPECT_NE(b.find("b.src:3: the motion's base BASE_DATA[1] is not declared"), std::string::npos) << b;
  // an FDAT declared nowhere: the same, at the first Cartesian motion in its frames; joints need no frame
  const std::string with = " WITH $TOOL = STOOL2(FHOME), $BASE = SBASE(FHOME.BASE_NO), $IPO_MODE = SIPO_MODE(FHOME.IPO_FRAME)\n";
  const std::string f = error_of([&] {
    read_native_program(krl("f", "SPTP {A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 30.0,A6 0.0}" + with + "SLIN {" + kPose + "}" + with),
                        ControllerFormat::Krl);
  });
  EXPECT_NE(f.find("f.src:3: the FDAT FHOME is not declared: give the backup's $config.dat or --declarations"), std::string::npos) << f;
  EXPECT_NO_THROW(read_native_program(krl("j", "BAS(#TOOL,3)\nPTP {A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 30.0,A6 0.0}\n"), ControllerFormat::Krl));
}

TEST(KrlReader, KrlStationaryToolIsRefused) {
  // IPO_FRAME #TCP (an FDAT's) or $IPO_MODE = #TCP: the robot carries the part past a fixed tool
  const std::string dat = "DECL E6POS XP1={" + kPose + "}\nDECL FDAT FP1={TOOL_NO 1,BASE_NO 1,IPO_FRAME #TCP,POINT2[] \" \"}\n";
  for (const std::string& src : {std::string("FDAT_ACT=FP1\nBAS(#CP_PARAMS,0.2)\nLIN XP1\n"),
                                  std::string("SLIN XP1 WITH $TOOL = STOOL2(FP1), $IPO_MODE = SIPO_MODE(FP1.IPO_FRAME)\n"),
                                  std::string("$IPO_MODE = #TCP\n\nLIN XP1\n")}) {
    const std::string e = error_of([&] { read_native_program(krl("tcp", src, dat), ControllerFormat::Krl, tools()); });
    EXPECT_NE(e.find("tcp.src:" + std::to_string(1 + static_cast<int>(std::count(src.begin(), src.end(), '\n'))) +
                     ": a stationary tool (IPO_FRAME #TCP): kincal does not compensate it"),
              std::string::npos)
        << e;
  }
}

TEST(KrlReader, KrlTargetInTwoFramesGetsACopy) {
  // a declared target used in a second (tool, base): a copy named NAME_1 (cut to 24 characters, unique among the
  // declared names), at the original's declaration, with edits renaming it in those motions' statements only
  const std::string name = "XAPPROACH_OVER_THE_TABLE";  // 24 characters
  const std::string path = krl("two",
                               "$TOOL = TOOL_DATA[1]\nLIN " + name + " ; over the table\n$BASE = BASE_DATA[2]\nLIN " + name +
                                   " C_DIS ; " + name + "\nPTP " + name + "\n$BASE = BASE_DATA[1]\nLIN " + name + "\n",
                               "DECL E6POS " + name + "={" + kPose + "}\nDECL E6POS XAPPROACH_OVER_THE_TAB_1={" + kPose + "}\n");
  const NativeProgram p = read_native_program(path, ControllerFormat::Krl, tools());
  ASSERT_EQ(p.targets.size(), 3u);
  const NativeTarget &a = p.targets[0], &b = p.targets[1], &c = p.targets[2];
  EXPECT_EQ(a.copy_of, -1);
  EXPECT_EQ(b.copy_of, 0);
  EXPECT_EQ(b.name, "XAPPROACH_OVER_THE_TAB_2");  // _1 is taken
  EXPECT_EQ(c.name, "XAPPROACH_OVER_THE_TAB_3");
  EXPECT_EQ(b.frames_named, "TOOL_DATA[1], BASE_DATA[2]");
  EXPECT_EQ(c.frames_named, "TOOL_DATA[1], BASE_DATA[1]");
  EXPECT_EQ(std::make_tuple(b.file, b.line, b.begin, b.end), std::make_tuple(a.file, a.line, a.begin, a.end));
  ASSERT_EQ(b.edits.size(), 2u);  // LIN .. C_DIS and PTP (not the comment)
  for (const NativeEdit& e : b.edits) {
    EXPECT_EQ(p.lines[0][static_cast<size_t>(e.line - 1)].substr(e.begin, e.end - e.begin), name);
    EXPECT_EQ(e.text, b.name);
  }
  EXPECT_EQ(b.edits[0].line, 5);
  EXPECT_EQ(b.edits[1].line, 6);
  EXPECT_TRUE(a.edits.empty());
  EXPECT_EQ(p.motions[0].target, 0);
  EXPECT_EQ(p.motions[2].target, 1);
  EXPECT_EQ(p.motions[3].target, 2);
}

TEST(KrlReader, KrlTaughtBranchAndExternalAxes) {
  // S and T as taught (numbers or 'B..' literals) are the target's branch; none without both; E1..E6 as written
  const NativeProgram p = read_native_program(
      krl("st", "PTP XP1\nLIN XP2\nLIN {" + kPose + ",S 'B110',T 'B110010',E1 350.0}\n",
          "DECL E6POS XP1={" + kPose + ",S 6,T 50,E1 -120.5,E2 0.0}\nDECL E6POS XP2={" + kPose + ",S 2}\n"),
      ControllerFormat::Krl);
  ASSERT_EQ(p.targets.size(), 3u);
  ASSERT_TRUE(p.targets[0].taught);
  EXPECT_EQ(p.targets[0].taught->kuka_s, 6);
  EXPECT_EQ(p.targets[0].taught->kuka_t, 50);
  EXPECT_FALSE(p.targets[1].taught);
  ASSERT_TRUE(p.targets[2].taught);
  EXPECT_EQ(p.targets[2].taught->kuka_s, 6);
  EXPECT_EQ(p.targets[2].taught->kuka_t, 50);
  EXPECT_EQ(p.targets[0].external[0], -120.5);
  EXPECT_EQ(p.targets[0].external[1], 0.0);
  EXPECT_TRUE(std::isnan(p.targets[0].external[2]));
  EXPECT_TRUE(std::isnan(p.targets[1].external[0]));
  EXPECT_EQ(p.targets[2].external[0], 350.0);
}

TEST(KrlReader, KrlNameDeclaredNowhereIsUnresolved) {
  // XHOME without the backup's $config.dat: no longer an error here but listed (the compensation stage lists
  // every such target and decides); with it, XHOME is joints
  const std::string path = krl("home", "PTP XHOME\nLIN XP1\n", "DECL E6POS XP1={" + kPose + "}\n");
  const NativeProgram p = read_native_program(path, ControllerFormat::Krl);
  ASSERT_EQ(p.unresolved.size(), 1u);
  EXPECT_EQ(p.unresolved[0].where, where(path, 2));
  EXPECT_EQ(p.unresolved[0].text, "PTP XHOME");
  EXPECT_EQ(p.unresolved[0].why, "declared nowhere");
  EXPECT_TRUE(read_native_program(path, ControllerFormat::Krl, backup_declarations()).unresolved.empty());
}

TEST(KrlReader, KrlBackupProgramsReadAsOneReachTheirTaughtBranch) {
  KINCAL_SEED_TRACE(9);
  // the three programs read as one: motions in their files, each declared target once per frame, and every
  // target reached by the nominal kr500 on its taught branch through its own tool and base
  const NativeProgram p = read_native_programs({program("pick.src"), program("weld.src"), program("service.src")},
                                               ControllerFormat::Krl, backup_declarations());
  EXPECT_EQ(p.paths.size(), 7u);  // three .src with their .dat, and $config.dat
  EXPECT_TRUE(p.unresolved.empty());
  std::set<int> files;
  for (const NativeMotion& m : p.motions) files.insert(m.file);
  EXPECT_EQ(files, (std::set<int>{0, 2, 4}));
  size_t xseam = 0;
  for (const NativeTarget& t : p.targets) xseam += t.name == "XSEAM_START";
  EXPECT_EQ(xseam, 1u);  // service.src uses weld.dat's: the file is not read twice
  const Robot robot = test::kr500_calibrated();
  for (const NativeTarget& t : p.targets) {
    ControllerTarget c;
    c.pose = iso_to_pose(t.frame * pose_to_iso(t.pose) * t.tool.inverse());
    ASSERT_TRUE(t.taught || t.name.empty() || t.name == "XP6") << t.name;
    if (!t.taught) continue;
    c.kuka_s = t.taught->kuka_s;
    c.kuka_t = t.taught->kuka_t;
    std::string why;
    EXPECT_TRUE(select_branch(robot, ControllerFormat::Krl, c, &why))
        << t.name << " (" << t.frames_named << "): " << why;
  }
}

TEST(KrlReader, KrlTapeProgramAsBefore) {
  // tests/data/programs/tape.src: E6POS / POS / FRAME targets, the inline LIN, XHOME joints, joint edits; its
  // $TOOL = $NULLFRAME is tool 0 (a TOOL_DATA[n] would need its declaration: KrlMissingToolDataIsAnError)
  const std::string tape = kBackup + "../../../tape.src";
  const NativeProgram p = read_native_program(tape, ControllerFormat::Krl);
  ASSERT_EQ(p.targets.size(), 6u);  // XP1, XP2, the inline LIN, XAUX, XP3, XP4
  EXPECT_TRUE(p.unresolved.empty());
  EXPECT_TRUE(p.targets[0].joint_motion);
  EXPECT_EQ(p.targets[0].joint_edits.at(0).text, "E6AXIS");
  EXPECT_EQ(p.targets[3].joint_edits.at(0).text, "AXIS");
  EXPECT_EQ(p.targets[0].frames_named, "");
  EXPECT_TRUE(p.targets[0].tool.isApprox(Eigen::Isometry3d::Identity()));
}

}  // namespace
}  // namespace kincal
