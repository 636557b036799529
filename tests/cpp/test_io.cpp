#include "kincal/compensation/program.hpp"
#include "kincal/model/robots.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <functional>
#include <cstdio>
#include <fstream>
#include <new>
#include <sstream>

using namespace kincal;

// Counts heap allocations (for every test of this program), to show real-time loops make none.
std::atomic<long> g_allocs{0};
void* operator new(std::size_t n) {
  ++g_allocs;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

Robot kr500_calibrated() {
  auto nom = std::make_shared<Model>(kr500_spec());
  return Robot{nom, std::make_shared<Model>(perturbed_spec(kr500_spec(), 9, 1.0, 0.05, 0.003))};
}

std::string tmp(const std::string& name, const std::string& text) {
  const std::string p = ::testing::TempDir() + name;
  std::ofstream(p) << text;
  return p;
}

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

TEST(Io, StreamEqualsFileAndAllocatesNothingPerLine) {
  const Robot r = kr500_calibrated();
  // a 200-pose G-code program with pass-through words
  std::ostringstream prog;
  prog << "; streamed\n";
  for (int i = 0; i < 200; ++i)
    prog << "N" << 10 * (i + 1) << " G1 X" << 1900 + i << " Y" << -500 + 5 * i << " Z600 A180 B0 C180 F2000\n";
  const std::string in = tmp("s.gcode", prog.str()), out = ::testing::TempDir() + "s_out.gcode";
  compensate_program_file(r, in, out, ProgramOptions{});
  std::ifstream fo(out);
  std::vector<std::string> expected;
  for (std::string l; std::getline(fo, l);) expected.push_back(l);

  StreamCompensator sc(r, ProgramOptions{});
  std::istringstream lines(prog.str());
  std::vector<std::string> inl;
  for (std::string l; std::getline(lines, l);) inl.push_back(l);
  char buf[8192];
  // warm up with the first line, then count allocations over the rest
  size_t n = sc.process(inl[0].data(), inl[0].size(), buf, sizeof buf);
  ASSERT_EQ(std::string(buf, n), expected[0]);
  std::vector<size_t> lens(inl.size());
  std::vector<std::string> got(inl.size());
  for (auto& g : got) g.reserve(512);
  const long before = g_allocs.load();
  for (size_t i = 1; i < inl.size(); ++i) {
    n = sc.process(inl[i].data(), inl[i].size(), buf, sizeof buf);
    got[i].assign(buf, n);  // within the reserved capacity: no allocation
  }
  const long allocs = g_allocs.load() - before;
  EXPECT_EQ(allocs, 0);
  for (size_t i = 1; i < inl.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "line " << i + 1;

  // CSV stream: header, then one joint line per pose, identical to the CSV file output
  const std::string cin = tmp("s.csv", "x,y,z,a,b,c\n2000,-100,500,180,0,180\n2000,-95,500,180,0,180\n");
  const std::string cout = ::testing::TempDir() + "s_out.csv";
  compensate_program_file(r, cin, cout, ProgramOptions{});
  std::ifstream fc(cout);
  StreamCompensator sc2(r, ProgramOptions{});
  std::istringstream cl("x,y,z,a,b,c\n2000,-100,500,180,0,180\n2000,-95,500,180,0,180\n");
  for (std::string l, e; std::getline(cl, l) && std::getline(fc, e);) {
    n = sc2.process(l.data(), l.size(), buf, sizeof buf);
    EXPECT_EQ(std::string(buf, n), e);
  }
}

// The stream with every effect (compliance, transmission error, backlash with the directions of the
// commanded motion, thermal expansion at --temperature) on a back-and-forth G-code program: equal to
// the file given the same first directions, and still no allocation per line.
TEST(Io, StreamWithEveryEffectAllocatesNothingPerLine) {
  ModelSpec s = perturbed_spec(kr500_spec(), 8, 1.0, 0.05, 0.003);
  s.effects.push_back({Effect{"transmission_error", 1, {1, 2}}, {3e-4, -2e-4, 1e-4, 0.0}});
  s.effects.push_back({Effect{"backlash", 0, {}}, {-2e-4}});
  s.effects.push_back({Effect{"backlash", 2, {}}, {-3e-4}});
  s.effects.push_back({Effect{"thermal_expansion", -1, {}}, {1.2e-5}});
  auto nom = std::make_shared<Model>(kr500_spec());
  const Robot r{nom, std::make_shared<Model>(s)};
  std::ostringstream prog;
  for (int i = 0; i < 200; ++i) {
    const int k = i < 100 ? i : 199 - i;  // out and back
    prog << "N" << 10 * (i + 1) << " G1 X" << 1900 + 2 * k << " Y" << -500 + 5 * k << " Z" << 600 + k
         << " A180 B0 C180\n";
  }
  ProgramOptions opt;
  opt.temperature_c = 26.0;
  const std::string in = tmp("e.gcode", prog.str()), out = ::testing::TempDir() + "e_out.gcode";
  const ProgramResult res = compensate_program_file(r, in, out, opt);
  std::ifstream fo(out);
  std::vector<std::string> expected;
  for (std::string l; std::getline(fo, l);) expected.push_back(l);
  ProgramOptions so = opt;
  so.initial_direction.assign(res.dir[0].data(), res.dir[0].data() + 6);
  StreamCompensator sc(r, so);
  std::istringstream lines(prog.str());
  std::vector<std::string> inl;
  for (std::string l; std::getline(lines, l);) inl.push_back(l);
  char buf[8192];
  size_t n = sc.process(inl[0].data(), inl[0].size(), buf, sizeof buf);
  ASSERT_EQ(std::string(buf, n), expected[0]);
  std::vector<std::string> got(inl.size());
  for (auto& g : got) g.reserve(512);
  const long before = g_allocs.load();
  for (size_t i = 1; i < inl.size(); ++i) {
    n = sc.process(inl[i].data(), inl[i].size(), buf, sizeof buf);
    got[i].assign(buf, n);
  }
  EXPECT_EQ(g_allocs.load() - before, 0);
  for (size_t i = 1; i < inl.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "line " << i + 1;
  int turns = 0;
  for (size_t i = 1; i < res.dir.size(); ++i) turns += res.dir[i] != res.dir[i - 1];
  EXPECT_GE(turns, 1);  // the program does reverse its axes
}
