#include "kincal/compensation/controller_program.hpp"

#include "kincal/compensation/branch.hpp"
#include "kincal/compensation/tolerance.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"
#include "kincal/io/programs.hpp"
#include "kincal/model/joint_convention.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <set>

namespace kincal {

std::vector<ControllerTarget> controller_targets(const Robot& robot, const std::vector<Vec6>& q, TargetKind kind,
                                                 ControllerFormat format, const std::vector<std::string>& where) {
  std::vector<ControllerTarget> out(q.size());
  const bool branches = format == ControllerFormat::Krl || format == ControllerFormat::Rapid ||
                        format == ControllerFormat::FanucLs;
  for (size_t i = 0; i < q.size(); ++i) {
    ControllerTarget& t = out[i];
    t.q_deg = q[i];
    if (kind != TargetKind::Filtered) continue;  // (the model's angles until the end)
    t.pose = iso_to_pose(fk(*robot.nominal, VecQ(q[i] * kDeg)));
    if (!branches) continue;
    set_branch_data(robot, t);
    std::string why;
    const auto back = select_branch(robot, format, t, &why);
    const std::string at = i < where.size() ? where[i] : "target " + std::to_string(i + 1);
    if (!back) throw InputError(at + ": the filtered target's branch data does not fix the joints (" + why + ")");
    const double d = (*back - q[i]).cwiseAbs().maxCoeff();
    if (d > 1e-6) {
      char buf[160];
      std::snprintf(buf, sizeof buf, ": the controller's nominal model would reach the filtered target %.3g deg away "
                    "from the compensated joints (near a singularity?)", d);
      throw InputError(at + buf);
    }
  }
  for (ControllerTarget& t : out) joints_to_controller(robot.nominal->spec(), t.q_deg.data(), 6);  // as written
  return out;
}

namespace {

// --tolerance on a native program: its motions' path in the order of the file
struct NativePath {
  ToleranceResult tol;
  std::vector<Vec6> q_of;                 // per target: the joints of its first motion
  std::vector<size_t> inserted_before;    // per inserted target: the motion it precedes
  std::vector<Vec6> q_inserted;
  std::vector<std::string> warnings;
};

// The motions to compensated targets, in the order of the file, compensated as one path; a straight-line
// motion (LIN, MoveL, L, movel) from the target of the motion just before it is followed and bisected
// until it keeps within tol_mm. Joint motions, arcs, and motions after a target kincal does not know
// (joints as written, computed at run time) are not followed: the program says nothing of their path.
NativePath compensate_native_path(const Robot& robot, const NativeProgram& p, const std::vector<Pose6>& poses,
                                  const ProgramOptions& opt, double tol_mm) {
  std::vector<Pose6> seq;
  std::vector<std::string> seq_where;
  std::vector<size_t> seq_motion;
  std::vector<PathKind> kinds;
  for (size_t m = 0; m < p.motions.size(); ++m) {
    const NativeMotion& mo = p.motions[m];
    if (mo.target < 0) continue;
    if (!seq.empty())
      kinds.push_back(mo.kind == 'L' && seq_motion.back() + 1 == m ? PathKind::NominalLine : PathKind::Unchecked);
    seq.push_back(poses[static_cast<size_t>(mo.target)]);
    seq_where.push_back(where(p.paths[0], mo.line));
    seq_motion.push_back(m);
  }
  NativePath r;
  r.tol = compensate_with_tolerance(robot, seq, seq_where, opt, {}, tol_mm, kinds);
  r.q_of.assign(p.targets.size(), Vec6::Zero());
  std::vector<int> first(p.targets.size(), -1);  // per target: its first motion
  std::vector<size_t> pending;                   // inserted poses before the next motion
  for (size_t j = 0; j < r.tol.poses.size(); ++j) {
    if (r.tol.original[j] < 0) {
      pending.push_back(j);
      continue;
    }
    const size_t m = seq_motion[static_cast<size_t>(r.tol.original[j])];
    for (const size_t i : pending) r.inserted_before.push_back(m), r.q_inserted.push_back(r.tol.result.q_deg[i]);
    pending.clear();
    const size_t k = static_cast<size_t>(p.motions[m].target);
    const Vec6& q = r.tol.result.q_deg[j];
    if (first[k] < 0) {
      first[k] = static_cast<int>(m);
      r.q_of[k] = q;
    } else if ((q - r.q_of[k]).cwiseAbs().maxCoeff() > 1e-6) {
      char buf[96];
      std::snprintf(buf, sizeof buf, " %.3g deg away", (q - r.q_of[k]).cwiseAbs().maxCoeff());
      r.warnings.push_back(where(p.paths[0], p.motions[m].line) + ": this motion's target would be compensated" + buf +
                           " from its first motion's (" + where(p.paths[0], p.motions[static_cast<size_t>(first[k])].line) +
                           ": another branch or direction of motion); the first is written");
    }
  }
  return r;
}

// Per target, the program's base (with its own frame) in the robot's base and its TCP in the model's tool
// frame. FANUC LS: with --uframe (--utool) given, every UF (UT) the positions use is among them and every
// one given is used; without, the positions share one UF (UT), in --program-base (--program-tool).
struct TargetFrames {
  std::vector<Eigen::Isometry3d> base, tool;
};
TargetFrames target_frames(const NativeProgram& p, const NativeOptions& n) {
  const auto frames = [&](const std::map<int, Pose6>& given, int NativeTarget::*number, const Pose6& one,
                          const std::string& what, const std::string& option, const std::string& single) {
    if (!given.empty() && !(one.xyz.isZero() && one.abc.isZero()))
      throw InputError(option + " and " + single + " together: give the frame of each " + what + " with " + option);
    std::vector<Eigen::Isometry3d> out;
    std::set<int> used;
    const NativeTarget& first = p.targets[0];
    for (const NativeTarget& t : p.targets) {
      used.insert(t.*number);
      const auto it = given.find(t.*number);
      if (it != given.end()) {
        out.push_back(pose_to_iso(it->second));
        continue;
      }
      const std::string at = where(p.paths[static_cast<size_t>(t.file)], t.line) + ": " + t.name + " is in " + what +
                             " " + std::to_string(t.*number);
      if (!given.empty()) throw InputError(at + ", which no " + option + " gives");
      if (t.*number != first.*number)
        throw InputError(at + ", " + first.name + " in " + what + " " + std::to_string(first.*number) +
                         ": with several, give each with " + option + " N=X,Y,Z,A,B,C");
      out.push_back(pose_to_iso(one));
    }
    for (const auto& g : given)
      if (!used.count(g.first))
        throw InputError(p.paths[0] + ": " + option + " " + std::to_string(g.first) + ": no position is in " + what +
                         " " + std::to_string(g.first));
    return out;
  };
  TargetFrames f;
  f.base = frames(n.user_frames, &NativeTarget::uframe, n.program_base, "UF", "--uframe", "--program-base");
  for (size_t k = 0; k < f.base.size(); ++k) f.base[k] = f.base[k] * p.targets[k].frame;
  f.tool = frames(n.user_tools, &NativeTarget::utool, n.program_tool, "UT", "--utool", "--program-tool");
  return f;
}

// a native program (KRL, RAPID, LS, URScript) with its Cartesian targets compensated, as joints or filtered
// poses, and --tolerance's targets inserted; every other byte unchanged
ControllerProgramResult compensate_native(const Robot& robot, const std::string& in_path, ControllerFormat in_format,
                                          const std::string& out_path, const ProgramOptions& opt,
                                          const WriterOptions& w, const NativeOptions& n) {
  if (w.format != in_format)
    throw InputError(out_path + ": a " + format_name(in_format) + " program is written back as " +
                     format_name(in_format) + " (not " + format_name(w.format) + ")");
  const NativeProgram p = read_native_program(in_path, in_format);
  ControllerProgramResult r;
  if (!p.unresolved.empty()) {
    std::string list;
    for (const auto& u : p.unresolved) list += "\n  " + u.where + ": target computed at run time: " + u.text;
    if (!n.skip_unresolved)
      throw InputError(in_path + ": " + std::to_string(p.unresolved.size()) +
                       " target(s) computed at run time (--skip-unresolved passes them through):" + list);
    for (const auto& u : p.unresolved)
      r.result.warnings.push_back(u.where + ": target computed at run time, passed through unchanged: " + u.text);
  }
  if (p.targets.empty()) throw InputError(in_path + ": the program has no Cartesian targets to compensate");
  const TargetFrames frames = target_frames(p, n);
  std::vector<Pose6> poses;
  std::vector<std::string> where_of;
  for (size_t k = 0; k < p.targets.size(); ++k) {
    const NativeTarget& t = p.targets[k];
    poses.push_back(iso_to_pose(frames.base[k] * pose_to_iso(t.pose) * frames.tool[k].inverse()));
    where_of.push_back(where(p.paths[static_cast<size_t>(t.file)], t.line));
  }
  const auto warnings = std::move(r.result.warnings);
  std::vector<Vec6> q_of;  // per target, its compensated joints
  std::vector<InsertedTarget> inserted;
  if (std::isfinite(n.tolerance_mm)) {
    for (size_t k = 1; k < p.targets.size(); ++k)
      if (p.targets[k].utool != p.targets[0].utool)
        throw InputError(where_of[k] + ": --tolerance follows the path of one tool; " + p.targets[k].name + " is in UT " +
                         std::to_string(p.targets[k].utool) + ", " + p.targets[0].name + " in UT " +
                         std::to_string(p.targets[0].utool));
    NativePath path = compensate_native_path(robot, p, poses, opt, n.tolerance_mm);
    r.result = std::move(path.tol.result);
    r.path_before_mm = path.tol.before_mm, r.path_after_mm = path.tol.after_mm, r.inserted = path.tol.inserted;
    q_of = std::move(path.q_of);
    r.result.warnings.insert(r.result.warnings.end(), path.warnings.begin(), path.warnings.end());
    // the inserted targets filtered (they precede straight-line motions), in the frame of the motion's target
    std::vector<std::string> where_ins;
    for (const size_t m : path.inserted_before) where_ins.push_back(where(p.paths[0], p.motions[m].line));
    const auto ins = controller_targets(robot, path.q_inserted, TargetKind::Filtered, in_format, where_ins);
    for (size_t j = 0; j < ins.size(); ++j) {
      const size_t t = static_cast<size_t>(p.motions[path.inserted_before[j]].target);
      inserted.push_back({path.inserted_before[j],
                          iso_to_pose(frames.base[t].inverse() * pose_to_iso(ins[j].pose) * frames.tool[t]), ins[j]});
    }
  } else {
    r.result = compensate_poses(robot, poses, where_of, opt);
    q_of = r.result.q_deg;
  }
  r.result.warnings.insert(r.result.warnings.begin(), warnings.begin(), warnings.end());
  // joint targets where every motion to the target interpolates in joints; the others filtered, so that
  // LIN / MoveL / L / movel keep their straight line
  std::vector<bool> joints(p.targets.size());
  std::vector<Vec6> q_filtered;
  std::vector<std::string> where_filtered;
  for (size_t k = 0; k < p.targets.size(); ++k) {
    joints[k] = w.targets == TargetKind::Joints && p.targets[k].joint_motion;
    if (!joints[k]) q_filtered.push_back(q_of[k]), where_filtered.push_back(where_of[k]);
  }
  auto targets = controller_targets(robot, q_of, TargetKind::Joints, in_format, where_of);
  const auto filtered = controller_targets(robot, q_filtered, TargetKind::Filtered, in_format, where_filtered);
  std::vector<Pose6> back(targets.size());
  for (size_t k = 0, f = 0; k < targets.size(); ++k) {
    if (joints[k]) continue;
    targets[k] = filtered[f++];
    back[k] = iso_to_pose(frames.base[k].inverse() * pose_to_iso(targets[k].pose) * frames.tool[k]);
  }
  const size_t n_joints = static_cast<size_t>(std::count(joints.begin(), joints.end(), true));
  r.targets_note = std::to_string(n_joints) + " target(s) written as joints, " +
                   std::to_string(targets.size() - n_joints) + " as filtered poses";
  if (w.targets == TargetKind::Joints && n_joints < targets.size())
    r.targets_note += " (targets of linear and circular motions, or named elsewhere in the program, stay Cartesian)";
  const auto files = write_native_program(p, back, targets, joints, out_path, inserted);
  write_files_atomic(files);
  for (const auto& f : files) r.files.push_back(f.path);
  return r;
}

// A G-code program's lines with a "G1 " motion line before each pose for every target --tolerance
// inserted before it; the pose indices renumbered to the refined program's (original: per refined
// pose, its input index or -1).
void with_inserted_targets(PoseProgram& prog, const std::vector<int>& original) {
  std::vector<int> refined_of(prog.poses.size(), -1);
  for (size_t k = 0; k < original.size(); ++k)
    if (original[k] >= 0) refined_of[static_cast<size_t>(original[k])] = static_cast<int>(k);
  std::vector<PoseProgram::Line> lines;
  int next = 0;  // the first refined pose not yet on a line
  for (const PoseProgram::Line& l : prog.lines) {
    if (l.pose >= 0) {
      const int k = refined_of[static_cast<size_t>(l.pose)];
      for (; next < k; ++next) lines.push_back({"G1 ", 3, next});
      next = k + 1;
      lines.push_back({l.text, l.insert_at, k, l.eol});
    } else {
      lines.push_back(l);
    }
  }
  prog.lines = std::move(lines);
}

}  // namespace

void add_numbered_frame(std::map<int, Pose6>& frames, const std::string& text, const std::string& option) {
  static const std::regex form(R"((\d{1,2})=(.*))"), number(R"([+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?)");
  const auto bad = [&](const std::string& cause) {
    return InputError(option + " " + text + ": " + cause + " (expected N=X,Y,Z,A,B,C: the frame's number 0..99, mm and deg)");
  };
  std::smatch m;
  if (!std::regex_match(text, m, form)) throw bad("not N=..");
  std::vector<double> v;
  const std::string values = m[2];
  for (size_t at = 0;;) {
    const size_t comma = std::min(values.find(',', at), values.size());
    const std::string item = values.substr(at, comma - at);
    v.push_back(std::regex_match(item, number) ? std::strtod(item.c_str(), nullptr) : HUGE_VAL);
    if (!std::isfinite(v.back())) throw bad("'" + item + "' is not a number");
    if (comma == values.size()) break;
    at = comma + 1;
  }
  if (v.size() != 6) throw bad(std::to_string(v.size()) + " numbers");
  const int n = std::stoi(m[1]);
  if (!frames.emplace(n, Pose6{Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5])}).second)
    throw bad("frame " + std::to_string(n) + " given twice");
}

