// ABB RAPID programs read in: the constructs of the controller's manual (issue 30).
#include "kincal/io/native.hpp"

#include "test_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace kincal {
// the RAPID value writers (rapid_reader.cpp), as native.cpp calls them
std::string rapid_robtarget(const std::string& old, const Pose6& pose, const ControllerTarget& t);
std::string rapid_jointtarget(const std::string& old, const Vec6& q_deg);
}  // namespace kincal

namespace {

using namespace kincal;

// the task folder beside this file (tests/cpp/..): __FILE__ is the path the build compiled
const std::string kTask = std::string(__FILE__).substr(0, std::string(__FILE__).rfind("cpp/")) + "data/programs/rapid/T_ROB1/";
const std::string kRt = "[[1900,-300,700],[0.707106781,0,0.707106781,0],[0,-1,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]]";

NativeProgram read_mod(const std::string& name, const std::string& body, const Declarations& ctx = {}) {
  return read_native_program(test::tmp(name, "MODULE " + name.substr(0, name.find('.')) + "\n" + body + "ENDMODULE\n"),
                             ControllerFormat::Rapid, ctx);
}

// the text of a target's value as the file has it
std::string value_of(const NativeProgram& p, const NativeTarget& t) {
  const auto& f = p.lines[static_cast<size_t>(t.file)];
  if (t.last_line <= t.line) return f[static_cast<size_t>(t.line - 1)].substr(t.begin, t.end - t.begin);
  std::string s = f[static_cast<size_t>(t.line - 1)].substr(t.begin);
  for (int l = t.line + 1; l < t.last_line; ++l) s += "\n" + f[static_cast<size_t>(l - 1)];
  return s + "\n" + f[static_cast<size_t>(t.last_line - 1)].substr(0, t.end);
}

const NativeTarget* named(const NativeProgram& p, const std::string& n) {
  for (const auto& t : p.targets)
    if (t.name == n) return &t;
  return nullptr;
}

std::vector<std::string> task_files() {
  return {kTask + "MainModule.mod", kTask + "Welding.mod", kTask + "MultiMove.mod"};
}

}  // namespace

// --- 1. the declarations of a task's modules, as other modules see them
TEST(RapidDeclarations, EveryModulesDataButLocalOnesWithTypeValueAndRunTime) {
  const Declarations d = read_declarations({kTask + "CellData.sys", kTask + "MainModule.mod"}, ControllerFormat::Rapid);
  ASSERT_NE(d.find("tgripper"), nullptr);
  EXPECT_EQ(d.find("tGripper")->type, "TOOLDATA");
  EXPECT_EQ(d.find("wobjFixture")->type, "WOBJDATA");  // TASK PERS
  EXPECT_EQ(d.find("loadPart")->type, "LOADDATA");
  EXPECT_EQ(d.find("jHome")->type, "JOINTTARGET");
  EXPECT_EQ(d.find("pService"), nullptr);  // LOCAL: its module's only
  // a value over several lines: the declaration's line, the value's whole text
  const Declaration* place = d.find("pPlace");
  ASSERT_NE(place, nullptr);
  EXPECT_EQ(place->line, 19);
  EXPECT_EQ(place->path, kTask + "CellData.sys");
  EXPECT_NE(place->value.find("[150,80,120]"), std::string::npos);
  EXPECT_NE(place->value.find("[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]"), std::string::npos);
  EXPECT_FALSE(place->run_time);
  EXPECT_TRUE(d.find("pLast")->run_time);    // VAR
  EXPECT_TRUE(d.find("pFound")->run_time);   // written by SearchL (its SearchPoint) in MainModule
  EXPECT_TRUE(d.find("nCycle")->run_time);   // VAR, and assigned
  EXPECT_EQ(d.find("pLast")->value, "");
}

