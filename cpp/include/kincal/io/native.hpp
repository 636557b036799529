// kincal: programs the controllers run, read in (KUKA KRL .src with its .dat, ABB RAPID modules, FANUC
// LS programs, URScript) so
// that their Cartesian targets can be compensated and written back with every other line unchanged,
// byte for byte. Targets computed at run time (KRL: a target assigned in the program, a geometric
// operator, a _REL motion; RAPID: Offs, RelTool, CRobT, ...) are listed as unresolved. Every error is
// an InputError "file:line: cause".
#pragma once

#include "kincal/core/types.hpp"
#include "kincal/io/controllers.hpp"

#include <array>
#include <limits>
#include <map>
#include <optional>
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
  /// The motion's TCP in the controller's tool 0 frame (its flange): KRL TOOL_DATA[n] of the motion's
  /// TOOL_NO / $TOOL, RAPID the tframe of the statement's tooldata; identity for tool 0 (tool0 / $NULLFRAME),
  /// which --program-tool places in the model's tool frame. (`frame` above is the motion's base in base 0:
  /// KRL BASE_DATA[n], RAPID the work object's uframe * oframe; base 0 is --program-base.)
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
  /// The frames' names as the program gives them, for messages ("TOOL_DATA[2], BASE_DATA[1]", "tool1,
  /// wobj2"); "" for tool 0 and base 0.
  std::string frames_named;
  /// The branch data as taught (KRL S and T, RAPID confdata, LS CONFIG with its turns): only the branch
  /// fields are set. None when the target carries none (a KRL target without S/T).
  std::optional<ControllerTarget> taught;
  /// The external axes as written, E1..E6 (RAPID eax_a..eax_f, LS E1..E3); NaN where none (RAPID 9E9).
  std::array<double, 6> external{{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                  std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                  std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()}};
  /// A declared target that motions use in a second tool or base: this target is a copy, declared on a new
  /// line after target copy_of's declaration (the same line with `name` for the original's name and this
  /// target's value), and `edits` rename the motions' references to it. -1: not a copy.
  int copy_of = -1;
  /// Changes made whatever the target is written as (a copy's name at the motions that use it).
  std::vector<NativeEdit> edits;
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
  int file = 0;         ///< the file it stands in (index into NativeProgram::paths)
  int line = 0;         ///< its line in that file (1-based)
  int target = -1;      ///< its target in NativeProgram::targets; -1: one kincal does not compensate
  /// 'J' joint interpolation, 'L' a straight line (KRL LIN / SLIN, RAPID MoveL, LS L, URScript movel),
  /// 'C' an arc, 'O' another motion (RAPID MoveLDO, MoveJSync, ..., URScript movep; not followed)
  char kind = 'J';
  /// the statement (without its comment and its indentation) around the target's value: a target
  /// inserted before it is head + value + tail
  std::string indent, head, tail;
};

/// A motion whose target kincal does not compensate: one the program computes at run time, one declared
/// nowhere, or a motion kincal names but cannot follow.
struct UnresolvedTarget {
  std::string where;  ///< "file:line"
  std::string text;   ///< the motion statement
  std::string why;    ///< e.g. "computed at run time", "declared nowhere", "a relative motion (SLIN_REL)"
};

/// One declaration of a controller backup's files (or of --declarations files), which programs may name
/// without declaring it themselves: KRL the data lists (.dat, $config.dat), RAPID every module's data.
struct Declaration {
  std::string type;        ///< upper case as written: E6POS, POS, FRAME, E6AXIS, AXIS, FDAT, ...; ROBTARGET, TOOLDATA, WOBJDATA, ...
  std::string name;        ///< as written
  std::string path;        ///< the file that declares it
  int line = 0;            ///< the 1-based line where its value starts (its declaration's line)
  std::string value;       ///< the value's text, "" when declared without one
  bool run_time = false;   ///< set at run time (KRL: assigned in a program; RAPID: VAR, or assigned)
};

/// The declarations of a set of files, by upper-case name. KRL frame arrays by element:
/// "TOOL_DATA[3]", "BASE_DATA[2]" (written $TOOL_DATA[3] or TOOL_DATA[3] in $config.dat).
struct Declarations {
  std::map<std::string, Declaration> named;
  const Declaration* find(const std::string& name) const;  ///< by name, any case; nullptr when none
};

/// Every declaration in the files (KRL .dat and $config.dat; RAPID .mod/.modx/.sys), InputError "file:line:
/// cause" on a malformed one. A name declared twice keeps its first declaration (RAPID: LOCAL ones are not read).
Declarations read_declarations(const std::vector<std::string>& paths, ControllerFormat format);

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
/// program or a URScript program. Names the program does not declare are looked up in `context` (the
/// backup's other files): a Cartesian target declared there is compensated in that file, which then joins
/// the program's files (p.paths).
NativeProgram read_native_program(const std::string& path, ControllerFormat format, const Declarations& context = {});

/// Several programs read as one (KRL: several .src, each with its .dat; RAPID: the modules of one task):
/// motions in each, targets declared in any of them or in `context`. LS and URScript: one path.
NativeProgram read_native_programs(const std::vector<std::string>& paths, ControllerFormat format,
                                   const Declarations& context = {});

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
/// RAPID confdata, LS CONFIG); a copy (copy_of) declared on a new line after its original's declaration;
/// every target's `edits`. Every other byte unchanged but for the inserted targets' lines (an LS program's
/// /MN lines are then renumbered, and its LINE_COUNT). File f of p.paths goes to out_paths[f]; a KRL module and
/// an LS program take the name of their output file (the controller ties the two; RAPID does not).
std::vector<OutputFile> write_native_program(const NativeProgram& p, const std::vector<Pose6>& pose,
                                             const std::vector<ControllerTarget>& t, const std::vector<bool>& joints,
                                             const std::vector<std::string>& out_paths,
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
