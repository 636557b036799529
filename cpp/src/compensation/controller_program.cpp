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
#include <functional>
#include <optional>
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
    t.pose = iso_to_pose(fk(*robot.nominal(), VecQ(q[i] * kDeg)));
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
  for (ControllerTarget& t : out) joints_to_controller(robot.nominal()->spec(), t.q_deg.data(), 6);  // as written
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

std::string motion_where(const NativeProgram& p, const NativeMotion& m) {
  return where(p.paths[static_cast<size_t>(m.file)], m.line);
}

// The motions to compensated targets, in the order of the file, compensated as one path; a straight-line
// motion (LIN, MoveL, L, movel) from the target of the motion just before it is followed and bisected
// until it keeps within tol_mm. Joint motions, arcs, and motions after a target kincal does not know
// (joints as written, computed at run time) are not followed: the program says nothing of their path.
NativePath compensate_native_path(const Robot& robot, const NativeProgram& p, const std::vector<Pose6>& poses,
                                  const std::vector<std::optional<Vec6>>& refs, const ProgramOptions& opt,
                                  double tol_mm) {
  std::vector<Pose6> seq;
  std::vector<std::string> seq_where;
  std::vector<size_t> seq_motion;
  std::vector<PathKind> kinds;
  std::vector<std::optional<Vec6>> seq_refs;
  for (size_t m = 0; m < p.motions.size(); ++m) {
    const NativeMotion& mo = p.motions[m];
    if (mo.target < 0) continue;
    if (!seq.empty())
      kinds.push_back(mo.kind == 'L' && seq_motion.back() + 1 == m && p.motions[m - 1].file == mo.file
                          ? PathKind::NominalLine
                          : PathKind::Unchecked);
    seq.push_back(poses[static_cast<size_t>(mo.target)]);
    seq_refs.push_back(refs[static_cast<size_t>(mo.target)]);
    seq_where.push_back(motion_where(p, mo));
    seq_motion.push_back(m);
  }
  NativePath r;
  r.tol = compensate_with_tolerance(robot, seq, seq_where, opt, {}, tol_mm, kinds, seq_refs);
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
      r.warnings.push_back(motion_where(p, p.motions[m]) + ": this motion's target would be compensated" + buf +
                           " from its first motion's (" + motion_where(p, p.motions[static_cast<size_t>(first[k])]) +
                           ": another branch or direction of motion); the first is written");
    }
  }
  return r;
}

// Per target, the program's base (with its own frame) in the robot's base and its TCP in the model's tool
// frame. Tool n and base n of a motion (NativeTarget::tool, ::frame) are taken from tool 0 and base 0, which
// are --program-tool and --program-base. FANUC LS: with --uframe (--utool) given, every UF (UT) the positions
// use is among them and every one given is used; without, the positions share one UF (UT), in --program-base
// (--program-tool). A linear track (--track) moves the base by its axis value along its direction.
struct TargetFrames {
  std::vector<Eigen::Isometry3d> base, tool;
};
TargetFrames target_frames(const NativeProgram& p, const NativeOptions& n, const std::vector<std::string>& where_of) {
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
  f.tool = frames(n.user_tools, &NativeTarget::utool, n.program_tool, "UT", "--utool", "--program-tool");
  // external axes: a linear track moves the base; any other one that varies is refused at the first motion
  // (in the order of the program) whose target has another value than the program's first
  for (int j = 0; j < 6; ++j) {
    if (n.track.count(j)) continue;
    const double* first = nullptr;
    for (const NativeMotion& m : p.motions) {
      if (m.target < 0) continue;
      const double& e = p.targets[static_cast<size_t>(m.target)].external[static_cast<size_t>(j)];
      if (!std::isfinite(e)) continue;
      if (!first) first = &e;
      if (std::abs(e - *first) > 1e-9) {
        char buf[400];
        std::snprintf(buf, sizeof buf, ": external axis E%d moves (%.6g, was %.6g): a linear track that carries the "
                      "robot takes --track E%d=X,Y,Z (its direction in the program's base frame); a rotary axis "
                      "(a positioner) is not supported", j + 1, e, *first, j + 1);
        throw InputError(motion_where(p, m) + buf);
      }
    }
  }
  // the robot on the track at e: the world (base 0) moves by -e * dir in the robot's base. KRL and RAPID: the
  // world is --program-base, each motion's base in it; LS: the user frame (--uframe, or --program-base) is in
  // the robot's base at e = 0
  const bool ls = p.format == ControllerFormat::FanucLs;
  for (size_t k = 0; k < f.base.size(); ++k) {
    Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
    for (const auto& [j, dir] : n.track) {
      const double e = p.targets[k].external[static_cast<size_t>(j)];
      if (!std::isfinite(e))
        throw InputError(where_of[k] + ": --track E" + std::to_string(j + 1) + ": the target has no value of E" +
                         std::to_string(j + 1));
      shift.translation() -= e * dir;
    }
    f.base[k] = ls ? shift * f.base[k] * p.targets[k].frame : f.base[k] * shift * p.targets[k].frame;
    f.tool[k] = f.tool[k] * p.targets[k].tool;
  }
  return f;
}