// --- 2. the modules of a task read as one, the backup's others as context
TEST(RapidTask, ModulesReadAsOneWithTheirFilesAndTheCellDataAsContext) {
  const Declarations ctx = read_declarations({kTask + "CellData.sys"}, ControllerFormat::Rapid);
  const NativeProgram p = read_native_programs(task_files(), ControllerFormat::Rapid, ctx);
  // CellData.sys joins the program once: its robtargets are written there
  ASSERT_EQ(p.paths.size(), 4u);
  EXPECT_EQ(p.paths[3], kTask + "CellData.sys");
  std::vector<int> per_file(4, 0);
  for (const auto& m : p.motions) ++per_file[static_cast<size_t>(m.file)];
  EXPECT_EQ(per_file, (std::vector<int>{13, 7, 3, 0}));  // MoveAbsJ counted, ArcC twice
  const NativeTarget* pick = named(p, "pPick");
  ASSERT_NE(pick, nullptr);
  EXPECT_EQ(pick->file, 3);
  EXPECT_EQ(value_of(p, *pick).substr(0, 15), "[[250,100,320],");
  EXPECT_EQ(named(p, "pSeamMid")->file, 1);
  EXPECT_EQ(named(p, "pSync20")->file, 2);
  // listed: Offs, RelTool, the search point pFound is written at run time (not a target)
  ASSERT_EQ(p.unresolved.size(), 2u);
  EXPECT_NE(p.unresolved[0].text.find("Offs(pFound"), std::string::npos);
  EXPECT_EQ(p.unresolved[0].why, "computed at run time");
  EXPECT_NE(p.unresolved[1].text.find("RelTool"), std::string::npos);
}

TEST(RapidTask, ATargetOfTheBackupJoinsTheProgramOnceAndANameDeclaredNowhereIsListed) {
  const Declarations ctx = read_declarations({kTask + "CellData.sys"}, ControllerFormat::Rapid);
  const NativeProgram p = read_native_program(kTask + "MainModule.mod", ControllerFormat::Rapid, ctx);
  EXPECT_EQ(p.paths.size(), 2u);
  EXPECT_EQ(named(p, "pApproach")->file, 1);
  EXPECT_EQ(named(p, "pSearchEnd")->file, 0);
  // without the cell data, the tools are declared nowhere: every motion listed with why
  const NativeProgram alone = read_native_program(kTask + "MainModule.mod", ControllerFormat::Rapid);
  EXPECT_TRUE(alone.targets.empty());
  ASSERT_FALSE(alone.unresolved.empty());
  EXPECT_EQ(alone.unresolved[0].why, "its tool 'tGripper' is declared nowhere");
  EXPECT_EQ(alone.unresolved[0].where, kTask + "MainModule.mod:27");
  const NativeProgram nowhere = read_mod("nowhere.mod", "  PROC main()\n    MoveL p9, v100, fine, tool0;\n  ENDPROC\n");
  ASSERT_EQ(nowhere.unresolved.size(), 1u);
  EXPECT_EQ(nowhere.unresolved[0].why, "declared nowhere");
  EXPECT_NE(nowhere.unresolved[0].where.find("nowhere.mod:3"), std::string::npos);
  EXPECT_EQ(nowhere.motions.size(), 1u);
}

TEST(RapidTask, LocalDeclarationsAreSeenInTheirOwnModuleOnly) {
  const std::string a = test::tmp("loc_a.mod", "MODULE loc_a\n  LOCAL CONST robtarget pL:=" + kRt + ";\n  PROC pa()\n"
                                   "    MoveL pL, v100, fine, tool0;\n  ENDPROC\nENDMODULE\n");
  const std::string b = test::tmp("loc_b.mod", "MODULE loc_b\n  PROC pb()\n    MoveL pL, v100, fine, tool0;\n  ENDPROC\nENDMODULE\n");
  const NativeProgram p = read_native_programs({a, b}, ControllerFormat::Rapid);
  ASSERT_EQ(p.targets.size(), 1u);
  ASSERT_EQ(p.unresolved.size(), 1u);
  EXPECT_NE(p.unresolved[0].where.find("loc_b.mod:3"), std::string::npos);
  EXPECT_EQ(p.unresolved[0].why, "declared nowhere");
}

