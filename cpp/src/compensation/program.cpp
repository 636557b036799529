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

PoseSolution failed(const char* cause) {
  PoseSolution s;
  s.error = cause;
  return s;
}

// The limit a compensated solution violates, as a message; empty when inside the limits.
std::string limit_violation(const Model& m, const Vec6& q) {
  if (m.within_limits_deg(q)) return {};
  for (int j = 0; j < 6; ++j) {
    const auto& js = m.spec().joints[j];
    if (q[j] < js.lower_deg - 1e-9 || q[j] > js.upper_deg + 1e-9) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "compensated q%d = %.4f deg is outside its limits [%g, %g]", j + 1, q[j],
                    js.lower_deg, js.upper_deg);
      return buf;
    }
  }
  return "outside the joint limits";
}

// A converged compensation inside the limits is the answer; otherwise the error says why not.
PoseSolution accept(const Model& m, const CompensationResult& r) {
  PoseSolution s;
  if (r.status != CompStatus::Converged) {
    char buf[160];
    std::snprintf(buf, sizeof buf, " (after %d iterations, |F| = %.3g)", r.iterations, r.residual);
    s.error = std::string("compensation failed: ") + to_string(r.status) + buf;
    return s;
  }
  s.error = limit_violation(m, r.q_deg);
  if (!s.error.empty()) return s;
  s.status = PoseStatus::Solved;
  s.q_deg = r.q_deg;
  s.iterations = r.iterations;
  s.residual = r.residual;
  return s;
}

// Newton on the calibrated model from one nominal IK solution q0 (corrected once, by default);
// approximate_start: q0 only comes near the target (beyond the nominal reach).
PoseSolution compensate_from(const Robot& robot, const ProgramOptions& opt, const Pose6& pose,
                             const Eigen::Isometry3d& target, Vec6 q0, bool approximate_start,
                             const EffectContext& ctx) {
  const Model& nom = *robot.nominal();
  const Model& cal = *robot.calibrated();
  if (opt.corrected_start && robot.identified()) {
    // one fixed-point step: the nominal IK of the target corrected by the model difference at q0,
    // e = FK_nom(q0)^-1 FK_cal(q0), where FK_nom(q0) is the target itself unless q0 only came near it
    const VecQ a = q0 * kDeg;
    const Eigen::Isometry3d at_q0 = approximate_start ? fk(nom, a) : target;
    const Eigen::Isometry3d e = at_q0.inverse() * fk_model(cal, a, ctx);
    const IkSolutions s2 = robot.ik().solve(target * e.inverse(), IkOptions(q0, Branches::NearestReference));
    const int k2 = s2.nearest(q0.data());
    if (k2 >= 0) q0 = s2.sol[k2].q_deg;
  }
  const CompensationResult r = compensate(cal, pose, q0, opt.comp, ctx);
  if (r.status != CompStatus::Converged && approximate_start)
    return failed("pose out of reach of the robot (beyond the nominal reach, and the model does not reach it either)");
  return accept(cal, r);
}

