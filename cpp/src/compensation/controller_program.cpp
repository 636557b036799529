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

// a KRL or RAPID program with its Cartesian targets filtered, every other byte unchanged
ControllerProgramResult compensate_native(const Robot& robot, const std::string& in_path, ControllerFormat in_format,
                                          const std::string& out_path, const ProgramOptions& opt,
                                          const WriterOptions& w, const NativeOptions& n) {
  if (w.format != in_format)
    throw InputError(out_path + ": a " + format_name(in_format) + " program is written back as " +
                     format_name(in_format) + " (not " + format_name(w.format) + ")");
  if (std::isfinite(n.tolerance_mm))
    throw InputError(in_path + ": --tolerance inserts targets into programs kincal writes (from CSV or G-code), "
                     "not yet into a " + std::string(format_name(in_format)) + " program it filters");
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
  const Eigen::Isometry3d base = pose_to_iso(n.program_base), tool = pose_to_iso(n.program_tool);
  std::vector<Pose6> poses;
  std::vector<std::string> where_of;
  for (const NativeTarget& t : p.targets) {
    poses.push_back(iso_to_pose(base * t.frame * pose_to_iso(t.pose) * tool.inverse()));
    where_of.push_back(where(p.paths[static_cast<size_t>(t.file)], t.line));
  }
  const auto warnings = std::move(r.result.warnings);
  r.result = compensate_poses(robot, poses, where_of, opt);
  r.result.warnings.insert(r.result.warnings.begin(), warnings.begin(), warnings.end());
  // joint targets where every motion to the target interpolates in joints; the others filtered, so that
  // LIN / MoveL / L / movel keep their straight line
  std::vector<bool> joints(p.targets.size());
  std::vector<Vec6> q_filtered;
  std::vector<std::string> where_filtered;
  for (size_t k = 0; k < p.targets.size(); ++k) {
    joints[k] = w.targets == TargetKind::Joints && p.targets[k].joint_motion;
    if (!joints[k]) q_filtered.push_back(r.result.q_deg[k]), where_filtered.push_back(where_of[k]);
  }
  auto targets = controller_targets(robot, r.result.q_deg, TargetKind::Joints, in_format, where_of);
  const auto filtered = controller_targets(robot, q_filtered, TargetKind::Filtered, in_format, where_filtered);
  std::vector<Pose6> back(targets.size());
  for (size_t k = 0, f = 0; k < targets.size(); ++k) {
    if (joints[k]) continue;
    targets[k] = filtered[f++];
    back[k] = iso_to_pose((base * p.targets[k].frame).inverse() * pose_to_iso(targets[k].pose) * tool);
  }
  const size_t n_joints = static_cast<size_t>(std::count(joints.begin(), joints.end(), true));
  r.targets_note = std::to_string(n_joints) + " target(s) written as joints, " +
                   std::to_string(targets.size() - n_joints) + " as filtered poses";
  if (w.targets == TargetKind::Joints && n_joints < targets.size())
    r.targets_note += " (targets of linear and circular motions, or named elsewhere in the program, stay Cartesian)";
  const auto files = write_native_program(p, back, targets, joints, out_path);
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
      lines.push_back({l.text, l.insert_at, k});
    } else {
      lines.push_back(l);
    }
  }
  prog.lines = std::move(lines);
}

}  // namespace

ControllerProgramResult compensate_to_controller(const Robot& robot, const std::string& in_path,
                                                 const std::string& out_path, const ProgramOptions& opt,
                                                 const WriterOptions& w, const NativeOptions& native) {
  const ControllerFormat in_format = controller_format_of_path(in_path);
  if (in_format != ControllerFormat::Csv && in_format != ControllerFormat::Gcode)
    return compensate_native(robot, in_path, in_format, out_path, opt, w, native);
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