// --- 3. statements and values over several lines
TEST(RapidMultiLine, ARobtargetDeclaredOverSeveralLinesIsReadWithItsValueSpan) {
  // (the bug: "a robtarget declaration over several lines" was refused)
  const Declarations ctx = read_declarations({kTask + "CellData.sys"}, ControllerFormat::Rapid);
  const NativeProgram p = read_native_program(kTask + "MainModule.mod", ControllerFormat::Rapid, ctx);
  const NativeTarget* place = named(p, "pPlace");
  ASSERT_NE(place, nullptr);
  EXPECT_EQ(place->line, 19);       // the value's first line ...
  EXPECT_EQ(place->last_line, 22);  // ... and its last, begin and end in them
  EXPECT_EQ(value_of(p, *place).substr(0, 14), "[[150,80,120],");
  EXPECT_EQ(value_of(p, *place).substr(value_of(p, *place).size() - 7), "9E+09]]");
  EXPECT_NEAR(place->pose.xyz.x(), 150, 1e-9);
  EXPECT_EQ(place->taught->abb_conf, (std::array<int, 4>{{0, 0, -1, 0}}));
}

TEST(RapidMultiLine, AStatementOverSeveralLinesAndAnInlineTargetOverTwo) {
  const NativeProgram p = read_mod("ml.mod",
      "  CONST robtarget p1:=\n    " + kRt + ";\n  PROC main()\n    MoveL p1, v500, z10,\n"
      "          tool0;\n    MoveL [[1900,-300,600],[0.707106781,0,0.707106781,0],\n           [0,-1,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]],\n"
      "          v500, fine, tool0;\n  ENDPROC\n");
  ASSERT_EQ(p.targets.size(), 2u);
  EXPECT_EQ(p.targets[0].line, 3);  // the value on the line after ':='
  EXPECT_EQ(p.targets[0].last_line, 0);
  EXPECT_EQ(value_of(p, p.targets[0]), kRt);
  EXPECT_EQ(p.motions[0].line, 5);  // a motion's line: its statement's first
  EXPECT_EQ(p.targets[1].line, 7);
  EXPECT_EQ(p.targets[1].last_line, 8);
  EXPECT_EQ(value_of(p, p.targets[1]), "[[1900,-300,600],[0.707106781,0,0.707106781,0],\n           [0,-1,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]]");
  // a target inserted before it (--tolerance) is the statement on one line
  EXPECT_EQ(p.motions[1].indent + p.motions[1].head + "X" + p.motions[1].tail, "    MoveL X, v500, fine, tool0;");
  EXPECT_THROW(read_mod("open.mod", "  PROC main()\n    MoveL p1, v500, z10, tool0\n  ENDPROC\n"), InputError);
}

TEST(RapidMultiLine, TheWritersKeepAValuesLineBreaksAndItsExtax) {
  // native.cpp's writer hands a value over several lines to rapid_robtarget / rapid_jointtarget with its
  // '\n's: the new value keeps them (and every blank), so that the file keeps its lines
  const std::string old = "[[150,80,120],\n      [0.707106781,0,0.707106781,0],\n      [0,0,-1,0],\n      [9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]";
  ControllerTarget t;
  t.abb_conf = {{1, 0, -2, 1}};
  Pose6 pose;
  pose.xyz = Vec3(151.5, 80, 119.25);
  pose.abc = Vec3(0, 90, 0);
  const std::string now = rapid_robtarget(old, pose, t);
  EXPECT_EQ(now, "[[151.5000,80.0000,119.2500],\n      [0.707106781,0.000000000,0.707106781,0.000000000],\n      [1,0,-2,1],\n"
                 "      [9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]");
  const std::string j = rapid_jointtarget(old, Vec6(1, 2, 3, 4, 5, 6));
  EXPECT_EQ(std::count(j.begin(), j.end(), '\n'), 3);
  EXPECT_EQ(j.substr(0, 56), "[[1.000000,2.000000,3.000000,4.000000,5.000000,6.000000]");
  EXPECT_EQ(j.substr(j.size() - 38), "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]");
  // one line as before
  EXPECT_EQ(rapid_robtarget(kRt, pose, t).substr(0, 29), "[[151.5000,80.0000,119.2500],");
}

