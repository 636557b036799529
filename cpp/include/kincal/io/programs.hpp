// kincal: robot programs as files: pose programs (CSV x,y,z,a,b,c or G-code X Y Z A B C words) read
// in (whole, or line by line in bounded memory), joint programs (CSV q1..qN or G-code A1= .. words) read
// in and written out. Every reader error is an InputError "file:line: cause".
#pragma once

#include "kincal/core/types.hpp"
#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"

#include <cstddef>
#include <limits>
#include <memory>
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

/// One line of a pose program as PoseProgramReader reads it: a pose (CSV: each row; G-code: a line with
/// pose words), or a G-code line without pose words, which passes through.
struct ProgramLine {
  bool has_pose = false;
  Pose6 pose;   ///< G-code: with the modal words of the lines before
  int line = 0;  ///< its line number (CSV: the line the row starts on)
  double temperature_c = std::numeric_limits<double>::quiet_NaN();  ///< CSV: the temperature_c column, if any
  // G-code: the line without its end, its pose words cut out; where the joint words go; its end ("\n",
  // "\r\n", or for a last line without a newline "" or "\r")
  std::string text;
  size_t insert_at = 0;
  std::string eol;
};

/// A pose program read line by line, a chunk of whole lines at a time (kincal/io/file.hpp TextChunks), so
/// that a file of any length needs memory for a chunk and its longest line only. The rules and errors of
/// read_pose_program, and the same first error: a broken CSV row or G-code line anywhere in the file comes
/// before a missing column, that before a cell that is not a finite number (the first such row), that
/// before "the program has no poses" (thrown at the end). To have these before the errors of what the
/// caller does with the poses, it reads the rest with rest() when it meets one of its own.
class PoseProgramReader {
 public:
  /// The file at path, in the format of its extension (program_format).
  explicit PoseProgramReader(const std::string& path, size_t chunk_bytes = kProgramChunkBytes);
  /// A text in memory, named source in errors.
  PoseProgramReader(std::string text, const std::string& source, ProgramFormat format);

  ProgramFormat format() const { return format_; }
  const std::string& source() const { return source_; }
  /// CSV: whether the program has a temperature_c column
  bool has_temperature() const { return temperature_col_ >= 0; }
  /// The next line into l; false at the end of the program.
  bool next(ProgramLine& l);
  /// Reads the rest of the program for its errors (those that come before the caller's): throws the first.
  void rest();
  size_t poses() const { return poses_; }

 private:
  [[noreturn]] void fail_after_rest(const std::string& error);
  bool next_csv(ProgramLine& l);
  bool next_gcode(ProgramLine& l);
  std::string source_;
  ProgramFormat format_;
  std::unique_ptr<CsvReader> csv_;
  int cols_[6] = {0, 1, 2, 3, 4, 5};
  int temperature_col_ = -1;
  std::unique_ptr<TextChunks> text_;
  size_t pos_ = 0;
  int line_ = 0;
  Pose6 modal_;
  bool set_[6] = {false, false, false, false, false, false};
  size_t poses_ = 0;
};

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
