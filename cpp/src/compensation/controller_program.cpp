#include "kincal/compensation/controller_program.hpp"

#include "kincal/compensation/branch.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/programs.hpp"
#include "kincal/kinematics/kinematics.hpp"

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
    if (kind != TargetKind::Filtered) continue;
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
  return out;
}

ControllerProgramResult compensate_to_controller(const Robot& robot, const std::string& in_path,
                                                 const std::string& out_path, const ProgramOptions& opt,
                                                 const WriterOptions& w) {
  const PoseProgram prog = read_pose_program(in_path);
  std::vector<std::string> where_of;
  where_of.reserve(prog.poses.size());
  for (int l : prog.pose_line) where_of.push_back(where(in_path, l));
  ControllerProgramResult r;
  r.result = compensate_poses(robot, prog.poses, where_of, opt, prog.temperature_c);
  std::vector<OutputFile> files;
  if (w.targets == TargetKind::Joints && (w.format == ControllerFormat::Csv || w.format == ControllerFormat::Gcode)) {
    files.push_back({out_path, format_joint_program(prog, r.result.q_deg,
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