// --- 4. every motion instruction of the manual
namespace {
const std::string kData = "  PERS tooldata tool1:=[TRUE,[[0,0,200],[1,0,0,0]],[10,[0,0,50],[1,0,0,0],0,0,0]];\n"
                          "  PERS wobjdata wobj1:=[FALSE,TRUE,\"\",[[100,0,0],[1,0,0,0]],[[0,-20,0],[1,0,0,0]]];\n"
                          "  CONST robtarget p1:=" + kRt + ";\n  CONST robtarget p2:=" + kRt + ";\n"
                          "  PERS robtarget sp:=" + kRt + ";\n  VAR triggdata tr1;\n";
NativeProgram read_proc(const std::string& name, const std::string& proc) {
  return read_mod(name, kData + "  PROC main()\n" + proc + "  ENDPROC\n");
}
std::string kinds(const NativeProgram& p) {
  std::string s;
  for (const auto& m : p.motions) s += m.kind;
  return s;
}
}  // namespace

TEST(RapidInstructions, EveryMotionOfTheManualWithItsTargetsAndKind) {
  const NativeProgram p = read_proc("all.mod",
      "    MoveJ p1, v100, z10, tool1;\n"                                   // J
      "    MoveL p1, v100, z10, tool1;\n"                                   // L
      "    MoveC p1, p2, v100, z10, tool1;\n"                               // C C
      "    MoveAbsJ [[0,-90,90,0,90,0],[9E9,9E9,9E9,9E9,9E9,9E9]]\\NoEOffs, v100, fine, tool0;\n"  // J, kept
      "    MoveExtJ [[0,0,0,0,0,0],[100,9E9,9E9,9E9,9E9,9E9]], vrot50, fine;\n"                 // O, nothing
      "    MoveJDO p1, v100, z10, tool1, do1, 1;\n    MoveLDO p1, v100, z10, tool1, do1, 1;\n"
      "    MoveCDO p1, p2, v100, z10, tool1, do1, 0;\n"
      "    MoveJSync p1, v100, z10, tool1, \"proc1\";\n    MoveLSync p1, v100, z10, tool1, \"proc1\";\n"
      "    MoveCSync p1, p2, v100, z10, tool1, \"proc1\";\n"
      "    MoveLAO p1, v100, z10, tool1, ao1, 5.5;\n    MoveJGO p1, v100, z10, tool1, go1, 5;\n"
      "    TriggJ p1, v100, tr1, z10, tool1;\n    TriggL p1, v100, tr1 \\T2:=tr1, z10, tool1;\n"
      "    TriggC p1, p2, v100, tr1, z10, tool1;\n"
      "    TriggLIOs p1, v100 \\TriggData1:=tio1, z10, tool1;\n    TriggJIOs p1, v100, z10, tool1;\n"
      "    CapL p1, v100, cd1, z10, tool1;\n    CapC p1, p2, v100, cd1, z10, tool1;\n");
  EXPECT_EQ(kinds(p), "JLCCJOOOCCOOCCOOJLCCLJLCC");
  EXPECT_TRUE(p.unresolved.empty());
  for (size_t m = 0; m < p.motions.size(); ++m) EXPECT_EQ(p.motions[m].target < 0, m == 4 || m == 5) << m;
  // the targets p1 and p2 in tool1: one each (MoveC's two arguments: via p1, end p2)
  EXPECT_EQ(p.targets.size(), 2u);
  EXPECT_EQ(p.motions[2].target, 0);
  EXPECT_EQ(p.motions[3].target, 1);
  // only MoveJ becomes MoveAbsJ: p1 is used by others too, so it stays a robtarget
  EXPECT_FALSE(p.targets[0].joint_motion);
}

TEST(RapidInstructions, OnlyMoveJTargetsMayBeWrittenAsJoints) {
  const NativeProgram p = read_proc("onlyj.mod", "    MoveJ p1, v100, z10, tool1;\n    TriggJ p2, v100, tr1, z10, tool1;\n");
  ASSERT_EQ(p.targets.size(), 2u);
  EXPECT_TRUE(p.targets[0].joint_motion);
  EXPECT_FALSE(p.targets[1].joint_motion);  // TriggJ: J, but not MoveAbsJ's
  ASSERT_EQ(p.targets[0].joint_edits.size(), 2u);
  EXPECT_EQ(p.targets[0].joint_edits[0].text, "jointtarget");
  EXPECT_EQ(p.targets[0].joint_edits[1].text, "MoveAbsJ");
  EXPECT_EQ(p.targets[0].joint_edits[1].line, p.motions[0].line);
}