// "NAME: " for a declared target, "" for an inline one (its line says which)
std::string named(const NativeTarget& t) { return t.name.empty() ? "" : t.name + ": "; }

// The taught targets' references: the nominal solution of each desired pose on its taught branch (none for
// targets without branch data: they keep the branch nearest the previous joints). A taught branch that does
// not reach the pose is an error, or with allow_branch_change a warning (the nearest branch is then taken).
std::vector<std::optional<Vec6>> taught_references(const Robot& robot, const NativeProgram& p,
                                                   const std::vector<Pose6>& poses,
                                                   const std::vector<std::string>& where_of, const NativeOptions& n,
                                                   std::vector<std::string>& warnings) {
  std::vector<std::optional<Vec6>> refs(p.targets.size());
  if (p.format == ControllerFormat::UrScript) return refs;
  for (size_t k = 0; k < p.targets.size(); ++k) {
    if (!p.targets[k].taught) continue;
    ControllerTarget t = *p.targets[k].taught;
    t.pose = poses[k];
    std::string why;
    refs[k] = select_branch(robot, p.format, t, &why, 1e-4);  // (printed to 1e-4 mm, 1e-6 deg or so)
    if (refs[k]) continue;
    const std::string msg = where_of[k] + ": " + named(p.targets[k]) + "the taught branch (" + branch_text(p.format, t) + ") does not reach the "
                            "target in the nominal model (" + why + ")";
    if (!n.allow_branch_change) throw InputError(msg + "; --allow-branch-change takes the nearest branch");
    warnings.push_back(msg + "; the branch nearest the previous target is taken (--allow-branch-change)");
  }
  return refs;
}

// The compensated joints against each taught target's branch data: another arm, elbow or wrist choice, or another
// turn far from the border, is an error (a warning with allow_branch_change); a joint the compensation moves across
// its border (less than 5 deg from the taught solution) keeps the new turn, reported.
void check_taught_branches(const Robot& robot, const NativeProgram& p, const std::vector<Vec6>& q,
                           const std::vector<std::optional<Vec6>>& refs, const std::vector<std::string>& where_of,
                           const NativeOptions& n, std::vector<std::string>& warnings) {
  for (size_t k = 0; k < p.targets.size(); ++k) {
    if (!refs[k]) continue;
    const ControllerTarget& taught = *p.targets[k].taught;
    const BranchDifference d = branch_difference(robot, p.format, taught, q[k]);
    std::string crossed, changed;
    for (const int j : d.turns) {
      char buf[120];
      std::snprintf(buf, sizeof buf, "%sA%d %.4f deg (taught solution %.4f)", "", j + 1, q[k][j], (*refs[k])[j]);
      std::string& list = std::abs(q[k][j] - (*refs[k])[j]) < 5.0 ? crossed : changed;
      list += (list.empty() ? "" : ", ") + std::string(buf);
    }
    if (!crossed.empty())
      warnings.push_back(where_of[k] + ": " + named(p.targets[k]) + "the compensation moves a joint across its turn's border (" + crossed +
                         "): written with the new turn");
    if (!d.arm && changed.empty()) continue;
    const std::string msg = where_of[k] + ": " + named(p.targets[k]) + "the compensated joints leave the taught branch (" +
                            branch_text(p.format, taught) + (d.arm ? "; another arm, elbow or wrist choice" : "") +
                            (changed.empty() ? "" : "; another turn: " + changed) +
                            "): the calibrated robot cannot reach the target on it within the joint limits";
    if (!n.allow_branch_change) throw InputError(msg + " (--allow-branch-change accepts another branch)");
    warnings.push_back(msg + "; another branch is written (--allow-branch-change)");
  }
}

}  // namespace