ControllerProgramResult compensate_to_controller(const Robot& robot, const std::string& in_path,
                                                 const std::string& out_path, const ProgramOptions& opt,
                                                 const WriterOptions& w, const NativeOptions& native) {
  const ControllerFormat in_format = controller_format_of_path(in_path);
  if ((!native.user_frames.empty() || !native.user_tools.empty()) && in_format != ControllerFormat::FanucLs)
    throw InputError(in_path + ": --uframe and --utool apply to FANUC LS programs (the others: --program-base, "
                     "--program-tool)");
  if (in_format != ControllerFormat::Csv && in_format != ControllerFormat::Gcode)
    return compensate_native(robot, in_path, in_format, out_path, opt, w, native);
  // a pose program's poses are in the robot's base frame and for the model's tool (or the
  // instrument's frame: --frame instrument); a frame option would be silently ignored
  const auto given = [](const Pose6& p) { return !p.xyz.isZero(0.0) || !p.abc.isZero(0.0); };
  if (given(native.program_base) || given(native.program_tool))
    throw InputError(in_path + ": --program-base and --program-tool give a native program's frames (KRL, RAPID, LS, "
                     "URScript); a CSV or G-code program's poses are in the robot's base frame (or the instrument's, "
                     "--frame instrument) for the model's tool");
  PoseProgram prog = read_pose_program(in_path);
  std::vector<std::string> where_of;
  where_of.reserve(prog.poses.size());
  for (int l : prog.pose_line) where_of.push_back(where(in_path, l));
  ControllerProgramResult r;
  if (std::isfinite(native.tolerance_mm)) {
    ToleranceResult t = compensate_with_tolerance(robot, prog.poses, where_of, opt, prog.temperature_c,
                                                  native.tolerance_mm,
                                                  w.targets == TargetKind::Joints ? PathKind::Joint : PathKind::NominalLine);
    r.result = std::move(t.result);
    r.path_before_mm = t.before_mm, r.path_after_mm = t.after_mm, r.inserted = t.inserted;
    where_of = std::move(t.where);
    with_inserted_targets(prog, t.original);
  } else {
    r.result = compensate_poses(robot, prog.poses, where_of, opt, prog.temperature_c);
  }
  std::vector<OutputFile> files;
  if (w.targets == TargetKind::Joints && (w.format == ControllerFormat::Csv || w.format == ControllerFormat::Gcode)) {
    std::vector<Vec6> qc = r.result.q_deg;  // the controller's numbers
    for (Vec6& q : qc) joints_to_controller(robot.nominal->spec(), q.data(), 6);
    files.push_back({out_path, format_joint_program(prog, qc,
                                                    w.format == ControllerFormat::Csv ? ProgramFormat::Csv
                                                                                      : ProgramFormat::Gcode)});
  } else {
    files = write_controller_program(out_path, controller_targets(robot, r.result.q_deg, w.targets, w.format, where_of), w);
  }
  write_files_atomic(files);
  for (const auto& f : files) r.files.push_back(f.path);
  return r;
}

}  // namespace kincal