TEST(RapidInstructions, SearchCompensatesItsToPointAndItsSearchPointIsAnOutput) {
  const NativeProgram p = read_proc("search.mod",
      "    SearchL \\Stop, di1, sp, p1, v100, tool1;\n    SearchL \\PStop, di1 \\Flanks, sp, p1, v100, tool1 \\WObj:=wobj1;\n"
      "    SearchC \\SStop, di1, sp, p1, p2, v100, tool1;\n    SearchJ \\Sup, di1, sp, p2, v100, tool1;\n"
      "    MoveL sp, v100, fine, tool1;\n");
  EXPECT_EQ(kinds(p), "OOCCOL");
  ASSERT_EQ(p.targets.size(), 3u);  // p1 in tool1, p1 in (tool1, wobj1): a copy, p2
  EXPECT_EQ(p.targets[0].name, "p1");
  EXPECT_EQ(p.targets[1].name, "p1_1");
  EXPECT_EQ(p.targets[2].name, "p2");
  ASSERT_EQ(p.unresolved.size(), 1u);  // MoveL to the point the search wrote
  EXPECT_EQ(p.unresolved[0].why.rfind("computed at run time (assigned at ", 0), 0u) << p.unresolved[0].why;
}

TEST(RapidInstructions, ArcWeldingSeamTargetsAreCompensatedLikeMoveL) {
  const Declarations ctx = read_declarations({kTask + "CellData.sys"}, ControllerFormat::Rapid);
  const NativeProgram p = read_native_program(kTask + "Welding.mod", ControllerFormat::Rapid, ctx);
  // MoveJ, ArcLStart (a copy would strike the arc earlier: O), ArcL, ArcC via and end, ArcLEnd, TriggL;
  // TriggIO is a setting, not a motion
  EXPECT_EQ(kinds(p), "JOLCCLL");
  EXPECT_TRUE(p.unresolved.empty());
  ASSERT_EQ(p.targets.size(), 7u);
  for (const auto& t : p.targets) EXPECT_EQ(t.frames_named, "tWeldGun, wobjFixture");
  EXPECT_EQ(p.targets[3].name, "pSeamArc");
  EXPECT_EQ(p.targets[4].name, "pSeamArcEnd");
  // a target inserted before ArcLEnd continues the seam (ArcL), the end stays at the end
  EXPECT_EQ(p.motions[5].head, "ArcL ");
  EXPECT_EQ(p.motions[5].tail.find(", v10, seamFillet, weldFillet, fine, tWeldGun\\WObj:=wobjFixture\\SeamName:=\"Fillet_1\";"), 0u);
}

TEST(RapidInstructions, OptionalArgumentsAnywhere) {
  const NativeProgram p = read_proc("opt.mod",
      "    MoveL \\Conc, p1, v100 \\V:=120, z10 \\Z:=12, tool1;\n"
      "    MoveJ\\Conc, p1, v100 \\T:=3, z10 \\Inpos:=inpos20, tool1 \\WObj:=wobj1 \\TLoad:=load1;\n"
      "    MoveL p2, v100, z10, tool1\\WObj:=wobj1\\Corr;\n"
      "    ArcL\\On p2, v100, sm1, wd1, wv1, fine, tool1\\WObj:=wobj1;\n");
  EXPECT_TRUE(p.unresolved.empty());
  ASSERT_EQ(p.targets.size(), 3u);  // p1 (tool1), p1 (tool1, wobj1), p2 (tool1, wobj1)
  EXPECT_EQ(p.targets[1].frames_named, "tool1, wobj1");
  EXPECT_EQ(p.motions[3].target, 2);
  EXPECT_EQ(p.motions[0].head, "MoveL \\Conc, ");
}

TEST(RapidInstructions, MultiMoveIdAfterTheToPointIsNotARunTimeTarget) {
  // (the bug: `MoveL p2 \ID:=10, v200, z50, tool1;` was taken for a run-time target)
  const NativeProgram p = read_proc("mm.mod",
      "    SyncMoveOn sync1, tasks1;\n    MoveL p2 \\ID:=10, v200, z50, tool1;\n"
      "    MoveC p1, p2 \\ID:=20, v200, z50, tool1;\n    MoveL " + kRt + "\\ID:=30, v200, fine, tool1;\n    SyncMoveOff sync2;\n");
  EXPECT_TRUE(p.unresolved.empty());
  ASSERT_EQ(p.targets.size(), 3u);
  EXPECT_EQ(p.targets[0].name, "p2");
  EXPECT_EQ(p.motions[3].target, 2);  // the inline one
  const Declarations ctx = read_declarations({kTask + "CellData.sys"}, ControllerFormat::Rapid);
  const NativeProgram task = read_native_program(kTask + "MultiMove.mod", ControllerFormat::Rapid, ctx);
  EXPECT_EQ(task.targets.size(), 3u);
  EXPECT_TRUE(task.unresolved.empty());
}

