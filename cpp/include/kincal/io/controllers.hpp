// kincal: programs in the controllers' own languages, written once here (and used by `kincal
// compensate` through the bindings and by kincal-compensate): KUKA KRL (.src + .dat), ABB RAPID
// (.mod), FANUC LS (.ls), URScript (.script), and the G-code and CSV of kincal/io/programs.hpp.
// Each target is either a joint target or a filtered Cartesian target with the controller's branch
// data (kincal/compensation/branch.hpp computes it). Every writer respects its controller's limits
// (name lengths and characters, number formats, targets per file: a longer program is split into
// parts that a main program calls) and fails with an InputError naming the cause.
#pragma once

#include "kincal/core/types.hpp"

#include <array>
#include <limits>
#include <string>
#include <vector>

namespace kincal {

/// The program languages kincal writes.
enum class ControllerFormat { Csv, Gcode, Krl, Rapid, FanucLs, UrScript };

/// What the targets of a written program are.
enum class TargetKind {
  Joints,   ///< joint targets (E6AXIS / jointtarget + MoveAbsJ / joint P[n] / movej)
  Filtered  ///< Cartesian targets the controller's nominal model turns into the compensated joints
};

/// "joints" or "filtered" (InputError otherwise: "--targets WORD: joints or filtered").
TargetKind target_kind_named(const std::string& name);
/// "krl", "rapid", "fanuc-ls", "urscript", "gcode", "csv" (InputError otherwise).
ControllerFormat controller_format_named(const std::string& name);
/// By the output's extension: .src/.dat KRL, .mod/.modx RAPID, .ls FANUC LS, .script URScript, .csv
/// CSV, anything else G-code (.ngc, .gcode, .nc, ...).
ControllerFormat controller_format_of_path(const std::string& path);
const char* format_name(ControllerFormat f);

/// One target of a written program.
struct ControllerTarget {
  Vec6 q_deg = Vec6::Zero();  ///< the joints (controller numbers, degrees)
  Pose6 pose;                 ///< Filtered: the tool pose in the robot base frame (mm, KUKA ABC deg)
  int kuka_s = 0, kuka_t = 0;              ///< KUKA Status and Turn
  std::array<int, 4> abb_conf{{0, 0, 0, 0}};  ///< ABB confdata cf1, cf4, cf6, cfx
  std::string fanuc_config;                ///< FANUC configuration, e.g. "N U T, 0, 0, 0"
};

/// How a program is written.
struct WriterOptions {
  ControllerFormat format = ControllerFormat::Csv;
  TargetKind targets = TargetKind::Joints;
  std::string name;  ///< program name; empty: from the output file's name
  /// joint motions: percent of the axes' maximum speed; linear motions (filtered targets after the
  /// first): the tool's speed in mm/s. NaN: the defaults (20 %, 250 mm/s)
  double speed = std::numeric_limits<double>::quiet_NaN();
  /// approximation / blending: mm (KRL C_DIS / C_PTP, RAPID zonedata, URScript r); FANUC: the CNT
  /// value 0..100. 0 or NaN: exact stop (FINE, fine)
  double zone = std::numeric_limits<double>::quiet_NaN();
  /// targets per file (0: the controller's limit, kControllerMaxTargets); more are split into parts
  int max_targets_per_file = 0;
};

/// Targets per file beyond which a program is split into parts (KRL, FANUC LS); 0: no limit.
int controller_max_targets(ControllerFormat f);

/// One file of a written program.
struct OutputFile {
  std::string path;
  std::string text;
};

/// The files of the program (KRL: NAME.src + NAME.dat, and NAME_1.src/.dat ... when split; FANUC LS:
/// NAME.ls and NAME_1.ls ...), for the output path out_path. CSV and G-code: one file of joint
/// targets (q1..q6 / "G1 A1=.."), or with Filtered of the poses (x,y,z,a,b,c / "G1 X.. C..").
std::vector<OutputFile> write_controller_program(const std::string& out_path,
                                                 const std::vector<ControllerTarget>& targets,
                                                 const WriterOptions& opt);

/// Writes every file atomically; when one fails, the ones written before it are removed.
void write_files_atomic(const std::vector<OutputFile>& files);

/// The program name for out_path when none is given: the file's stem. Checked against the
/// controller's rules (InputError "cause").
std::string controller_program_name(const std::string& out_path, const WriterOptions& opt);

}  // namespace kincal
