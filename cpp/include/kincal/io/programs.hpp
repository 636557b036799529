// kincal: robot programs as files: pose programs (CSV x,y,z,a,b,c or G-code X Y Z A B C words) read
// in, joint programs (CSV q1..qN or G-code A1= .. words) read in and written out. Every reader error
// is an InputError "file:line: cause".
#pragma once

#include "kincal/core/types.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace kincal {

/// The two program formats.
enum class ProgramFormat { Csv, Gcode };

/// CSV when the path ends in .csv, G-code otherwise.
ProgramFormat program_format(const std::string& path);

/// A program of tool poses (CSV x,y,z,a,b,c or G-code X Y Z A B C words, modal).
struct PoseProgram {
  std::string source;
  ProgramFormat format = ProgramFormat::Csv;
  std::vector<Pose6> poses;
  std::vector<int> pose_line;  ///< line number of every pose
  std::vector<double> temperature_c;  ///< CSV: the temperature_c column per pose, when present
  // G-code only: every input line with its pose words cut out, where to put the joint words, which
  // pose it carries (-1: passes through unchanged), and its own line end ("\n" or "\r\n"; empty: the
  // program's `eol`, for a line inserted after reading)
  struct Line {
    std::string text;
    size_t insert_at = 0;
    int pose = -1;
    std::string eol{};
  };
  std::vector<Line> lines;
  std::string eol = "\n";     ///< G-code: the first line's end ("\r\n" for a CRLF file)
  bool final_newline = true;  ///< G-code: whether the last line ends in a newline
};
PoseProgram read_pose_program(const std::string& path);
PoseProgram parse_pose_program(const std::string& text, const std::string& source, ProgramFormat format);

/// A joint program (CSV q1..qN or G-code A1=.. words, modal), angles in degrees.
struct JointProgram {
  std::string source;
  int dof = 0;
  std::vector<std::vector<double>> q;
  std::vector<int> line;
};
JointProgram read_joint_program(const std::string& path, int dof);
JointProgram parse_joint_program(const std::string& text, const std::string& source, ProgramFormat format, int dof);

/// One pose's joint angles as text, 10 decimals: CSV "q1,..,q6" or G-code words "A1=.. A6=..", into
/// out (capacity cap); returns the length. No allocation.
size_t format_joints(char* out, size_t cap, const Vec6& q_deg, ProgramFormat format);

/// The joint program of a pose program as text: CSV (q1..q6) or G-code (a G-code input's lines with
/// A1=.. words in place of the pose words, each with its own line end; "G1 A1=.." lines for a CSV
/// input), one q_deg per pose.
std::string format_joint_program(const PoseProgram& in, const std::vector<Vec6>& q_deg, ProgramFormat format);

}  // namespace kincal
