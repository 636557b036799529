// kincal: compensation of whole programs (Samak's pipeline, pose after pose): nominal IK nearest the
// previous pose, the corrected start, Newton on the calibrated model, the joint limits and branch
// changes, backlash directions of the commanded motion, thermal expansion per pose; and the pose
// program file in, joint program file out. The file formats are in kincal/io/programs.hpp, the
// streaming corrector in kincal/compensation/stream.hpp.
#pragma once

#include "kincal/compensation/pose.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/programs.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/model.hpp"

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace kincal {

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
  /// compensate_program_file: the program file is read, and the joint program written, this many bytes
  /// at a time (a test makes it small to cross chunks in a short program)
  size_t chunk_bytes = kProgramChunkBytes;
  /// compensate_program_file: the result keeps every pose's joints, iterations, residual and directions;
  /// false: only their count and extremes (ProgramResult::poses ...), so that a program of any length
  /// is compensated in bounded memory
  bool keep_poses = true;
};

/// How solve_pose ended.
enum class PoseStatus {
  Solved,         ///< on the branch nearest the reference
  BranchChanged,  ///< on another branch: the nearest one's solution is outside the limits (error says why)
  Failed          ///< no solution: error says why
};

/// The joint angles of one pose, or why there are none.
struct PoseSolution {
  PoseStatus status = PoseStatus::Failed;
  Vec6 q_deg = Vec6::Zero();
  int iterations = 0;   ///< Newton updates made
  double residual = 0;  ///< |F| at q_deg
  std::string error;    ///< Failed: the cause; BranchChanged: why the nearest branch did not do
  bool ok() const { return status != PoseStatus::Failed; }
  bool branch_changed() const { return status == PoseStatus::BranchChanged; }
};

/// One pose: nominal IK nearest ref (a pose a little beyond nominal reach starts from the nearest
/// configuration), then Newton on the calibrated model with its effects acting in ctx. When the
/// compensated solution of that branch is outside the joint limits (or does not converge), the
/// other branches are tried nearest first, and the first whose compensated solution is inside the
/// limits is taken (BranchChanged). Allocates nothing when the nearest branch succeeds.
PoseSolution solve_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Vec6& ref,
                        const EffectContext& ctx = EffectContext());

struct ProgramResult {
  std::vector<Vec6> q_deg;
  std::vector<int> iterations;
  std::vector<double> residual;
  std::vector<Vec6> dir;  ///< backlash: each joint's direction into each pose
  std::vector<std::string> warnings;             ///< "file:line: cause", e.g. branch changes
  size_t poses = 0;  ///< poses compensated (q_deg.size(), unless ProgramOptions::keep_poses is false)
  int min_iterations = 0, max_iterations = 0;
  long long total_iterations = 0;
  double max_residual = 0;
};

/// A joint's motion smaller than this (deg) keeps its direction (it stands still).
constexpr double kStillDeg = 1e-7;

/// The direction of motion of every joint into every pose of a joint program: the sign of its
/// change from the previous pose, held while it stands still; the first pose's from initial (+-1
/// per joint; empty: the direction of each joint's first motion, +1 for a joint that never moves).
std::vector<Vec6> motion_directions(const std::vector<Vec6>& q_deg, const std::vector<double>& initial);

/// Each joint's direction into the first pose from ProgramOptions::initial_direction (one sign for
/// every joint, or one for all); InputError when it is neither or a sign is not +-1.
Vec6 initial_directions(const std::vector<double>& v);
/// --initial-direction's text: "+1", "-1" or one sign per joint, comma separated (empty: none given),
/// checked by initial_directions' rule; InputError naming the option otherwise. The one reader of
/// the option for kincal-compensate and the kincal command.
std::vector<double> parse_initial_direction(const std::string& text);

/// A program compensated pose after pose, in order (compensate_poses and StreamCompensator): the
/// reference of the next pose (the last result; the robot's home first) and the effect context
/// (backlash: the joints' directions of motion into the last pose; the temperature).
struct ProgramCursor {
  /// At the robot's home, the directions dir0 into the first pose when the model has backlash.
  ProgramCursor(const Robot& robot, const ProgramOptions& opt, const Vec6& dir0);
  Vec6 prev;
  EffectContext ctx;
  bool first = true;
  /// the next pose's reference when it is not prev (a taught target: its taught branch's nominal solution)
  std::optional<Vec6> reference;
};

/// The next pose of a program (ctx.temperature_c set by the caller): solved with the directions the
/// joints have (held from the previous pose), then, with backlash, again with the directions of its
/// own motion when that motion turns a joint around. On success the cursor moves to the pose
/// (ctx.dir: the directions into it). Allocates nothing when the nearest branch succeeds.
PoseSolution next_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, ProgramCursor& cursor);

/// The warning (or, with keep_branch, the error) of a branch change: "branch changed: ..., cause".
std::string branch_change_message(const std::string& cause);

/// The error of a model with thermal expansion given no temperature.
inline constexpr const char* kNeedsTemperature =
    "the model has thermal expansion: give the temperature (--temperature C, or a temperature_c column)";

/// IK + compensation of every pose in order, keeping the branch continuous (each pose starts from
/// the IK solution nearest the previous result; the first from the robot's home; a pose with a reference
/// in `references` from the solution nearest it: a taught target's branch). Backlash: every
/// pose is compensated with the directions its own commanded motion has (motion_directions);
/// thermal expansion: temperature_c per pose (or opt.temperature_c). The first pose that fails
/// throws an InputError naming where[i] and the cause.
/// The result's count and extremes (poses, iterations, residual) with one more pose.
void count_pose(ProgramResult& res, const PoseSolution& s);

ProgramResult compensate_poses(const Robot& robot, const std::vector<Pose6>& poses,
                               const std::vector<std::string>& where, const ProgramOptions& opt,
                               const std::vector<double>& temperature_c = {},
                               const std::vector<std::optional<Vec6>>& references = {});

/// Reads a pose program, compensates it and writes the joint program (CSV or G-code: out_format, by
/// default by the output file's extension), as compensate_poses and format_joint_program would, in
/// bounded memory: the file is read a chunk at a time (opt.chunk_bytes) and the joint program written
/// as it goes into a temporary file beside out_path, renamed into place at the end; nothing is written
/// when anything fails, and the error is the one the whole program read at once would give (a broken
/// line anywhere in the file before a pose that fails). With backlash and no initial direction the file
/// is read twice (the first pass finds the direction of each joint's first motion). A file that cannot
/// be read twice (a pipe) is read whole.
ProgramResult compensate_program_file(const Robot& robot, const std::string& in_path, const std::string& out_path,
                                      const ProgramOptions& opt, std::optional<ProgramFormat> out_format = {});

}  // namespace kincal
