// The streaming corrector: equal to the file compensation line for line, and no allocation per line
// (with every effect too).
#include "kincal/compensation/program.hpp"
#include "kincal/compensation/stream.hpp"

#include "test_files.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <new>
#include <sstream>

using namespace kincal;
using test::kr500_calibrated;
using test::tmp;

// Counts heap allocations (for every test of this program), to show real-time loops make none.
std::atomic<long> g_allocs{0};
void* operator new(std::size_t n) {
  ++g_allocs;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

TEST(Io, StreamEqualsFileAndAllocatesNothingPerLine) {
  KINCAL_SEED_TRACE(9);
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
  KINCAL_SEED_TRACE(8);
  ModelSpec s = perturbed_spec(kr500_spec(), test::test_seed(8), 1.0, 0.05, 0.003);
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

// solve_pose, the per-pose path of programs and of the stream, allocates nothing when the branch
// nearest the reference gives the answer.
TEST(Io, SolvePoseAllocatesNothingOnTheNearestBranch) {
  KINCAL_SEED_TRACE(9);
  const Robot r = kr500_calibrated();
  Vec6 q;
  q << 10, -70, 95, 20, 40, -10;
  std::vector<Pose6> poses;
  for (int i = 0; i < 50; ++i) {
    Vec6 qi = q;
    qi[0] += 0.5 * i, qi[2] -= 0.2 * i;
    poses.push_back(iso_to_pose(fk_compliant(*r.calibrated(), VecQ(qi * kDeg))));
  }
  const ProgramOptions opt;
  ASSERT_EQ(solve_pose(r, opt, poses[0], q).status, PoseStatus::Solved);
  int solved = 0;
  const long before = g_allocs.load();
  for (const Pose6& p : poses) solved += solve_pose(r, opt, p, q).status == PoseStatus::Solved;
  EXPECT_EQ(g_allocs.load() - before, 0);
  EXPECT_EQ(solved, 50);
}

// The stream stops at the first bad line (README): a NaN, infinite or non-decimal pose word is an error
// naming stdin:line and the word (before: "G1 Xnan" came out unchanged and the motion was dropped).
TEST(Io, StreamStopsAtANonFiniteWord) {
  KINCAL_SEED_TRACE(9);
  const Robot r = kr500_calibrated();
  for (const char* w : {"Xnan", "Xinf", "X1,5", "X1e400"}) {
    StreamCompensator sc(r, ProgramOptions{});
    char buf[8192];
    const std::string l1 = "G1 X2000 Y-100 Z500 A180 B0 C180", l2 = std::string("G1 ") + w;
    sc.process(l1.data(), l1.size(), buf, sizeof buf);
    std::string e;
    try {
      sc.process(l2.data(), l2.size(), buf, sizeof buf);
    } catch (const InputError& x) {
      e = x.what();
    }
    EXPECT_NE(e.find(std::string("stdin:2: broken number in word X ('") + w + "'): not a finite decimal number"),
              std::string::npos) << w << ": " << e;
  }
}

// A CRLF G-code line comes out with its '\r' (the caller adds the '\n'), an LF line without; a CSV stream
// may start with Excel's byte order mark and carry quoted extra columns.
TEST(Io, StreamKeepsCrlfAndReadsExcelCsv) {
  KINCAL_SEED_TRACE(9);
  const Robot r = kr500_calibrated();
  StreamCompensator sc(r, ProgramOptions{});
  char buf[8192];
  const std::string crlf = "N10 G1 X2000 Y-100 Z500 A180 B0 C180 F2000\r", lf = "N20 Y-95", pass = "M30\r";
  std::string a(buf, sc.process(crlf.data(), crlf.size(), buf, sizeof buf));
  ASSERT_EQ(a.back(), '\r');
  EXPECT_EQ(a.rfind(" F2000\r"), a.size() - 7);
  std::string b(buf, sc.process(lf.data(), lf.size(), buf, sizeof buf));
  EXPECT_NE(b.back(), '\r');
  EXPECT_EQ(std::string(buf, sc.process(pass.data(), pass.size(), buf, sizeof buf)), "M30\r");
  const std::string comment = "N30 Y-90 (slow, here)";  // a comma in a G-code comment: still G-code
  EXPECT_NE(std::string(buf, sc.process(comment.data(), comment.size(), buf, sizeof buf)).find("A1="), std::string::npos);

  StreamCompensator plain(r, ProgramOptions{}), excel(r, ProgramOptions{});
  const std::string ph = "x,y,z,a,b,c", pl = "2000,-100,500,180,0,180";
  const std::string eh = "\xEF\xBB\xBF" "x,\"note, free text\",y,z,a,b,c", el = "\"2000\",\"hello, world\",-100,500,180,0,180";
  std::string hp(buf, plain.process(ph.data(), ph.size(), buf, sizeof buf));
  std::string he(buf, excel.process(eh.data(), eh.size(), buf, sizeof buf));
  EXPECT_EQ(hp, he);
  std::string rp(buf, plain.process(pl.data(), pl.size(), buf, sizeof buf));
  std::string re(buf, excel.process(el.data(), el.size(), buf, sizeof buf));
  EXPECT_EQ(rp, re);
  const std::string broken = "2000,\"open,-100,500,180,0,180";
  std::string e;
  try {
    excel.process(broken.data(), broken.size(), buf, sizeof buf);
  } catch (const InputError& x) {
    e = x.what();
  }
  EXPECT_NE(e.find("stdin:3: a quoted field is not closed"), std::string::npos) << e;
}