// Robots with a closed-form IK: the nominal IK start (nearest ref) and Newton; the other branches,
// nearest first, when the nearest one's compensated solution is not inside the limits.
PoseSolution solve_closed_form(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Vec6& ref,
                               const EffectContext& ctx) {
  const IkSolver& ik = robot.ik();
  const Eigen::Isometry3d target = pose_to_iso(pose);
  // the branch nearest the reference first; all branches when it is out of limits
  IkSolutions s = ik.solve(target, IkOptions(ref, Branches::NearestReference));
  bool all = false;
  if (s.status != IkStatus::Ok || !s.sol[0].within_limits) s = ik.solve(target, IkOptions(ref)), all = true;
  // a calibrated robot may reach a little beyond the nominal one: start from the nearest
  if (s.status != IkStatus::Ok && opt.compensate)
    s = ik.solve(target, IkOptions(ref, Branches::All, OutOfReach::Nearest)), all = true;
  if (s.status != IkStatus::Ok) return failed("pose out of reach of the robot (no inverse-kinematics solution)");
  const int k = s.nearest(ref.data());
  if (!opt.compensate) {
    if (k < 0) return failed("no inverse-kinematics solution within the joint limits");
    PoseSolution sol;
    sol.status = PoseStatus::Solved;
    sol.q_deg = s.sol[k].q_deg;
    return sol;
  }
  PoseSolution nearest;
  if (k >= 0) {
    nearest = compensate_from(robot, opt, pose, target, s.sol[k].q_deg, s.sol[k].approximate, ctx);
    if (nearest.ok()) return nearest;
  } else {
    nearest.error = "no inverse-kinematics solution within the joint limits";
  }
  // the nearest branch does not give a compensated solution inside the limits: the others, nearest
  // first (a nominal solution a little outside the limits may come inside once compensated)
  const Vec6 tried = k >= 0 ? s.sol[k].q_deg : Vec6::Constant(1e300);
  if (!all) s = ik.solve(target, IkOptions(ref));
  std::array<int, 8> order;
  std::array<double, 8> dist;
  for (int i = 0; i < s.count; ++i) order[i] = i, dist[i] = (s.sol[i].q_deg - ref).cwiseAbs().maxCoeff();
  for (int i = 1; i < s.count; ++i)  // insertion sort by distance (at most 8)
    for (int j = i; j > 0 && dist[order[j]] < dist[order[j - 1]]; --j) std::swap(order[j], order[j - 1]);
  for (int i = 0; i < s.count; ++i) {
    const IkSolution& c = s.sol[order[i]];
    if ((c.q_deg - tried).cwiseAbs().maxCoeff() < 1e-9) continue;  // the nearest branch, tried first
    PoseSolution other = compensate_from(robot, opt, pose, target, c.q_deg, c.approximate, ctx);
    if (other.ok()) {
      other.status = PoseStatus::BranchChanged;
      other.error = std::move(nearest.error);  // why the nearest branch did not do
      return other;
    }
  }
  if (s.count > 1) nearest.error += "; no other branch reaches the pose inside the limits";
  return nearest;
}

// Nominal robots without closed-form IK, and every calibrated robot: Newton on the model from the
// reference, then a numerical IK from the reference, home and seeded starts.
PoseSolution solve_numeric(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Vec6& ref,
                           const EffectContext& ctx) {
  const Model& target_model = opt.compensate ? *robot.calibrated() : *robot.nominal();
  const EffectContext none;
  const EffectContext& c = opt.compensate ? ctx : none;
  CompensationResult r = compensate(target_model, pose, ref, opt.comp, c);
  if (r.status == CompStatus::Converged) r.q_deg = wrap_near(target_model, r.q_deg, ref);
  if (r.status != CompStatus::Converged || !target_model.within_limits_deg(r.q_deg)) {
    if (const auto qn = numeric_ik(target_model, pose, ref, opt.comp, 48, c))
      r = compensate(target_model, pose, *qn, opt.comp, c);
    if (r.status == CompStatus::Converged) r.q_deg = wrap_near(target_model, r.q_deg, ref);
  }
  return accept(target_model, r);
}

Vec6 home_of(const Model& m) {
  Vec6 q = Vec6::Zero();
  if (m.spec().home_deg.size() == 6)
    for (int j = 0; j < 6; ++j) q[j] = m.spec().home_deg[j];
  return q;
}

}  // namespace

// The result's count and extremes with one more pose.
void count_pose(ProgramResult& res, const PoseSolution& s) {
  res.min_iterations = res.poses == 0 ? s.iterations : std::min(res.min_iterations, s.iterations);
  res.max_iterations = std::max(res.max_iterations, s.iterations);
  res.total_iterations += s.iterations;
  res.max_residual = std::max(res.max_residual, s.residual);
  ++res.poses;
}

