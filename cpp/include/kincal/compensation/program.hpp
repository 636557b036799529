// kincal: CSV and G-code programs, compensation of whole programs, and the streaming corrector.
// Every reader error is an InputError "file:line: cause"; writers never leave a partial file.
#pragma once

#include "kincal/compensation/pose.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/model.hpp"

#include <limits>
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
  std::vector<double> temperature_c;  ///< CSV: the temperature_c column per pose, when present
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
  /// thermal expansion: the temperature of every pose (deg C) unless the program has a column
  double temperature_c = std::numeric_limits<double>::quiet_NaN();
  /// backlash: each joint's direction of motion into the first pose (+-1); empty: the direction of
  /// the first motion (offline programs only)
  std::vector<double> initial_direction;
  /// a branch change inside a program (to stay within the joint limits) is an error, not a warning
  bool keep_branch = false;
  /// Start Newton from the nominal IK of the target corrected by the model difference at the
  /// nominal solution (one fixed-point step); false: from the nominal IK solution, as the paper.
  bool corrected_start = true;
  CompensationOptions comp;
};

/// One pose: nominal IK nearest ref (a pose a little beyond nominal reach starts from the nearest
/// configuration), then Newton on the calibrated model with its effects acting in ctx. When the
/// compensated solution of that branch is outside the joint limits (or does not converge), the
/// other branches are tried nearest first, and the first whose compensated solution is inside the
/// limits is taken (branch_changed). Returns false with the cause in err; allocates nothing when
/// the nearest branch succeeds.
bool solve_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Vec6& ref,
                const EffectContext& ctx, Vec6& q_out, int& iterations, double& residual,
                bool& branch_changed, std::string& err);
/// The same without effects context (a model without backlash or thermal expansion).
bool solve_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Vec6& ref,
                Vec6& q_out, int& iterations, double& residual, std::string& err);

struct ProgramResult {
  std::vector<Vec6> q_deg;
  std::vector<int> iterations;
  std::vector<double> residual;
  std::vector<Vec6> dir;  ///< backlash: each joint's direction into each pose
  std::vector<std::string> warnings;             ///< "file:line: cause", e.g. branch changes
  int max_iterations = 0;
  double max_residual = 0;
};

/// A joint's motion smaller than this (deg) keeps its direction (it stands still).
constexpr double kStillDeg = 1e-7;

/// The direction of motion of every joint into every pose of a joint program: the sign of its
/// change from the previous pose, held while it stands still; the first pose's from initial (+-1
/// per joint; empty: the direction of each joint's first motion, +1 for a joint that never moves).
std::vector<Vec6> motion_directions(const std::vector<Vec6>& q_deg,
                                                           const std::vector<double>& initial);

/// IK + compensation of every pose in order, keeping the branch continuous (each pose starts from
/// the IK solution nearest the previous result; the first from the robot's home). Backlash: every
/// pose is compensated with the directions its own commanded motion has (motion_directions);
/// thermal expansion: temperature_c per pose (or opt.temperature_c). The first pose that fails
/// throws an InputError naming where[i] and the cause.
ProgramResult compensate_poses(const Robot& robot, const std::vector<Pose6>& poses,
                               const std::vector<std::string>& where, const ProgramOptions& opt,
                               const std::vector<double>& temperature_c = {});

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
  /// A warning about the last line processed (a branch change), or empty.
  const std::string& warning() const { return warning_; }

 private:
  Robot robot_;
  ProgramOptions opt_;
  int line_no_ = 0;
  bool first_ = true;
  Vec6 prev_;
  EffectContext ctx_;
  int csv_temperature_col_ = -1;
  std::string warning_;
  // CSV state
  bool csv_header_seen_ = false;
  int csv_cols_[6] = {0, 1, 2, 3, 4, 5};
  // G-code modal state
  Pose6 modal_;
  bool modal_set_[6] = {false, false, false, false, false, false};
  Vec6 solve(const Pose6& p, double temperature_c);
};

}  // namespace kincal