// a native program (KRL, RAPID, LS, URScript; several files read as one) with its Cartesian targets compensated,
// as joints or filtered poses, and --tolerance's targets inserted; every other byte unchanged
ControllerProgramResult compensate_native_program(const Robot& robot, const NativeProgram& p,
                                          const std::function<std::string(const std::string&)>& out_of,
                                          const ProgramOptions& opt, const WriterOptions& w, const NativeOptions& n) {
  const ControllerFormat in_format = p.format;
  if (w.format != in_format)
    throw InputError(out_of(p.paths[0]) + ": a " + format_name(in_format) + " program is written back as " +
                     format_name(in_format) + " (not " + format_name(w.format) + ")");
  ControllerProgramResult r;
  if (!p.unresolved.empty()) {
    std::string list;
    for (const auto& u : p.unresolved) list += "\n  " + u.where + ": " + u.why + ": " + u.text;
    if (!n.skip_unresolved)
      throw InputError(p.paths[0] + ": " + std::to_string(p.unresolved.size()) +
                       " motion(s) whose target kincal does not compensate (--skip-unresolved passes them through "
                       "unchanged):" + list);
    for (const auto& u : p.unresolved)
      r.result.warnings.push_back(u.where + ": " + u.why + ", passed through unchanged: " + u.text);
  }
  if (p.targets.empty()) throw InputError(p.paths[0] + ": the program has no Cartesian targets to compensate");
  std::vector<std::string> where_of;
  for (size_t k = 0; k < p.targets.size(); ++k) {
    const NativeTarget& t = p.targets[k];
    where_of.push_back(where(p.paths[static_cast<size_t>(t.file)], t.line));
    if (t.copy_of < 0) continue;
    // a copy (declared on the line after its original, in another tool or base) is named by the motion that uses it
    for (const NativeMotion& m : p.motions)
      if (m.target == static_cast<int>(k)) {
        where_of.back() = motion_where(p, m) + ": " + p.targets[static_cast<size_t>(t.copy_of)].name + " in " +
                          (t.frames_named.empty() ? "tool 0 and base 0" : t.frames_named) + " (written as " + t.name +
                          ", declared after " + where_of.back() + ")";
        break;
      }
  }
  const TargetFrames frames = target_frames(p, n, where_of);
  std::vector<Pose6> poses;
  for (size_t k = 0; k < p.targets.size(); ++k)
    poses.push_back(iso_to_pose(frames.base[k] * pose_to_iso(p.targets[k].pose) * frames.tool[k].inverse()));
  auto warnings = std::move(r.result.warnings);
  const auto refs = taught_references(robot, p, poses, where_of, n, warnings);
  std::vector<Vec6> q_of;  // per target, its compensated joints
  std::vector<InsertedTarget> inserted;
  if (std::isfinite(n.tolerance_mm)) {
    for (size_t k = 1; k < p.targets.size(); ++k)
      if (!frames.tool[k].isApprox(frames.tool[0], 1e-12))
        throw InputError(where_of[k] + ": --tolerance follows the path of one tool; " + p.targets[k].name +
                         " is in another tool than " + p.targets[0].name);
    NativePath path = compensate_native_path(robot, p, poses, refs, opt, n.tolerance_mm);
    r.result = std::move(path.tol.result);
    r.path_before_mm = path.tol.before_mm, r.path_after_mm = path.tol.after_mm, r.inserted = path.tol.inserted;
    q_of = std::move(path.q_of);
    r.result.warnings.insert(r.result.warnings.end(), path.warnings.begin(), path.warnings.end());
    // the inserted targets filtered (they precede straight-line motions), in the frame of the motion's target
    std::vector<std::string> where_ins;
    for (const size_t m : path.inserted_before) where_ins.push_back(motion_where(p, p.motions[m]));
    const auto ins = controller_targets(robot, path.q_inserted, TargetKind::Filtered, in_format, where_ins);
    for (size_t j = 0; j < ins.size(); ++j) {
      const size_t t = static_cast<size_t>(p.motions[path.inserted_before[j]].target);
      inserted.push_back({path.inserted_before[j],
                          iso_to_pose(frames.base[t].inverse() * pose_to_iso(ins[j].pose) * frames.tool[t]), ins[j]});
    }
  } else {
    r.result = compensate_poses(robot, poses, where_of, opt, {}, refs);
    q_of = r.result.q_deg;
  }
  // the compensation's own notes of a taught target off its branch are replaced by the check's
  std::vector<std::string> kept;
  for (auto& m : r.result.warnings)
    if (m.find(": off the taught branch: ") == std::string::npos) kept.push_back(std::move(m));
  r.result.warnings = std::move(kept);
  check_taught_branches(robot, p, q_of, refs, where_of, n, r.result.warnings);
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
  std::vector<std::string> outs;
  for (const std::string& path : p.paths) outs.push_back(out_of(path));
  const auto files = write_native_program(p, back, targets, joints, outs, inserted);
  write_files_atomic(files);
  for (const auto& f : files) r.files.push_back(f.path);
  return r;
}