PoseSolution solve_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose_in, const Vec6& ref,
                        const EffectContext& ctx) {
  if (robot.nominal()->dof() != 6) return failed("programs need a 6-joint robot");
  Pose6 pose = pose_in;
  if (opt.instrument_frame) pose = iso_to_pose(robot.campaign().base().inverse() * pose_to_iso(pose_in));
  if (robot.ik().structure().spherical_wrist_parallel_23) return solve_closed_form(robot, opt, pose, ref, ctx);
  return solve_numeric(robot, opt, pose, ref, ctx);
}

std::vector<Vec6> motion_directions(const std::vector<Vec6>& q, const std::vector<double>& initial) {
  Vec6 d = Vec6::Ones();
  if (initial.size() == 6) {
    d = Eigen::Map<const Vec6>(initial.data());
  } else if (initial.size() == 1) {
    d.setConstant(initial[0]);
  } else {  // the direction of each joint's first motion
    for (int j = 0; j < 6; ++j)
      for (size_t i = 1; i < q.size(); ++i) {
        const double delta = q[i][j] - q[i - 1][j];
        if (std::abs(delta) > kStillDeg) {
          d[j] = delta > 0 ? 1.0 : -1.0;
          break;
        }
      }
  }
  std::vector<Vec6> out(q.size());
  for (size_t i = 0; i < q.size(); ++i) {
    for (int j = 0; j < 6 && i > 0; ++j) {
      const double delta = q[i][j] - q[i - 1][j];
      if (std::abs(delta) > kStillDeg) d[j] = delta > 0 ? 1.0 : -1.0;
    }
    out[i] = d;
  }
  return out;
}

Vec6 initial_directions(const std::vector<double>& v) {
  if (v.size() != 1 && v.size() != 6)
    throw InputError("--initial-direction needs one sign for every joint, or one for all");
  for (double x : v)
    if (x != 1.0 && x != -1.0) throw InputError("--initial-direction: the directions must be +1 or -1");
  return v.size() == 1 ? Vec6::Constant(v[0]) : Vec6(Eigen::Map<const Vec6>(v.data()));
}

std::vector<double> parse_initial_direction(const std::string& text) {
  std::vector<double> out;
  if (text.empty()) return out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    double v = 0;
    if (parse_number(item.data(), item.data() + item.size(), v) != NumberParse::Ok)
      throw InputError("--initial-direction " + text + ": '" + item + "' is not +1 or -1");
    out.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  initial_directions(out);  // the rule: one sign for all joints or one per joint, each +1 or -1
  return out;
}

ProgramCursor::ProgramCursor(const Robot& robot, const ProgramOptions& opt, const Vec6& dir0)
    : prev(home_of(*robot.nominal())) {
  if (opt.compensate && robot.calibrated()->needs_dir()) ctx.dir = dir0;
}

PoseSolution next_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, ProgramCursor& cur) {
  const Vec6 ref = cur.reference ? *cur.reference : cur.prev;
  PoseSolution s = solve_pose(robot, opt, pose, ref, cur.ctx);
  if (!s.ok()) return s;
  if (!cur.first && opt.compensate && robot.calibrated()->needs_dir()) {
    VecQ turned = cur.ctx.dir;
    bool any = false;
    for (int j = 0; j < 6; ++j) {
      const double delta = s.q_deg[j] - cur.prev[j];
      if (std::abs(delta) > kStillDeg && (delta > 0 ? 1.0 : -1.0) != cur.ctx.dir[j])
        turned[j] = -cur.ctx.dir[j], any = true;
    }
    if (any) {
      EffectContext c2 = cur.ctx;
      c2.dir = turned;
      PoseSolution s2 = solve_pose(robot, opt, pose, ref, c2);
      if (!s2.ok()) return s2;
      if (s.branch_changed() && !s2.branch_changed()) {
        s2.status = PoseStatus::BranchChanged;
        s2.error = std::move(s.error);
      }
      s = std::move(s2);
      // the directions the commanded motion really has (a move inside the backlash keeps its sign)
      for (int j = 0; j < 6; ++j) {
        const double delta = s.q_deg[j] - cur.prev[j];
        if (std::abs(delta) > kStillDeg) cur.ctx.dir[j] = delta > 0 ? 1.0 : -1.0;
      }
    }
  }
  if (cur.first && !cur.reference && s.branch_changed()) s.status = PoseStatus::Solved;  // no branch to keep
  cur.prev = s.q_deg;
  cur.first = false;
  return s;
}

