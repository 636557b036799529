// kincal: a program file compensated in bounded memory: read in chunks of whole lines, the joint
// program written as it goes (compensation/program.hpp, compensate_program_file).
#include "kincal/compensation/program.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/gcode.hpp"
#include "kincal/io/programs.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/coverage.hpp"
#include "kincal/model/joint_convention.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace kincal {

namespace {

// The joint program of a pose program written line by line, as format_joint_program writes it whole:
// CSV (q1..q6), or G-code (a G-code input's lines with the joint words in place of the pose words, each
// with its own end; "G1 A1=.." lines for a CSV input). A line that does not fit is the error of the
// output (thrown by finish(), after every error of the program, as when the output was written whole).
class JointProgramOutput {
 public:
  JointProgramOutput(AtomicFileWriter& w, ProgramFormat in, ProgramFormat out) : w_(w), in_(in), out_(out) {
    if (out_ == ProgramFormat::Csv) w_.write("q1,q2,q3,q4,q5,q6\n", 18);
  }
  void line(const ProgramLine& l, const Vec6& q_controller) {
    if (!error_.empty()) return;
    try {
      if (out_ == ProgramFormat::Csv) {
        if (!l.has_pose) return;
        char buf[512];
        w_.write(buf, format_joints(buf, sizeof buf, q_controller, ProgramFormat::Csv));
        w_.write("\n", 1);
      } else if (in_ != ProgramFormat::Gcode) {
        char buf[512];
        w_.write("G1 ", 3);
        w_.write(buf, format_joints(buf, sizeof buf, q_controller, ProgramFormat::Gcode));
        w_.write("\n", 1);
      } else {
        if (l.has_pose) {
          char buf[8192];
          w_.write(buf, emit_gcode_line(l.text.data(), l.text.size(), l.insert_at, q_controller, buf, sizeof buf));
        } else {
          w_.write(l.text);
        }
        w_.write(l.eol);
      }
    } catch (const InputError& e) {
      error_ = e.what();
    }
  }
  void finish() {
    if (!error_.empty()) throw InputError(error_);
    w_.commit();
  }

 private:
  AtomicFileWriter& w_;
  ProgramFormat in_, out_;
  std::string error_;
};

// The program in memory, as it was compensated before it was read in chunks: for a file that cannot be
// read twice (a pipe).
ProgramResult compensate_program_whole(const Robot& robot, const std::string& in_path, const std::string& out_path,
                                       const ProgramOptions& opt, ProgramFormat format) {
  const PoseProgram prog = read_pose_program(in_path);
  std::vector<std::string> where_of;
  where_of.reserve(prog.poses.size());
  for (int l : prog.pose_line) where_of.push_back(where(in_path, l));
  const ProgramResult res = compensate_poses(robot, prog.poses, where_of, opt, prog.temperature_c);
  std::vector<Vec6> qc = res.q_deg;  // the controller's numbers
  for (Vec6& q : qc) joints_to_controller(robot.nominal()->spec(), q.data(), 6);
  write_file_atomic(out_path, format_joint_program(prog, qc, format));
  return res;
}

struct ProgramFile {  // a pose program file and how it is compensated
  const Robot& robot;
  const ProgramOptions& opt;
  const std::string& in_path;
  bool needs_dir, needs_t;
  std::vector<Extrapolation> periodic;  // the joints whose periodic effects were fitted on a range of angles
};

// One pass over the file, pose after pose from the directions dir0: into out when given; first_motion:
// the direction of each joint's first motion (motion_directions' first row). An error of a pose (its
// temperature missing, its compensation failing) waits for the rest of the file, whose broken lines
// come first, as when the program was read before it was compensated.
ProgramResult program_pass(const ProgramFile& f, const Vec6& dir0, JointProgramOutput* out, Vec6* first_motion) {
  PoseProgramReader rd(f.in_path, f.opt.chunk_bytes);
  ProgramResult res;
  ProgramCursor cur(f.robot, f.opt, dir0);
  std::string pending;  // the first error of the compensation
  bool pending_temperature = false;
  std::vector<Extrapolation> outside = f.periodic;
  std::vector<int> outside_line(f.periodic.size(), 0);
  Vec6 prev = Vec6::Zero();
  bool moved[6] = {false, false, false, false, false, false};
  if (first_motion) first_motion->setOnes();
  ProgramLine l;
  while (rd.next(l)) {
    if (!l.has_pose) {
      if (out && pending.empty()) out->line(l, prev);
      continue;
    }
    const double t = std::isfinite(l.temperature_c) ? l.temperature_c : f.opt.temperature_c;
    if (f.needs_t && !std::isfinite(t)) {  // (compensate_poses checks every pose before the first is solved)
      if (!pending_temperature) pending = where(f.in_path, l.line) + ": " + kNeedsTemperature;
      pending_temperature = true;
      continue;
    }
    if (!pending.empty()) continue;
    cur.ctx.temperature_c = t;
    cur.reference.reset();
    PoseSolution s;
    try {
      s = next_pose(f.robot, f.opt, l.pose, cur);
    } catch (const InputError& e) {
      pending = e.what();
      continue;
    }
    if (!s.ok()) {
      pending = where(f.in_path, l.line) + ": " + s.error;
      continue;
    }
    if (s.branch_changed()) {
      const std::string w = where(f.in_path, l.line) + ": " + branch_change_message(s.error);
      if (f.opt.keep_branch) {
        pending = w + " (--keep-branch)";
        continue;
      }
      res.warnings.push_back(w);
    }
    if (f.opt.keep_poses && out) {
      res.q_deg.push_back(s.q_deg);
      res.dir.push_back(f.needs_dir ? Vec6(cur.ctx.dir) : Vec6::Zero());
      res.iterations.push_back(s.iterations);
      res.residual.push_back(s.residual);
    }
    for (size_t k = 0; k < outside.size(); ++k) {
      Extrapolation& e = outside[k];
      if (!outside_range(s.q_deg[e.joint - 1], e.fitted)) continue;
      if (e.rows == 0) e.first = res.poses, outside_line[k] = l.line;
      ++e.rows;
    }
    if (first_motion && res.poses > 0)
      for (int j = 0; j < 6; ++j) {
        const double delta = s.q_deg[j] - prev[j];
        if (!moved[j] && std::abs(delta) > kStillDeg) (*first_motion)[j] = delta > 0 ? 1.0 : -1.0, moved[j] = true;
      }
    count_pose(res, s);
    prev = s.q_deg;
    if (out) {
      Vec6 qc = s.q_deg;  // the controller's numbers
      joints_to_controller(f.robot.nominal()->spec(), qc.data(), 6);
      out->line(l, qc);
    }
  }
  if (!pending.empty()) throw InputError(pending);
  // the poses that take a joint's periodic effects outside the angles they were fitted on
  for (size_t k = 0; k < outside.size(); ++k)
    if (outside[k].rows > 0)
      res.warnings.push_back(where(f.in_path, outside_line[k]) + ": " +
                             extrapolation_message(outside[k], res.poses, "poses compensated"));
  return res;
}

}  // namespace