namespace {

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

void add_track_axis(std::map<int, Vec3>& track, const std::string& text) {
  static const std::regex form(R"(\s*[Ee]([1-6])\s*=\s*([^,]+),([^,]+),([^,]+))");
  std::smatch m;
  const auto bad = [&](const std::string& cause) {
    return InputError("--track " + text + ": " + cause + " (expected AXIS=X,Y,Z: E1..E6 and the direction, mm per mm, "
                      "in which one unit of the axis moves the robot's base in the program's base frame)");
  };
  if (!std::regex_match(text, m, form)) throw bad("not E<n>=X,Y,Z");
  Vec3 d;
  for (int k = 0; k < 3; ++k) {
    char* end = nullptr;
    const std::string item = m[k + 2].str();
    d[k] = std::strtod(item.c_str(), &end);
    while (end && (*end == ' ' || *end == '\t')) ++end;
    if (end == item.c_str() || *end != '\0' || !std::isfinite(d[k])) throw bad("'" + item + "' is not a number");
  }
  if (d.norm() == 0) throw bad("a zero direction");
  if (!track.emplace(std::stoi(m[1]) - 1, d).second) throw bad("E" + m[1].str() + " given twice");
}

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
  if (in_format != ControllerFormat::Csv && in_format != ControllerFormat::Gcode) {
    const NativeProgram p = read_native_program(in_path, in_format, native.context ? *native.context : Declarations());
    // the program's own files beside out_path (KRL: its .dat); a file of --declarations it writes to beside it too
    const auto out_of = [&](const std::string& path) {
      if (path == p.paths[0]) return out_path;
      const auto dat = [](const std::string& x) {  // the extension of the file's name (not of a folder's) to .dat
        const size_t slash = x.find_last_of('/'), dot = x.find_last_of('.');
        return (dot == std::string::npos || (slash != std::string::npos && dot < slash) ? x : x.substr(0, dot)) + ".dat";
      };
      if (in_format == ControllerFormat::Krl && p.paths.size() > 1 && path == p.paths[1] &&
          upper_case(path) == upper_case(dat(p.paths[0])))
        return dat(out_path);
      const size_t slash = out_path.find_last_of('/');
      const std::string name = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
      return (slash == std::string::npos ? std::string() : out_path.substr(0, slash + 1)) + name;
    };
    return compensate_native_program(robot, p, out_of, opt, w, native);
  }
  // a pose program's poses are in the robot's base frame and for the model's tool (or the
  // instrument's frame: --frame instrument); a frame option would be silently ignored
  const auto given = [](const Pose6& p) { return !p.xyz.isZero(0.0) || !p.abc.isZero(0.0); };
  if (given(native.program_base) || given(native.program_tool))
    throw InputError(in_path + ": --program-base and --program-tool give a native program's frames (KRL, RAPID, LS, "
                     "URScript); a CSV or G-code program's poses are in the robot's base frame (or the instrument's, "
                     "--frame instrument) for the model's tool");
  const bool joint_file = w.targets == TargetKind::Joints &&
                          (w.format == ControllerFormat::Csv || w.format == ControllerFormat::Gcode);
  if (joint_file && !std::isfinite(native.tolerance_mm)) {  // pose after pose, in bounded memory
    ControllerProgramResult r;
    r.result = compensate_program_file(robot, in_path, out_path, opt,
                                       w.format == ControllerFormat::Csv ? ProgramFormat::Csv : ProgramFormat::Gcode);
    r.files.push_back(out_path);
    return r;
  }
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
  if (joint_file) {
    std::vector<Vec6> qc = r.result.q_deg;  // the controller's numbers
    for (Vec6& q : qc) joints_to_controller(robot.nominal()->spec(), q.data(), 6);
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
