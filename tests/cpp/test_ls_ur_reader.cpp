// FANUC LS and URScript programs read in: the constructs of the controller's manual (issue 30).
#include "kincal/io/native.hpp"

#include "test_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace kincal {
namespace {

const ControllerFormat kLs = ControllerFormat::FanucLs, kUr = ControllerFormat::UrScript;

std::string data(const std::string& name) {
  const std::string here = __FILE__;
  return here.substr(0, here.rfind('/')) + "/../data/programs/" + name;
}

// the error message of reading path, "" when it reads
std::string error_of(const std::string& path, ControllerFormat f) {
  try {
    read_native_program(path, f);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const UnresolvedTarget* unresolved_at(const NativeProgram& p, const std::string& where) {
  for (const auto& u : p.unresolved)
    if (u.where == where) return &u;
  return nullptr;
}

const NativeTarget* target_named(const NativeProgram& p, const std::string& name) {
  for (const auto& t : p.targets)
    if (t.name == name) return &t;
  return nullptr;
}

// a small LS program: the /MN lines and the /POS entries given
std::string ls(const std::string& mn, const std::string& pos) {
  return "/PROG  T\n/ATTR\nLINE_COUNT\t= 3;\nDEFAULT_GROUP\t= 1,*,*,*,*;\n/APPL\n/MN\n" + mn + "/POS\n" + pos + "/END\n";
}
std::string ls_pos(int n, const std::string& config = "N U T, 0, 0, 0", const std::string& extra = "") {
  return "P[" + std::to_string(n) + "]{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : '" + config +
         "',\n\tX =  2000.000  mm,\tY =  -300.000  mm,\tZ =   800.000  mm,\n"
         "\tW =   180.000 deg,\tP =     0.000 deg,\tR =   180.000 deg" + extra + "\n};\n";
}

// ---------------------------------------------------------------------------------------------- FANUC LS

// The production program: every motion statement of deburr.ls read, in order, with its kind; the
// Cartesian positions used by plain motions are targets with their UF/UT; the C arc's end point comes
// from its continuation line; the A arc's three points are arcs; the commented-out '//' motion is not
// a motion.
TEST(LsReader, ProductionProgramMotionsKindsAndFrames) {
  const NativeProgram p = read_native_program(data("ls/deburr.ls"), kLs);
  std::string kinds;
  for (const auto& m : p.motions) kinds += m.kind;
  // J J L L C C(end) C C C(A arcs) L J(Wjnt) L L L L L J
  EXPECT_EQ(kinds, "JJLLCCCCCLJLLLLLJ");
  ASSERT_EQ(p.motions.size(), 17u);
  EXPECT_EQ(p.motions[4].line, 31);  // C P[5] on its line, its end P[6] on the continuation line
  EXPECT_EQ(p.motions[5].line, 32);
  std::vector<std::string> names;
  for (const auto& t : p.targets) names.push_back(t.name);
  EXPECT_EQ(names, (std::vector<std::string>{"P[2]", "P[3]", "P[4]", "P[5]", "P[6]", "P[7]", "P[8]", "P[9]",
                                             "P[10]", "P[13]"}));
  const NativeTarget* b3 = target_named(p, "P[13]");
  ASSERT_TRUE(b3);
  EXPECT_EQ(b3->uframe, 2);
  EXPECT_EQ(b3->utool, 2);
  EXPECT_EQ(b3->frames_named, "UF 2, UT 2");
  EXPECT_EQ(target_named(p, "P[2]")->uframe, 1);
  EXPECT_NEAR(b3->pose.xyz[0], 400.0, 1e-9);
  EXPECT_NEAR(b3->pose.abc[0], 90.0, 1e-9);   // A = R
  EXPECT_NEAR(b3->pose.abc[2], 180.0, 1e-9);  // C = W
  // P[6]: the C's end point and the first A point: one target, two motions
  int uses = 0;
  for (const auto& m : p.motions) uses += m.target == p.motions[5].target;
  EXPECT_EQ(uses, 2);
  EXPECT_FALSE(target_named(p, "P[2]")->joint_motion == false);  // J motions only
  EXPECT_FALSE(target_named(p, "P[3]")->joint_motion);
}

// A statement continued over a ':' line: the motion's options on the next line (TA ... on the L to P[9]);
// a motion inserted before it (--tolerance) copies its continuation line too.
TEST(LsReader, ContinuationLineOfAStatement) {
  const NativeProgram p = read_native_program(data("ls/deburr.ls"), kLs);
  const NativeMotion& m = p.motions[9];  // L P[9:leave A] ... Skip,LBL[90] / : TA ...
  EXPECT_EQ(m.kind, 'L');
  EXPECT_EQ(m.line, 36);
  EXPECT_EQ(p.targets[static_cast<size_t>(m.target)].name, "P[9]");
  EXPECT_NE(m.tail.find("\n    :  TA   0.00sec,DO[12:spindle]=OFF    ;"), std::string::npos) << m.tail;
  // an unfinished motion at the end of /MN
  const std::string bad = test::tmp("open.ls", ls("   1:L P[1] 100mm/sec CNT100    \n    :  TB .1sec,DO[1]=ON\n", ls_pos(1)));
  EXPECT_NE(error_of(bad, kLs).find("open.ls:7: the motion does not end with ';'"), std::string::npos);
}

// Offset,PR[i], Tool_Offset,PR[i], INC, a PR[i] target: unresolved, each with its why (the register
// comments dropped); P[11] used by offset motions only is no target.
TEST(LsReader, RunTimeTargetsUnresolvedWithWhy) {
  const NativeProgram p = read_native_program(data("ls/deburr.ls"), kLs);
  ASSERT_EQ(p.unresolved.size(), 4u);
  const std::string f = data("ls/deburr.ls");
  const auto* off = unresolved_at(p, f + ":42");
  ASSERT_TRUE(off);
  EXPECT_EQ(off->why, "Offset,PR[5]: the target depends on a register at run time");
  EXPECT_EQ(off->text, "L P[11:edge B1] 300mm/sec CNT30 Offset,PR[5:fixture shift]    ;");
  EXPECT_EQ(unresolved_at(p, f + ":43")->why, "Tool_Offset,PR[6]: the target depends on a register at run time");
  EXPECT_EQ(unresolved_at(p, f + ":44")->why.substr(0, 4), "INC:");
  EXPECT_EQ(unresolved_at(p, f + ":45")->why, "PR[20]: a position register, known at run time");
  EXPECT_EQ(target_named(p, "P[11]"), nullptr);
  EXPECT_EQ(target_named(p, "P[12]"), nullptr);
}

// Offset and Tool_Offset without a register (OFFSET CONDITION), VOFFSET,VR[i], an indirect P[R[i]]; an
// "Offset" in a register's comment is not the option.
TEST(LsReader, OffsetConditionVisionAndIndirect) {
  const std::string path = test::tmp("offs.ls", ls("   1:  OFFSET CONDITION PR[1] ;\n"
                                                   "   2:L P[1] 100mm/sec FINE Offset    ;\n"
                                                   "   3:L P[1] 100mm/sec FINE Tool_Offset    ;\n"
                                                   "   4:L P[1] 100mm/sec FINE VOFFSET,VR[2]    ;\n"
                                                   "   5:J P[R[4:index]] 50% FINE    ;\n"
                                                   "   6:L P[1] 100mm/sec FINE DO[1:Offset done]=ON    ;\n",
                                                   ls_pos(1)));
  const NativeProgram p = read_native_program(path, kLs);
  ASSERT_EQ(p.unresolved.size(), 4u);
  EXPECT_NE(p.unresolved[0].why.find("Offset: the target is shifted by the register of OFFSET CONDITION"), std::string::npos);
  EXPECT_NE(p.unresolved[1].why.find("Tool_Offset: the target is shifted by the register of TOOL_OFFSET CONDITION"),
            std::string::npos);
  EXPECT_EQ(p.unresolved[2].why, "VOFFSET,VR[2]: a vision offset measured at run time");
  EXPECT_EQ(p.unresolved[3].why, "P[R[4]]: an indirect position, chosen at run time");
  ASSERT_EQ(p.targets.size(), 1u);  // the motion of line 6
  EXPECT_EQ(p.motions[4].target, 0);
}

// COORD (coordinated with a positioner) and RTCP (remote TCP) are refused at the motion, by name.
TEST(LsReader, CoordAndRtcpRefusedByName) {
  const std::string coord = test::tmp("coord.ls", ls("   1:J P[1] 50% FINE    ;\n   2:L P[1] 50mm/sec CNT100 COORD    ;\n", ls_pos(1)));
  EXPECT_NE(error_of(coord, kLs).find("coord.ls:8: COORD (a motion coordinated with a positioner"), std::string::npos)
      << error_of(coord, kLs);
  const std::string rtcp = test::tmp("rtcp.ls", ls("   1:L P[1] 50mm/sec FINE RTCP    ;\n", ls_pos(1)));
  EXPECT_NE(error_of(rtcp, kLs).find("rtcp.ls:7: RTCP (remote TCP"), std::string::npos) << error_of(rtcp, kLs);
  // a C arc with COORD on its continuation line: refused at the C
  const std::string arc = test::tmp("arc_coord.ls", ls("   1:C P[1]    \n    :  P[2] 50mm/sec FINE COORD    ;\n",
                                                       ls_pos(1) + ls_pos(2)));
  EXPECT_NE(error_of(arc, kLs).find("arc_coord.ls:7: COORD"), std::string::npos) << error_of(arc, kLs);
}

// C without its end point on the next line, and a motion without a position: refused with file:line.
TEST(LsReader, MalformedCircularMotion) {
  const std::string c = test::tmp("c.ls", ls("   1:C P[1] 100mm/sec FINE    ;\n", ls_pos(1)));
  EXPECT_NE(error_of(c, kLs).find("c.ls:7: C: the arc's end point"), std::string::npos) << error_of(c, kLs);
  const std::string c2 = test::tmp("c2.ls", ls("   1:C P[1]    \n    :  LPOS 100mm/sec FINE    ;\n", ls_pos(1)));
  EXPECT_NE(error_of(c2, kLs).find("c2.ls:8: C: the arc's end point is not"), std::string::npos) << error_of(c2, kLs);
}

// CONFIG kept as the taught branch, in set_branch_data's form ("F U T, 0, 0, 0"): the turn numbers of
// calib.ls, and other spellings normalised; a CONFIG that is not a six-axis arm's is refused by name.
TEST(LsReader, TaughtConfigWithTurns) {
  const NativeProgram p = read_native_program(data("ls/calib.ls"), kLs);
  ASSERT_EQ(p.targets.size(), 5u);
  const char* want[] = {"N U T, 0, 1, 0", "N U T, 0, 0, -1", "F U T, 0, 0, -1", "N U T, 0, 1, 0", "F U T, 0, 0, 1"};
  for (size_t k = 0; k < 5; ++k) {
    ASSERT_TRUE(p.targets[k].taught.has_value());
    EXPECT_EQ(p.targets[k].taught->fanuc_config, want[k]);
  }
  const std::string odd = test::tmp("cfg.ls", ls("   1:J P[1] 50% FINE    ;\n   2:J P[2] 50% FINE    ;\n",
                                                 ls_pos(1, "NDB,-1,0,1") + ls_pos(2, " F U T , 0 , +1 , 0 ")));
  const NativeProgram q = read_native_program(odd, kLs);
  EXPECT_EQ(q.targets[0].taught->fanuc_config, "N D B, -1, 0, 1");
  EXPECT_EQ(q.targets[1].taught->fanuc_config, "F U T, 0, 1, 0");
  const std::string scara = test::tmp("scara.ls", ls("   1:J P[1] 50% FINE    ;\n", ls_pos(1, "N, 0, 0, 0")));
  EXPECT_NE(error_of(scara, kLs).find("scara.ls:11: P[1] CONFIG 'N, 0, 0, 0' is not a six-axis arm's configuration"),
            std::string::npos)
      << error_of(scara, kLs);
}

// E1..E3 of GP1 are the target's external axes (a track), NaN beyond; the other fields still read.
TEST(LsReader, ExternalAxes) {
  const NativeProgram p = read_native_program(data("ls/calib.ls"), kLs);
  EXPECT_EQ(p.targets[0].external[0], 0.0);
  EXPECT_TRUE(std::isnan(p.targets[0].external[1]));
  const std::string path = test::tmp("e.ls", ls("   1:L P[1] 50mm/sec FINE    ;\n",
                                                ls_pos(1, "N U T, 0, 0, 0", ",\n\tE1=   750.500  mm,\tE2=   -12.000 deg")));
  const NativeProgram q = read_native_program(path, kLs);
  EXPECT_EQ(q.targets[0].external[0], 750.5);
  EXPECT_EQ(q.targets[0].external[1], -12.0);
  EXPECT_TRUE(std::isnan(q.targets[0].external[2]));
  EXPECT_NEAR(q.targets[0].pose.xyz[2], 800.0, 1e-12);
}

// A position with GP1 and GP2 (a positioner's joints): GP1 is the robot's target, its span stops before
// GP2 (GP2 is written back as it is); a position of GP2 only is not the robot's: its motion has no target.
TEST(LsReader, PositionerGroupKeptAsWritten) {
  const std::string gp2 = "P[2]{\n   GP2:\n\tUF : 1, UT : 2,\n\tJ1=    90.000 deg,\tJ2=     0.000 deg\n};\n";
  std::string both = ls_pos(1);
  both.insert(both.rfind("};"), "   GP2:\n\tUF : 1, UT : 2,\n\tJ1=    45.000 deg,\tJ2=     0.000 deg\n");
  const std::string path = test::tmp("gp2.ls", ls("   1:L P[1] 50mm/sec FINE    ;\n   2:J P[2] 50% FINE    ;\n", both + gp2));
  const NativeProgram p = read_native_program(path, kLs);
  ASSERT_EQ(p.targets.size(), 1u);
  EXPECT_EQ(p.targets[0].line, 12);
  EXPECT_EQ(p.targets[0].last_line, 14);
  ASSERT_EQ(p.motions.size(), 2u);
  EXPECT_EQ(p.motions[1].target, -1);
  EXPECT_TRUE(p.unresolved.empty());
}

// A position recorded but never taught (UF : F, X = ********): its motions unresolved, naming it.
TEST(LsReader, UntaughtPositionUnresolved) {
  const std::string untaught = "P[1]{\n   GP1:\n\tUF : F, UT : F,\t\tCONFIG : 'N D B, 0, 0, 0',\n"
                               "\tX = ********  mm,\tY = ********  mm,\tZ = ********  mm,\n"
                               "\tW = ******** deg,\tP = ******** deg,\tR = ******** deg\n};\n";
  const std::string path = test::tmp("untaught.ls", ls("   1:J P[1] 20% CNT100    ;\n   2:L P[2] 50mm/sec FINE    ;\n",
                                                       untaught + ls_pos(2)));
  const NativeProgram p = read_native_program(path, kLs);
  ASSERT_EQ(p.unresolved.size(), 1u);
  EXPECT_EQ(p.unresolved[0].where, path + ":7");
  EXPECT_EQ(p.unresolved[0].why, "P[1] is not taught (its values are ********)");
  ASSERT_EQ(p.targets.size(), 1u);
  EXPECT_EQ(p.targets[0].name, "P[2]");
}

// Unnumbered statements (" : J P[1] ...") as some printouts write them; comments '!' and '//' lines are no
// statements, and a '//' motion does not make its position "named elsewhere" (P[1] stays a joint target).
TEST(LsReader, UnnumberedStatementsAndComments) {
  const std::string path = test::tmp("unnum.ls", ls(" : UTOOL_NUM=1 ;\n : !approach ;\n : J P[1:a] 15% FINE ;\n"
                                                    " : //L P[1] 100mm/sec FINE ;\n : L P[2:b] 50mm/sec FINE ;\n",
                                                    ls_pos(1) + ls_pos(2)));
  const NativeProgram p = read_native_program(path, kLs);
  ASSERT_EQ(p.motions.size(), 2u);
  EXPECT_EQ(p.motions[0].kind, 'J');
  EXPECT_EQ(p.motions[0].line, 9);
  EXPECT_EQ(p.motions[1].line, 11);
  EXPECT_TRUE(p.targets[0].joint_motion);
  EXPECT_FALSE(p.targets[1].joint_motion);
}

// Wjnt on a linear motion: its target compensated, the motion not followed as a line ('O').
TEST(LsReader, WristJointMotion) {
  const std::string path = test::tmp("wjnt.ls", ls("   1:L P[1] 100mm/sec FINE Wjnt    ;\n   2:L P[1] 100mm/sec FINE ACC50 PTH    ;\n",
                                                   ls_pos(1)));
  const NativeProgram p = read_native_program(path, kLs);
  ASSERT_EQ(p.motions.size(), 2u);
  EXPECT_EQ(p.motions[0].kind, 'O');
  EXPECT_EQ(p.motions[1].kind, 'L');
  EXPECT_EQ(p.motions[0].target, 0);
}

// tape.ls as before: its two run-time motions (PR[2], Offset,PR[3]) now with their why.
TEST(LsReader, TapeKeepsItsTargets) {
  const NativeProgram p = read_native_program(data("tape.ls"), kLs);
  EXPECT_EQ(p.targets.size(), 4u);
  ASSERT_EQ(p.unresolved.size(), 2u);
  EXPECT_EQ(p.unresolved[0].why, "PR[2]: a position register, known at run time");
  EXPECT_EQ(p.unresolved[1].why, "Offset,PR[3]: the target depends on a register at run time");
  EXPECT_TRUE(target_named(p, "P[2]")->joint_motion);
}

// ---------------------------------------------------------------------------------------------- URScript

// The pick-and-place: movej to a joint list (no target), to pose variables and to a pose literal (Cartesian
// targets in joint interpolation), movel, movep ('O'), movec's via and end point ('C'), speedl and servoj
// (motions without a target), in the order of the file.
TEST(UrReader, PickAndPlaceMotions) {
  const NativeProgram p = read_native_program(data("urscript/pick_place.script"), kUr);
  std::string kinds;
  for (const auto& m : p.motions) kinds += m.kind;
  // approach_and_leave: L L; main: J J L L O C C L L J O O J
  EXPECT_EQ(kinds, "LLJJLLOCCLLJOOJ");
  std::vector<std::string> names;
  for (const auto& t : p.targets) names.push_back(t.name);
  EXPECT_EQ(names, (std::vector<std::string>{"above_pick", "pick", "via", "above_place", "place", ""}));
  EXPECT_NEAR(p.targets[0].pose.xyz[0], 1850.0, 1e-9);
  EXPECT_NEAR(p.targets[5].pose.xyz[2], 1200.0, 1e-9);
  EXPECT_TRUE(p.targets[5].joint_motion);    // movej(p[...]): a pose reached in joints
  EXPECT_FALSE(p.targets[0].joint_motion);   // above_pick: movej and movep
  EXPECT_FALSE(p.targets[4].joint_motion);   // place: passed to a function
  EXPECT_EQ(p.motions[2].target, -1);        // movej(home_q): joints kept
}

// Run-time targets of the pick-and-place with their why: pose_trans, a function's parameter, a pose literal
// with a computed value, pose_add of get_actual_tcp_pose(), servoj to get_inverse_kin(..).
TEST(UrReader, RunTimeTargetsUnresolvedWithWhy) {
  const NativeProgram p = read_native_program(data("urscript/pick_place.script"), kUr);
  const std::string f = data("urscript/pick_place.script");
  ASSERT_EQ(p.unresolved.size(), 5u);
  EXPECT_EQ(unresolved_at(p, f + ":20")->why, "pose_trans(..): computed at run time");
  EXPECT_EQ(unresolved_at(p, f + ":21")->why, "'target': a parameter of approach_and_leave(), known at run time");
  EXPECT_NE(unresolved_at(p, f + ":39")->why.find("a pose with a value computed at run time"), std::string::npos);
  EXPECT_EQ(unresolved_at(p, f + ":45")->why, "pose_add(..): computed at run time");
  EXPECT_EQ(unresolved_at(p, f + ":50")->why, "get_inverse_kin(..): joints computed from a pose at run time");
  EXPECT_EQ(unresolved_at(p, f + ":50")->text.substr(0, 7), "servoj(");
}

// Variables: assigned twice, or assigned a run-time value once; get_actual_tcp_pose() as the target; servoj to
// a variable computed by get_inverse_kin; servoj and speedj to joints: named, nothing to compensate.
TEST(UrReader, VariablesAndServo) {
  const std::string path = test::tmp("vars.script", "def vars():\n"
                                                    "  a = p[2.0, 0.0, 1.0, 0, 3.14159, 0]\n"
                                                    "  a = p[2.0, 0.1, 1.0, 0, 3.14159, 0]\n"
                                                    "  b = pose_trans(a, p[0, 0, 0.1, 0, 0, 0])\n"
                                                    "  q = get_inverse_kin(a)\n"
                                                    "  movel(a)\n"
                                                    "  movel(b)\n"
                                                    "  movel(get_actual_tcp_pose())\n"
                                                    "  servoj(q, t=0.008)\n"
                                                    "  servoj([0, -1.57, 1.57, 0, 1.57, 0], t=0.008)\n"
                                                    "  speedj([0.1, 0, 0, 0, 0, 0], 0.5, 1.0)\n"
                                                    "  servoc(p[2.0, 0.2, 1.0, 0, 3.14159, 0], a=1.2, v=0.25, r=0)\n"
                                                    "end\n");
  const NativeProgram p = read_native_program(path, kUr);
  ASSERT_EQ(p.unresolved.size(), 4u);
  EXPECT_EQ(p.unresolved[0].why, "'a' is assigned 2 times: its value at this motion is known at run time");
  EXPECT_EQ(p.unresolved[1].why, "'b' is assigned pose_trans(..): computed at run time");
  EXPECT_EQ(p.unresolved[2].why, "get_actual_tcp_pose(): where the robot is at run time");
  EXPECT_EQ(p.unresolved[3].where, path + ":9");
  EXPECT_EQ(p.unresolved[3].why, "'q' is assigned get_inverse_kin(..): joints computed from a pose at run time");
  ASSERT_EQ(p.motions.size(), 7u);
  EXPECT_EQ(p.motions[4].target, -1);  // servoj to joints
  EXPECT_EQ(p.motions[5].target, -1);  // speedj
  ASSERT_EQ(p.targets.size(), 1u);     // servoc's pose
  EXPECT_EQ(p.motions[6].kind, 'O');
  EXPECT_EQ(p.motions[6].target, 0);
  EXPECT_NEAR(p.targets[0].pose.xyz[1], 200.0, 1e-9);
}

// movec with one argument, an unbalanced call, a malformed number, an unassigned name: refused with file:line.
TEST(UrReader, MalformedMotionsRefused) {
  const auto err = [](const std::string& name, const std::string& body) {
    return error_of(test::tmp(name, "def t():\n" + body + "end\n"), ControllerFormat::UrScript);
  };
  EXPECT_NE(err("m1.script", "  movec(p[2, 0, 1, 0, 3.14, 0])\n").find("m1.script:2: movec needs its targets (via and end point)"),
            std::string::npos);
  EXPECT_NE(err("m2.script", "  movel(p[2, 0, 1, 0, 3.14, 0]\n").find("m2.script:2: unbalanced parentheses"), std::string::npos);
  EXPECT_NE(err("m3.script", "  movel(p[2, 0, 1x, 0, 3.14, 0])\n").find("m3.script:2: pose value '1x' is not a number"),
            std::string::npos);
  EXPECT_NE(err("m4.script", "  movel(nowhere)\n").find("m4.script:2: target 'nowhere' is not assigned"), std::string::npos);
  EXPECT_NE(err("m5.script", "  while True:\n    movel(p[2, 0, 1, 0, 3.14, 0])\n").find("m5.script:1: 'def' is not closed by 'end'"),
            std::string::npos);
}

// tape.script as before: pose_trans is its one run-time target, now with its why.
TEST(UrReader, TapeKeepsItsTargets) {
  const NativeProgram p = read_native_program(data("tape.script"), kUr);
  EXPECT_EQ(p.targets.size(), 4u);
  ASSERT_EQ(p.unresolved.size(), 1u);
  EXPECT_EQ(p.unresolved[0].why, "pose_trans(..): computed at run time");
}

}  // namespace
}  // namespace kincal