ProgramResult compensate_program_file(const Robot& robot, const std::string& in_path, const std::string& out_path,
                                      const ProgramOptions& opt, std::optional<ProgramFormat> out_format) {
  const ProgramFormat format = out_format ? *out_format : program_format(out_path);
  if (!is_regular_file(in_path)) return compensate_program_whole(robot, in_path, out_path, opt, format);
  const Model& cal = *robot.calibrated();
  const bool needs_dir = opt.compensate && cal.needs_dir();
  const bool needs_t = opt.compensate && cal.needs_temperature();
  // the joints whose periodic effects were fitted on a range of angles (compensate_poses' warnings)
  std::vector<Extrapolation> periodic;
  if (opt.compensate)
    for (const Extrapolation& e : periodic_joints(cal.spec(), robot.campaign().fitted_deg))
      if (e.joint <= 6) periodic.push_back(e);
  const ProgramFile f{robot, opt, in_path, needs_dir, needs_t, std::move(periodic)};
  auto write = [&](const Vec6& dir0) {
    AtomicFileWriter file(out_path, opt.chunk_bytes);
    JointProgramOutput out(file, program_format(in_path), format);
    ProgramResult res = program_pass(f, dir0, &out, nullptr);
    out.finish();
    return res;
  };
  if (!needs_dir) return write(Vec6::Ones());
  if (opt.initial_direction.empty()) {
    // the direction of the first motion: from a first pass that assumes +1, then the program again
    Vec6 first;
    program_pass(f, Vec6::Ones(), nullptr, &first);
    return write(first);
  }
  Vec6 dir0;
  try {
    dir0 = initial_directions(opt.initial_direction);
  } catch (const InputError&) {  // after the program's own errors (compensate_poses reads it first)
    PoseProgramReader rd(in_path, opt.chunk_bytes);
    for (ProgramLine l; rd.next(l);)
      if (l.has_pose && needs_t && !std::isfinite(l.temperature_c) && !std::isfinite(opt.temperature_c))
        throw InputError(where(in_path, l.line) + ": " + kNeedsTemperature);
    throw;
  }
  return write(dir0);
}

}  // namespace kincal
