// Program files: G-code words replaced with everything else passing through, modal words, joint
// programs read back; bad input named by file, line and cause, and no output file written.
#include "kincal/compensation/program.hpp"
#include "kincal/io/programs.hpp"

#include "test_files.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <functional>

using namespace kincal;
using test::kr500_calibrated;
using test::tmp;

namespace {

bool exists(const std::string& p) { return std::ifstream(p).good(); }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const char* kGcode =
    "; tape course 1\n"
    "N10 G90 (absolute)\n"
    "N20 G1 X2000 Y-100 Z500 A180 B0 C180 F3000 ; first pose\n"
    "N30 G1 Y-95\n"
    "N40 X2005 Y-90 M7\n"
    "N50 M30\n";

}  // namespace

TEST(Io, GcodeWordsAreReplacedAndEverythingElsePassesThrough) {
  const Robot r = kr500_calibrated();
  const std::string in = tmp("p.gcode", kGcode), out = ::testing::TempDir() + "q.gcode";
  const ProgramResult res = compensate_program_file(r, in, out, ProgramOptions{});
  ASSERT_EQ(res.q_deg.size(), 3u);
  std::ifstream f(out);
  std::vector<std::string> lines;
  for (std::string l; std::getline(f, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[0], "; tape course 1");
  EXPECT_EQ(lines[1], "N10 G90 (absolute)");
  EXPECT_EQ(lines[2].rfind("N20 G1 A1=", 0), 0u) << lines[2];
  EXPECT_NE(lines[2].find(" A6="), std::string::npos);
  EXPECT_NE(lines[2].find(" F3000 ; first pose"), std::string::npos) << lines[2];
  EXPECT_EQ(lines[2].find('X'), std::string::npos);
  EXPECT_NE(lines[4].find(" M7"), std::string::npos);
  EXPECT_EQ(lines[5], "N50 M30");
  // modal words: the second pose kept X, Z, A, B, C of the first
  const PoseProgram p = read_pose_program(in);
  EXPECT_EQ(p.poses[1].xyz, Vec3(2000, -95, 500));
  EXPECT_EQ(p.poses[2].xyz, Vec3(2005, -90, 500));
  // the joint program reads back to the same angles (10 decimals)
  const JointProgram jp = read_joint_program(out, 6);
  ASSERT_EQ(jp.q.size(), 3u);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(jp.q[1][j], res.q_deg[1][j], 1e-10);
}

TEST(Io, BadInputNamesFileLineAndCauseAndWritesNothing) {
  const Robot r = kr500_calibrated();
  const std::string out = ::testing::TempDir() + "never.csv";
  std::remove(out.c_str());
  struct Case {
    const char* name;
    const char* text;
    const char* expect;
  } cases[] = {
      {"b1.gcode", "G1 X1.2.3 Y0 Z0 A0 B0 C0\n", "b1.gcode:1: broken number in word X"},
      {"b2.gcode", "G1 X2000 Y0 Z500\n", "b2.gcode:1: pose word(s) A B C not set yet"},
      {"b3.gcode", "G1 X2000 Y0 Z500 A180 B0 C180\nG1 Y-\n", "b3.gcode:2: broken number in word Y"},
      {"b4.gcode", "G1 A1=10 A2=0\n", "b4.gcode:1: joint word A1= in a pose program"},
      {"b5.csv", "x,y,z,a,b,c\n2000,0,500,180,0,180\n2000,abc,500,180,0,180\n", "b5.csv:3: column 'y': 'abc' is not a number"},
      {"b6.csv", "x,y,z,a,b,c\n2000,nan,500,180,0,180\n", "b6.csv:2: column 'y': 'nan' is not a finite number"},
      {"b7.csv", "x,y,z,a,b\n2000,0,500,180,0\n", "b7.csv:1: missing column 'c'"},
      {"b8.csv", "x,y,z,a,b,c\n2000,0,500,180,0\n", "b8.csv:2: 5 fields, the header has 6"},
      {"b9.csv", "x,y,z,a,b,c\n2000,0,500,180,0,180\n9000,0,500,180,0,180\n", "b9.csv:3: pose out of reach"},
      {"b10.csv", "", "b10.csv: empty file"},
  };
  for (const Case& c : cases) {
    const std::string in = tmp(c.name, c.text);
    const std::string e = error_of([&] { compensate_program_file(r, in, out, ProgramOptions{}); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.name << ": " << e;
    EXPECT_FALSE(exists(out)) << c.name;
  }
  EXPECT_NE(error_of([&] { read_pose_program(::testing::TempDir() + "missing.csv"); }).find("cannot open"),
            std::string::npos);
}