TEST(RapidInstructions, AMotionLikeInstructionKincalDoesNotReadIsListedWithWhy) {
  const NativeProgram p = read_proc("unread.mod",
      "    ArcRepL p1, v100, sm1, wd1, fine, tool1;\n    DispL \\On, p1, v100, bead1, z10, tool1;\n    MoveLCustom p1;\n"
      "    TriggIO tr1, 10 \\DOp:=do1, 1;\n    MoveToSafe;\n    IF bRun MoveQuick p1;\n");
  // (TriggIO: a setting; MoveToSafe: a routine of a module not read, named like a motion: listed)
  ASSERT_EQ(p.unresolved.size(), 5u);
  EXPECT_EQ(p.unresolved[0].why, "an instruction kincal does not read (ArcRepL)");
  EXPECT_EQ(p.unresolved[1].why, "an instruction kincal does not read (DispL)");
  EXPECT_EQ(p.unresolved[2].why, "an instruction kincal does not read (MoveLCustom)");
  EXPECT_EQ(p.unresolved[3].why, "an instruction kincal does not read (MoveToSafe)");
  EXPECT_EQ(p.unresolved[4].why, "an instruction kincal does not read (MoveQuick)");  // in a compact IF
  // a routine of the modules read is not an instruction (its own motions are read where it is)
  const NativeProgram q = read_mod("own.mod", kData + "  PROC MoveToSafe()\n    MoveJ p1, v100, z10, tool1;\n  ENDPROC\n"
                                   "  PROC main()\n    MoveToSafe;\n  ENDPROC\n");
  EXPECT_TRUE(q.unresolved.empty());
  EXPECT_EQ(q.motions.size(), 1u);
}

