// Program files: G-code words replaced with everything else passing through, modal words, joint
// programs read back; bad input named by file, line and cause, and no output file written.
#include "kincal/compensation/program.hpp"
#include "kincal/io/csv.hpp"
#include "kincal/io/native.hpp"
#include "kincal/io/programs.hpp"

#include "test_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>

using namespace kincal;
using test::kr500_calibrated;
using test::tmp;

namespace {

bool exists(const std::string& p) { return std::ifstream(p).good(); }

std::string slurp(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string replaced(std::string s, const std::string& a, const std::string& b) {
  for (size_t at = s.find(a); at != std::string::npos; at = s.find(a, at + b.size())) s.replace(at, a.size(), b);
  return s;
}

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
  KINCAL_SEED_TRACE(9);
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
  KINCAL_SEED_TRACE(9);
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

// A number that is not a finite decimal (NaN, infinity, an exponent, a decimal comma) in a pose or joint
// word is an error naming the file, the line and the word; the motion is never dropped and no output is
// written. (Before: "G1 Xnan" passed through as an unknown word, "X1,5" and "X1e400" read as X1.)
TEST(Io, NonFiniteOrNonDecimalGcodeNumbersAreErrors) {
  KINCAL_SEED_TRACE(9);
  const Robot r = kr500_calibrated();
  const std::string out = ::testing::TempDir() + "never.gcode";
  std::remove(out.c_str());
  const std::string first = "G1 X2000 Y-100 Z500 A180 B0 C180\n";
  const char* words[] = {"Xnan", "XNaN", "Xinf", "XINFINITY", "X-inf", "X+nan", "X1,5", "X1e400", "X1E-3", "Y2000.5.", "C1/2"};
  for (const char* w : words) {
    const std::string in = tmp("nf.gcode", first + "G1 " + w + " Z600\n");
    const std::string e = error_of([&] { compensate_program_file(r, in, out, ProgramOptions{}); });
    const std::string letter(1, w[0]);
    EXPECT_NE(e.find("nf.gcode:2: broken number in word " + letter + " ('" + w + "'): not a finite decimal number"),
              std::string::npos) << w << ": " << e;
    EXPECT_FALSE(exists(out)) << w;
  }
  // joint words too
  const std::string jin = tmp("nfj.gcode", "G1 A1=0 A2=-90 A3=90 A4=0 A5=30 A6=0\nG1 A2=nan\n");
  EXPECT_NE(error_of([&] { read_joint_program(jin, 6); })
                .find("nfj.gcode:2: broken number in word A2= ('A2=nan'): not a finite decimal number"),
            std::string::npos);
  // what stays valid: packed words, a sign, a leading or trailing point, a word E without a number
  const PoseProgram p = parse_pose_program("G1X2000Y-100Z+500.A180B.0C180 E F10\n", "ok.gcode", ProgramFormat::Gcode);
  EXPECT_EQ(p.poses[0].xyz, Vec3(2000, -100, 500));
}

// A joint program holding a Cartesian motion line is ambiguous: an error naming file:line (before: the
// line was skipped and the motion dropped).
TEST(Io, CartesianWordsInAJointProgramAreErrors) {
  const std::string head = "G1 A1=0 A2=-90 A3=90 A4=0 A5=30 A6=0\n";
  for (const char* l : {"G1 X100 Y5", "G1 A180", "N20 G0 Z-5.5", "G1 A1=1 C0", "G1 Bnan"}) {
    const std::string e =
        error_of([&] { parse_joint_program(head + l + "\n", "j.gcode", ProgramFormat::Gcode, 6); });
    EXPECT_NE(e.find("j.gcode:2: pose word '"), std::string::npos) << l << ": " << e;
    EXPECT_NE(e.find("in a joint program"), std::string::npos) << l << ": " << e;
  }
  // comments, feed and other words still pass; so does a dwell (G4 / G04: its X or P is a time)
  const JointProgram jp = parse_joint_program(head + "G1 A1=5 F2000 (X100) ; Y5\nG4 X1.5\nG04 P500\nM30\n", "j.gcode",
                                              ProgramFormat::Gcode, 6);
  ASSERT_EQ(jp.q.size(), 2u);
  EXPECT_EQ(jp.q[1][0], 5.0);
  // G40 (cutter compensation off) and G4.1 are no dwells: their X is still a pose word
  for (const char* l : {"G40 X100", "G4.1 X2"})
    EXPECT_NE(error_of([&] { parse_joint_program(head + l + "\n", "j.gcode", ProgramFormat::Gcode, 6); })
                  .find("pose word 'X"),
              std::string::npos)
        << l;
}

// A dwell's X (G4 X1.5: seconds) is no position in a pose program either: the line passes through as
// text and the next motion keeps the modal pose before it.
TEST(Io, ADwellIsNoMotion) {
  const PoseProgram p = parse_pose_program("G1 X2000 Y0 Z500 A180 B0 C180\nG4 X1.5\nG1 Y10\n", "p.gcode",
                                           ProgramFormat::Gcode);
  ASSERT_EQ(p.poses.size(), 2u);
  EXPECT_EQ(p.poses[1].xyz.x(), 2000.0);
  EXPECT_EQ(p.poses[1].xyz.y(), 10.0);
}

// A CRLF program comes back with CRLF, line by line (the LF program's output with each "\n" a "\r\n");
// mixed line ends and a last line without a newline are kept as they were.
TEST(Io, GcodeLinesKeepTheirOwnLineEnds) {
  KINCAL_SEED_TRACE(9);
  const Robot r = kr500_calibrated();
  const std::string lf_in = tmp("lf.gcode", kGcode), crlf_in = tmp("crlf.gcode", replaced(kGcode, "\n", "\r\n"));
  const std::string lf_out = ::testing::TempDir() + "lf_o.gcode", crlf_out = ::testing::TempDir() + "crlf_o.gcode";
  compensate_program_file(r, lf_in, lf_out, ProgramOptions{});
  compensate_program_file(r, crlf_in, crlf_out, ProgramOptions{});
  const std::string lf = slurp(lf_out), crlf = slurp(crlf_out);
  EXPECT_EQ(lf.find('\r'), std::string::npos);
  EXPECT_EQ(crlf, replaced(lf, "\n", "\r\n"));
  // mixed, and no newline at the end
  const std::string mixed = "; a\r\nG1 X2000 Y-100 Z500 A180 B0 C180\nG1 Y-95\r\nM30";
  const std::string mixed_in = tmp("mixed.gcode", mixed), mixed_out = ::testing::TempDir() + "mixed_o.gcode";
  compensate_program_file(r, mixed_in, mixed_out, ProgramOptions{});
  std::string got = slurp(mixed_out);
  ASSERT_EQ(std::count(got.begin(), got.end(), '\n'), 3) << got;
  EXPECT_EQ(got.substr(0, 5), "; a\r\n");
  const size_t l2 = got.find('\n', 5), l3 = got.find('\n', l2 + 1);
  EXPECT_NE(got[l2 - 1], '\r');
  EXPECT_EQ(got[l3 - 1], '\r');
  EXPECT_EQ(got.substr(l3 + 1), "M30");
}

// RFC 4180 CSV: quoted fields with commas, doubled quotes and line breaks; blanks around fields; a UTF-8
// byte order mark (as Excel writes it) skipped. (Before: the quoted comma split the field, "8 fields, the
// header has 7"; the mark made the first column "\xEF\xBB\xBFx", "missing column 'x'".)
TEST(Io, CsvQuotedFieldsAndByteOrderMark) {
  KINCAL_SEED_TRACE(9);
  const CsvTable t = parse_csv("\xEF\xBB\xBF" "x,\"note, with comma\",y\n"
                               "1,\"hello, world\",2\n"
                               "  3 , \"say \"\"hi\"\"\" ,4\r\n"
                               "\n"
                               "5,\"two\nlines\",6\n"
                               "\"7\",,8\n",
                               "q.csv");
  ASSERT_EQ(t.header, (std::vector<std::string>{"x", "note, with comma", "y"}));
  ASSERT_EQ(t.cells.size(), 4u);
  EXPECT_EQ(t.cells[0][1], "hello, world");
  EXPECT_EQ(t.cells[1][1], "say \"hi\"");
  EXPECT_EQ(t.cells[2][1], "two\nlines");
  EXPECT_EQ(t.number(3, 0), 7.0);
  EXPECT_EQ(t.cells[3][1], "");
  EXPECT_EQ(t.line, (std::vector<int>{2, 3, 5, 7}));  // the line each row starts on
  EXPECT_EQ(t.number(1, 2), 4.0);
  EXPECT_NE(error_of([&] { parse_csv("x,y\n1,\"open\n2,3\n", "u.csv"); }).find("u.csv:2: a quoted field is not closed"),
            std::string::npos);
  EXPECT_NE(error_of([&] { parse_csv("x,y\n1,\"a\"b\n", "t.csv"); }).find("t.csv:2: text after the closing"),
            std::string::npos);
  EXPECT_NE(error_of([&] { parse_csv("x,y\n1,2,3\n", "f.csv"); }).find("f.csv:2: 3 fields, the header has 2"),
            std::string::npos);

  // a pose program and a measurement file with both: read as the plain ones
  const Robot r = kr500_calibrated();
  const std::string plain = tmp("plain.csv", "x,y,z,a,b,c\n2000,-100,500,180,0,180\n");
  const std::string excel = tmp("excel.csv", "\xEF\xBB\xBF" "x,y,z,a,b,c,note\r\n2000,-100,500,180,0,180,\"hello, world\"\r\n");
  const std::string o1 = ::testing::TempDir() + "plain_o.csv", o2 = ::testing::TempDir() + "excel_o.csv";
  compensate_program_file(r, plain, o1, ProgramOptions{});
  compensate_program_file(r, excel, o2, ProgramOptions{});
  EXPECT_EQ(slurp(o1), slurp(o2));
}

// A native program filtered into a file of another name takes that name where the controller ties
// module and file (KRL DEF / DEFDAT, RAPID MODULE); a name the controller would not take is refused,
// naming --out and the rule. Every other byte stays.
TEST(Io, NativeProgramTakesTheNameOfItsNewFile) {
  const std::string src = "&ACCESS RVP\nDEF tape( ) ; main\n  PTP XP1\nEND\nDEF helper( )\nEND\n";
  const std::string dat = "DEFDAT  tape PUBLIC\nDECL E6POS XP1={X 2000.0,Y -100.0,Z 500.0,A 180.0,B 0.0,C 180.0}\nENDDAT\n";
  tmp("tape.src", src);
  tmp("tape.dat", dat);
  const NativeProgram p = read_native_program(::testing::TempDir() + "tape.src", ControllerFormat::Krl);
  ASSERT_EQ(p.targets.size(), 1u);
  std::vector<Pose6> pose{p.targets[0].pose};
  std::vector<ControllerTarget> t(1);
  t[0].pose = p.targets[0].pose;
  t[0].kuka_s = 2;
  t[0].kuka_t = 2;
  const auto outs = [](const std::string& stem) { return std::vector<std::string>{stem + ".src", stem + ".dat"}; };
  const auto files = write_native_program(p, pose, t, {false}, outs("out/other_2"));
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].path, "out/other_2.src");
  EXPECT_EQ(files[0].text, replaced(src, "DEF tape( )", "DEF other_2( )"));  // not the helper
  EXPECT_EQ(files[1].text.substr(0, files[1].text.find('\n')), "DEFDAT  other_2 PUBLIC");
  // the same name in another case: unchanged
  EXPECT_EQ(write_native_program(p, pose, t, {false}, outs("out/TAPE"))[0].text, src);
  for (const char* bad : {"out/other-2", "out/2other", "out/a_name_longer_than_24_chars"}) {
    const std::string e = error_of([&] { write_native_program(p, pose, t, {false}, outs(bad)); });
    EXPECT_NE(e.find(std::string("--out ") + bad + ".src: a KRL module is named by its files"), std::string::npos) << e;
    EXPECT_NE(e.find("a letter, then letters, digits or '_', at most 24 characters"), std::string::npos) << e;
  }
  const std::string mod = "MODULE tape\n  CONST robtarget p1:=[[2000,-100,500],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                          "  PROC main()\n    MoveL p1,v100,fine,tool0;\n  ENDPROC\nENDMODULE\r\n";
  const NativeProgram m = read_native_program(tmp("tape.mod", mod), ControllerFormat::Rapid);
  std::vector<ControllerTarget> mt(1);
  mt[0].pose = m.targets[0].pose;
  // RAPID does not tie a module's name to its file's: the module keeps its name whatever the file is called
  const auto mf = write_native_program(m, {m.targets[0].pose}, mt, {false}, {"other.mod"});
  EXPECT_EQ(mf[0].text.substr(0, 12), "MODULE tape\n");
  EXPECT_EQ(write_native_program(m, {m.targets[0].pose}, mt, {false}, {"o.t.mod"})[0].text.substr(0, 12), "MODULE tape\n");
}
