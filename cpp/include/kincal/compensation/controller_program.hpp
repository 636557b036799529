// kincal: a pose program compensated into a program in a controller's language (KRL, RAPID, FANUC
// LS, URScript, G-code, CSV), with joint targets or filtered Cartesian targets (the nominal FK of the
// compensated joints with the branch data that makes the controller take them).
#pragma once

#include "kincal/compensation/program.hpp"
#include "kincal/io/controllers.hpp"
#include "kincal/io/native.hpp"

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace kincal {

/// The targets of compensated joints: with Filtered, the nominal FK pose and the branch data of each,
/// checked: the controller's selection (select_branch, KRL / RAPID / FANUC LS) must bring back the
/// compensated joints to 1e-6 deg, else InputError "where[i]: cause".
std::vector<ControllerTarget> controller_targets(const Robot& robot, const std::vector<Vec6>& q_deg, TargetKind kind,
                                                 ControllerFormat format, const std::vector<std::string>& where);

/// A native program's frames, what to do with targets computed at run time, and the path tolerance.
struct NativeOptions {
  Pose6 program_tool;  ///< the program's TCP in the model's tool frame (--program-tool)
  Pose6 program_base;  ///< the program's base in the robot's base frame (--program-base)
  /// FANUC LS: user frame n in the robot's base frame (--uframe n=..) and tool n in the model's tool frame
  /// (--utool n=..), for the positions in UF n / UT n. Needed when the positions use several; a program in
  /// one UF and one UT may use program_base / program_tool instead.
  std::map<int, Pose6> user_frames, user_tools;
  bool skip_unresolved = false;  ///< pass run-time targets through with a warning (else an error)
  /// A taught target (with branch data) compensated off its taught solution (another arm, elbow or wrist
  /// choice, or another turn that is not the compensation moving a joint across its border) is a warning,
  /// not an error (--allow-branch-change).
  bool allow_branch_change = false;
  /// --track AXIS=X,Y,Z: external axis j (0-based, E1 = 0) is a linear track; one unit of it moves the robot's
  /// base by this vector in the program's base frame (mm per mm). An external axis that varies without one is an error.
  std::map<int, Vec3> track;
  /// declarations the program may name without declaring them (a backup's other files, --declarations)
  std::shared_ptr<const Declarations> context;
  /// --tolerance: targets inserted where the real robot's path between two targets leaves the desired
  /// segment by more (mm; kincal/compensation/tolerance.hpp); NaN: none inserted
  double tolerance_mm = std::numeric_limits<double>::quiet_NaN();
};

/// Adds "N=X,Y,Z,A,B,C" (mm, deg) of `option` (--uframe, --utool) to `frames`, else InputError naming it.
void add_numbered_frame(std::map<int, Pose6>& frames, const std::string& text, const std::string& option);

/// Adds "--track AXIS=X,Y,Z" (AXIS: E1..E6) to `track`, else InputError naming it.
void add_track_axis(std::map<int, Vec3>& track, const std::string& text);

/// Reads a pose program (CSV or G-code; a KRL or RAPID program: see NativeOptions), compensates it and writes it in w.format (every file, or
/// none when anything fails). A G-code program written as G-code joints keeps its other lines. A CSV or
/// G-code program written as CSV or G-code joints (without --tolerance) is compensated pose after pose in
/// bounded memory (compensate_program_file; opt.keep_poses false: the result without per-pose vectors).
/// Returns the result with the files written in `files`.
struct ControllerProgramResult {
  ProgramResult result;
  std::vector<std::string> files;
  /// the largest deviation of the path between targets from the desired segments (mm), before and after
  /// --tolerance inserted targets (NaN without --tolerance), and how many it inserted
  double path_before_mm = std::numeric_limits<double>::quiet_NaN();
  double path_after_mm = std::numeric_limits<double>::quiet_NaN();
  int inserted = 0;
  /// a native program: how many targets were written as joints and how many as filtered poses ("" otherwise)
  std::string targets_note;
};
/// A native program read (read_native_programs) compensated and written: file f of p.paths to out_of(f), every
/// file or none. Its taught targets stay on their taught branch (NativeOptions::allow_branch_change).
ControllerProgramResult compensate_native_program(const Robot& robot, const NativeProgram& p,
                                                  const std::function<std::string(const std::string&)>& out_of,
                                                  const ProgramOptions& opt, const WriterOptions& w,
                                                  const NativeOptions& native);

ControllerProgramResult compensate_to_controller(const Robot& robot, const std::string& in_path,
                                                 const std::string& out_path, const ProgramOptions& opt,
                                                 const WriterOptions& w, const NativeOptions& native = {});

}  // namespace kincal
