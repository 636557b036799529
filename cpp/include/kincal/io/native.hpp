// kincal: programs the controllers run, read in (KUKA KRL .src with its .dat, ABB RAPID modules, FANUC
// LS programs, URScript) so
// that their Cartesian targets can be compensated and written back with every other line unchanged,
// byte for byte. Targets computed at run time (KRL: a target assigned in the program, a geometric
// operator, a _REL motion; RAPID: Offs, RelTool, CRobT, ...) are listed as unresolved. Every error is
// an InputError "file:line: cause".
#pragma once

#include "kincal/core/types.hpp"
#include "kincal/io/controllers.hpp"

#include <regex>
#include <string>
#include <utility>
#include <vector>

namespace kincal {

/// A change of the program beside a target's value: a span of one line and its new text.
struct NativeEdit {
  int file = 0, line = 0;  ///< file index, 1-based line
  size_t begin = 0, end = 0;
  std::string text;
};

/// One Cartesian target of a native program: where its value stands (a span of one line), its
/// pose in the program's frame, and that frame (RAPID: the work object of its first motion).
struct NativeTarget {
  int file = 0;                        ///< index into NativeProgram::paths
  int line = 0;                        ///< 1-based line of the value
  size_t begin = 0, end = 0;           ///< the value's span: from begin in `line` to end in `last_line`
  int last_line = 0;                   ///< the value's last line (0: `line`; FANUC LS: a /POS entry)
  Pose6 pose;                          ///< in the program's frame (mm, KUKA ABC deg)
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();  ///< the program's frame in the robot base
  std::string name;                    ///< declared name, or "" when inline
  int uframe = -1, utool = -1;         ///< FANUC LS: the position's UF and UT numbers (-1: other languages)
  /// Whether it can be written as a joint target: every motion to it interpolates in joints (KRL PTP /
  /// SPTP, RAPID MoveJ, LS J, URScript movej) and nothing else in the program names it.
  bool joint_motion = false;
  /// The changes besides its value when it is written as joints: KRL the declaration's type (E6POS to
  /// E6AXIS, POS and FRAME to AXIS), RAPID the declaration's type (robtarget to jointtarget) and every
  /// MoveJ to it (MoveAbsJ).
  std::vector<NativeEdit> joint_edits;
};

/// One motion statement of a native program, in the order of the file (a circular motion: two, its
/// via and its end point). --tolerance follows the path from each motion's target to the next.
struct NativeMotion {
  int line = 0;         ///< its line in the program's first file (1-based)
  int target = -1;      ///< its target in NativeProgram::targets; -1: one kincal does not compensate
  /// 'J' joint interpolation, 'L' a straight line (KRL LIN / SLIN, RAPID MoveL, LS L, URScript movel),
  /// 'C' an arc, 'O' another motion (RAPID MoveLDO, MoveJSync, ..., URScript movep; not followed)
  char kind = 'J';
  /// the statement (without its comment and its indentation) around the target's value: a target
  /// inserted before it is head + value + tail
  std::string indent, head, tail;
};

/// A target the program computes at run time: not compensated.
struct UnresolvedTarget {
  std::string where;  ///< "file:line"
  std::string text;   ///< the motion statement
};

struct NativeProgram {
  ControllerFormat format = ControllerFormat::Krl;
  std::vector<std::string> paths;               ///< KRL: .src, .dat; RAPID: the module
  std::vector<std::vector<std::string>> lines;  ///< every file's lines (without the '\n')
  std::vector<bool> final_newline;              ///< whether each file ends in '\n'
  std::vector<NativeTarget> targets;            ///< in the order the motions first use them
  std::vector<NativeMotion> motions;            ///< every motion statement, in the order of the file
  std::vector<UnresolvedTarget> unresolved;
};

/// Reads a KRL program (path: the .src; its .dat beside it when present), a RAPID module, a FANUC LS
/// program or a URScript program.
NativeProgram read_native_program(const std::string& path, ControllerFormat format);

/// A target --tolerance inserts before a straight-line motion: a copy of that motion (indentation,
/// instruction, speed, zone, tool, ... as written) to an inline filtered target; LS: a new P[n] in /POS.
struct InsertedTarget {
  size_t motion = 0;         ///< inserted before NativeProgram::motions[motion]
  Pose6 pose;                ///< in the program's frame
  ControllerTarget target;   ///< its branch data
};

/// The program with target k's value replaced: when joints[k], by the joints t[k].q_deg (KRL E6AXIS /
/// AXIS, RAPID jointtarget, LS J1..J6, URScript [q1..q6] in rad; external axes kept) with the target's
/// joint_edits; otherwise by pose[k] (in the program's frame) with the branch data of t[k] (KRL S and T,
/// RAPID confdata, LS CONFIG). Every other byte unchanged but for the inserted targets' lines (an LS
/// program's /MN lines are then renumbered, and its LINE_COUNT). Files go to out_path (KRL: its .src and .dat).
std::vector<OutputFile> write_native_program(const NativeProgram& p, const std::vector<Pose6>& pose,
                                             const std::vector<ControllerTarget>& t, const std::vector<bool>& joints,
                                             const std::string& out_path,
                                             const std::vector<InsertedTarget>& inserted = {});

/// Appends the file at path to p: its path, its lines (without the '\n') and whether it ends in '\n'.
void add_program_file(NativeProgram& p, const std::string& path);

/// The span [begin, end) of group `group` of a match.
std::pair<size_t, size_t> span_of(const std::smatch& m, int group);

/// A declared target (or URScript variable) named anywhere but in its declaration and its motions
/// (code before the comment character; names compared case-insensitively when asked) is not written as
/// joints: joint_motion false.
void keep_named_targets_cartesian(NativeProgram& p, char comment, bool ignore_case);

/// A motion of the given kind on a line whose code (the line without its comment) holds its target's
/// value at [begin, begin + size).
NativeMotion motion_around(const std::string& code, int line, char kind, size_t begin, size_t size);

/// Splits s at top-level commas (outside brackets, braces, parentheses and strings); trims blanks.
std::vector<std::string> split_top(const std::string& s);

/// s in upper case (ASCII).
std::string upper_case(std::string s);

/// The line without its comment: everything from the first `comment` character outside a
/// "string" on (KRL ';', RAPID '!', URScript '#'), and without the '\r' of a CRLF line.
std::string code_before(const std::string& line, char comment);

/// How often name stands in code as a whole word (letters, digits and '_' on neither side);
/// ignore_case for KRL and RAPID names.
int word_count(const std::string& code, const std::string& name, bool ignore_case = true);

}  // namespace kincal
