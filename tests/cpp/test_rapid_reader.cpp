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