// --- 5. each statement's tool and work object
TEST(RapidFrames, ToolAndWorkObjectOfEachStatement) {
  const NativeProgram p = read_proc("frames.mod",
      "    MoveL p1, v100, z10, tool1 \\WObj:=wobj1;\n    MoveL p2, v100, z10, tool0;\n");
  ASSERT_EQ(p.targets.size(), 2u);
  EXPECT_EQ(p.targets[0].frames_named, "tool1, wobj1");
  EXPECT_NEAR(p.targets[0].tool.translation().z(), 200, 1e-12);        // tframe
  EXPECT_NEAR(p.targets[0].frame.translation().x(), 100, 1e-12);       // uframe * oframe
  EXPECT_NEAR(p.targets[0].frame.translation().y(), -20, 1e-12);
  EXPECT_EQ(p.targets[1].frames_named, "");                            // tool0, wobj0
  EXPECT_TRUE(p.targets[1].tool.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(p.targets[1].frame.isApprox(Eigen::Isometry3d::Identity()));
  // from the backup's other module: the welding gun's tframe, rotated 45 deg about y
  const Declarations ctx = read_declarations({kTask + "CellData.sys"}, ControllerFormat::Rapid);
  const NativeProgram w = read_native_program(kTask + "Welding.mod", ControllerFormat::Rapid, ctx);
  EXPECT_NEAR(w.targets[0].tool.translation().z(), 385.2, 1e-12);
  EXPECT_NEAR(w.targets[0].tool.linear()(0, 2), std::sqrt(0.5), 1e-8);
  EXPECT_NEAR(w.targets[0].frame.translation().x(), 1800 + 50 * std::cos(M_PI / 6), 1e-6);
}

TEST(RapidFrames, StationaryToolsRobotHeldAndMovingWorkObjectsAreRefusedByName) {
  auto error_of = [](const std::string& name, const std::string& decl, const std::string& motion) {
    try {
      read_mod(name, kData + decl + "  PROC main()\n" + motion + "  ENDPROC\n");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string e = error_of("st.mod", "  PERS tooldata tStat:=[FALSE,[[500,0,800],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];\n",
                           "    MoveL p1, v100, z10, tStat \\WObj:=wobj1;\n");
  EXPECT_NE(e.find("st.mod:10: tool 'tStat' is a stationary tool (robhold FALSE)"), std::string::npos) << e;
  e = error_of("rh.mod", "  PERS wobjdata wHeld:=[TRUE,TRUE,\"\",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];\n",
               "    MoveL p1, v100, z10, tool1 \\WObj:=wHeld;\n");
  EXPECT_NE(e.find("rh.mod:10: work object 'wHeld' is held by the robot (robhold TRUE)"), std::string::npos) << e;
  e = error_of("mv.mod", "  PERS wobjdata wStn:=[FALSE,FALSE,\"STN1\",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];\n",
               "    MoveL p1, v100, z10, tool1 \\WObj:=wStn;\n");
  EXPECT_NE(e.find("mv.mod:10: work object 'wStn' is a moving user frame"), std::string::npos) << e;
}

TEST(RapidFrames, ATargetUsedInASecondFrameGetsACopyNamedAfterIt) {
  const NativeProgram p = read_proc("copy.mod",
      "    MoveJ p1, v100, z10, tool1;\n    MoveL p1, v100, z10, tool1 \\WObj:=wobj1;\n"
      "    MoveL p1, v100, fine, tool0;\n    MoveL p1, v100, z10, tool1\\WObj:=wobj1;\n    MoveL p1, v100, z10, tool1;\n");
  ASSERT_EQ(p.targets.size(), 3u);
  EXPECT_EQ(p.targets[0].name, "p1");  // the first frame's statements keep it
  EXPECT_EQ(p.targets[0].copy_of, -1);
  EXPECT_TRUE(p.targets[0].edits.empty());
  const NativeTarget& c1 = p.targets[1];
  EXPECT_EQ(c1.name, "p1_1");
  EXPECT_EQ(c1.copy_of, 0);
  EXPECT_EQ(c1.frames_named, "tool1, wobj1");
  EXPECT_EQ(c1.line, p.targets[0].line);  // the original's declaration: the writer adds the copy's after it
  EXPECT_EQ(c1.begin, p.targets[0].begin);
  EXPECT_FALSE(c1.joint_motion);
  ASSERT_EQ(c1.edits.size(), 2u);  // the name in each statement of its frame, renamed
  EXPECT_EQ(c1.edits[0].line, 10);
  EXPECT_EQ(p.lines[0][9].substr(c1.edits[0].begin, c1.edits[0].end - c1.edits[0].begin), "p1");
  EXPECT_EQ(c1.edits[0].text, "p1_1");
  EXPECT_EQ(c1.edits[1].line, 12);
  EXPECT_EQ(p.targets[2].name, "p1_2");
  EXPECT_EQ(p.targets[2].frames_named, "");
  EXPECT_EQ((std::vector<int>{p.motions[0].target, p.motions[1].target, p.motions[2].target, p.motions[3].target,
                              p.motions[4].target}),
            (std::vector<int>{0, 1, 2, 1, 0}));
}

TEST(RapidFrames, ACopysNameKeepsTo32CharactersAndIsUnique) {
  const std::string n = "pApproachFixtureLeftSideUpper_31";  // 32 characters
  const NativeProgram p = read_mod("long.mod", kData + "  CONST robtarget " + n + ":=" + kRt + ";\n  CONST robtarget " +
                                                   n.substr(0, 30) + "_1:=" + kRt + ";\n  PROC main()\n    MoveL " + n +
                                                   ", v100, z10, tool1;\n    MoveL " + n + ", v100, z10, tool0;\n  ENDPROC\n");
  ASSERT_EQ(p.targets.size(), 2u);
  EXPECT_EQ(p.targets[1].name, n.substr(0, 30) + "_2");  // _1 is taken
  EXPECT_EQ(p.targets[1].name.size(), 32u);
}

// --- 6. the taught branch and the external axes
TEST(RapidTaught, ConfdataIsTheTaughtBranchAndExtaxTheExternalAxes) {
  const NativeProgram p = read_proc("conf.mod",
      "    MoveL [[1900,-300,700],[0.707106781,0,0.707106781,0],[-1,2,-3,5],[1250.5,9E+09,9E9,-20,9E9,9E9]], v100, z10, tool1;\n");
  ASSERT_EQ(p.targets.size(), 1u);
  ASSERT_TRUE(p.targets[0].taught.has_value());
  EXPECT_EQ(p.targets[0].taught->abb_conf, (std::array<int, 4>{{-1, 2, -3, 5}}));
  EXPECT_EQ(p.targets[0].external[0], 1250.5);
  EXPECT_TRUE(std::isnan(p.targets[0].external[1]));
  EXPECT_EQ(p.targets[0].external[3], -20);
  EXPECT_TRUE(std::isnan(p.targets[0].external[5]));
}

// --- 7. what was kept: MODULE checks, run-time targets, malformed values
TEST(RapidKept, ModuleChecksRunTimeTargetsAndMalformedValues) {
  auto throws = [](const std::string& text, const std::string& message) {
    try {
      read_native_program(test::tmp("bad.mod", text), ControllerFormat::Rapid);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "no error: " << message;
  };
  throws("MODULE a\n  PROC main()\n  ENDPROC\n", "bad.mod:1: MODULE is not closed by ENDMODULE");
  throws("ENDMODULE\n", "bad.mod:1: ENDMODULE without MODULE");
  throws("  VAR num n;\n", "no MODULE in the file");
  throws("MODULE a\n  CONST robtarget p1:=[[1,2,3],[1,0,0,0]];\n  PROC main()\n    MoveL p1, v1, z1, tool0;\n  ENDPROC\nENDMODULE\n",
         "bad.mod:2: a robtarget has 4 parts");
  throws("MODULE a\n  CONST jointtarget j1:=[[0,0,0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n  PROC main()\n    MoveL j1, v1, z1, tool0;\n"
         "  ENDPROC\nENDMODULE\n", "bad.mod:4: target 'j1' is not declared as a robtarget");
  const NativeProgram p = read_proc("rt.mod",
      "    MoveL Offs(p1,0,0,50), v100, z10, tool1;\n    MoveL RelTool(p1,0,0,-20), v100, z10, tool1;\n"
      "    MoveL CRobT(\\Tool:=tool1), v100, z10, tool1;\n    p2.trans.z := 650;\n    MoveL p2, v100, z10, tool1;\n"
      "    MoveL pts{2}, v100, z10, tool1;\n");
  ASSERT_EQ(p.unresolved.size(), 5u);
  EXPECT_EQ(p.unresolved[0].why, "computed at run time");
  EXPECT_EQ(p.unresolved[3].why.rfind("computed at run time (assigned at ", 0), 0u);
  EXPECT_EQ(p.unresolved[4].why, "computed at run time (an array element)");
  EXPECT_TRUE(p.targets.empty());
  EXPECT_EQ(p.motions.size(), 5u);
}

// native.cpp's writer hands a RAPID value over several lines to rapid_robtarget / rapid_jointtarget.
TEST(RapidMultiLine, ValuesOverSeveralLinesAreWrittenBackInTheirLines) {
  const NativeProgram p = read_mod("wml.mod", "  CONST robtarget p1:=[[1900,-300,700],\n      [0.707106781,0,0.707106781,0],\n"
                                               "      [0,-1,-1,0],\n      [9E9,9E9,9E9,9E9,9E9,9E9]];\n  PROC main()\n"
                                               "    MoveL p1, v100, fine, tool0;\n  ENDPROC\n");
  ASSERT_EQ(p.targets.size(), 1u);
  Pose6 pose = p.targets[0].pose;
  pose.xyz.x() += 1;
  const auto out = write_native_program(p, {pose}, {ControllerTarget{}}, {false}, {::testing::TempDir() + "wml_out.mod"});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NE(out[0].text.find("p1:=[[1901.0000,-300.0000,700.0000],\n      [0.707106781,"), std::string::npos) << out[0].text;
  EXPECT_NE(out[0].text.find("\n      [0,0,0,0],\n      [9E9,9E9,9E9,9E9,9E9,9E9]];\n"), std::string::npos) << out[0].text;
}
