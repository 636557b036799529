// kincal: CSV and G-code programs, compensation of whole programs, and the streaming corrector.
// Every reader error is an InputError "file:line: cause"; writers never leave a partial file.
#pragma once

#include "kincal/compensation.hpp"
#include "kincal/ik.hpp"
#include "kincal/model.hpp"

#include <string>
#include <vector>

namespace kincal {

/// A CSV file: header and string cells, with the line number of every row.
struct CsvTable {
  std::string source;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> cells;
  std::vector<int> line;
  int find(const std::string& name) const;      ///< column index or -1
  int require(const std::string& name) const;   ///< column index or InputError
  double number(size_t row, int col) const;     ///< finite number or InputError naming file:line
  std::string where(size_t row) const { return source + ":" + std::to_string(line[row]); }
};
CsvTable read_csv(const std::string& path);
CsvTable parse_csv(const std::string& text, const std::string& source);

/// A program of tool poses (CSV x,y,z,a,b,c or G-code X Y Z A B C words, modal).
struct PoseProgram {
  std::string source;
  bool gcode = false;
  std::vector<Pose6> poses;
  std::vector<int> pose_line;  ///< line number of every pose
  // G-code only: every input line with its pose words cut out, where to put the joint words, and
  // which pose it carries (-1: passes through unchanged)
  struct Line {
    std::string text;
    size_t insert_at = 0;
    int pose = -1;
  };
  std::vector<Line> lines;
};
PoseProgram read_pose_program(const std::string& path);
PoseProgram parse_pose_program(const std::string& text, const std::string& source, bool gcode);

/// A joint program (CSV q1..qN or G-code A1=.. words, modal), angles in degrees.
struct JointProgram {
  std::string source;
  int dof = 0;
  std::vector<std::vector<double>> q;
  std::vector<int> line;
};
JointProgram read_joint_program(const std::string& path, int dof);
JointProgram parse_joint_program(const std::string& text, const std::string& source, bool gcode, int dof);

/// Write text to path atomically (a temporary file beside it, renamed when complete).
void write_file_atomic(const std::string& path, const std::string& text);
bool is_csv_path(const std::string& path);

struct ProgramOptions {
  bool compensate = true;      ///< false: the nominal IK program (uncompensated)
  bool instrument_frame = false;
  /// Start Newton from the nominal IK of the target corrected by the model difference at the
  /// nominal solution (one fixed-point step); false: from the nominal IK solution, as the paper.
  bool corrected_start = true;
  CompensationOptions comp;
};

/// One pose: nominal IK nearest ref (a pose a little beyond nominal reach starts from the nearest
/// configuration), then Newton on the calibrated model. Returns false with the cause in err;
/// allocates nothing on success.
bool solve_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Eigen::Matrix<double, 6, 1>& ref,
                Eigen::Matrix<double, 6, 1>& q_out, int& iterations, double& residual, std::string& err);

struct ProgramResult {
  std::vector<Eigen::Matrix<double, 6, 1>> q_deg;
  std::vector<int> iterations;
  std::vector<double> residual;
  int max_iterations = 0;
  double max_residual = 0;
};

/// IK + compensation of every pose in order, keeping the branch continuous (each pose starts from
/// the IK solution nearest the previous result; the first from the robot's home). The first pose
/// that fails throws an InputError naming where[i] and the cause.
ProgramResult compensate_poses(const Robot& robot, const std::vector<Pose6>& poses,
                               const std::vector<std::string>& where, const ProgramOptions& opt);

/// Reads a pose program, compensates it and writes the joint program (CSV or G-code by the output
/// file's extension). Nothing is written when any pose fails.
ProgramResult compensate_program_file(const Robot& robot, const std::string& in_path, const std::string& out_path,
                                      const ProgramOptions& opt);

/// Format a joint program as text: CSV (q1..q6) or G-code (the input's lines with A1=.. words).
std::string format_joint_program(const PoseProgram& in, const ProgramResult& res, bool csv);

/// The controller-PC corrector: one pose line in, one joint line out, no allocation per line.
class StreamCompensator {
 public:
  StreamCompensator(Robot robot, ProgramOptions opt);
  /// Processes one input line (without its newline); writes the output line (without newline) to
  /// out and returns its length. Throws InputError "stdin:N: cause" on bad input.
  size_t process(const char* line, size_t len, char* out, size_t cap);

 private:
  Robot robot_;
  ProgramOptions opt_;
  int line_no_ = 0;
  bool have_prev_ = false;
  Eigen::Matrix<double, 6, 1> prev_;
  // CSV state
  bool csv_header_seen_ = false;
  int csv_cols_[6] = {0, 1, 2, 3, 4, 5};
  // G-code modal state
  Pose6 modal_;
  bool modal_set_[6] = {false, false, false, false, false, false};
  Eigen::Matrix<double, 6, 1> solve(const Pose6& p);
};

}  // namespace kincal