std::string branch_change_message(const std::string& cause) {
  return "branch changed: on the branch nearest the previous pose, " + cause;
}

ProgramResult compensate_poses(const Robot& robot, const std::vector<Pose6>& poses,
                               const std::vector<std::string>& where_of, const ProgramOptions& opt,
                               const std::vector<double>& temperature_c,
                               const std::vector<std::optional<Vec6>>& references) {
  const Model& cal = *robot.calibrated();
  auto where_i = [&](size_t i) { return i < where_of.size() ? where_of[i] : "pose " + std::to_string(i); };
  const bool needs_dir = opt.compensate && cal.needs_dir();
  const bool needs_t = opt.compensate && cal.needs_temperature();
  std::vector<double> temps(poses.size(), opt.temperature_c);
  for (size_t i = 0; i < temperature_c.size() && i < poses.size(); ++i)
    if (std::isfinite(temperature_c[i])) temps[i] = temperature_c[i];
  if (needs_t)
    for (size_t i = 0; i < poses.size(); ++i)
      if (!std::isfinite(temps[i])) throw InputError(where_i(i) + ": " + kNeedsTemperature);
  auto run = [&](const Vec6& dir0) {
    ProgramResult res;
    ProgramCursor cur(robot, opt, dir0);
    for (size_t i = 0; i < poses.size(); ++i) {
      cur.ctx.temperature_c = temps[i];
      cur.reference = i < references.size() ? references[i] : std::nullopt;
      const PoseSolution s = next_pose(robot, opt, poses[i], cur);
      if (!s.ok()) throw InputError(where_i(i) + ": " + s.error);
      if (s.branch_changed() && cur.reference) {
        res.warnings.push_back(where_i(i) + ": off the taught branch: " + s.error);  // (checked by the caller)
      } else if (s.branch_changed()) {
        const std::string w = where_i(i) + ": " + branch_change_message(s.error);
        if (opt.keep_branch) throw InputError(w + " (--keep-branch)");
        res.warnings.push_back(w);
      }
      res.q_deg.push_back(s.q_deg);
      res.dir.push_back(needs_dir ? Vec6(cur.ctx.dir) : Vec6::Zero());
      res.iterations.push_back(s.iterations);
      res.residual.push_back(s.residual);
      count_pose(res, s);
    }
    return res;
  };
  ProgramResult res;
  if (!needs_dir) {
    res = run(Vec6::Ones());
  } else if (!opt.initial_direction.empty()) {
    res = run(initial_directions(opt.initial_direction));
  } else {
    // the direction of the first motion: from a first pass that assumes +1, then the program again
    const ProgramResult first = run(Vec6::Ones());
    res = run(motion_directions(first.q_deg, {})[0]);
  }
  // the poses that take a joint's periodic effects outside the angles they were fitted on
  if (opt.compensate && !res.q_deg.empty() && !robot.campaign().fitted_deg.empty()) {
    std::vector<double> q;
    q.reserve(res.q_deg.size() * 6);
    for (const Vec6& v : res.q_deg) q.insert(q.end(), v.data(), v.data() + 6);
    for (const Extrapolation& e : extrapolated(cal.spec(), robot.campaign().fitted_deg, q.data(), res.q_deg.size(), 6))
      res.warnings.push_back(where_i(e.first) + ": " + extrapolation_message(e, res.q_deg.size(), "poses compensated"));
  }
  return res;
}

}  // namespace kincal
