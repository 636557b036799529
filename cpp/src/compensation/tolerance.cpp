#include "kincal/compensation/tolerance.hpp"

#include "kincal/io/file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kincal {

Pose6 interpolate_pose(const Pose6& a, const Pose6& b, double s) {
  const Eigen::Quaterniond qa(abc_to_rotation(a.abc)), qb(abc_to_rotation(b.abc));
  Pose6 p;
  p.xyz = a.xyz + s * (b.xyz - a.xyz);
  p.abc = rotation_to_abc(qa.slerp(s, qb).toRotationMatrix());  // Eigen's slerp takes the shortest way
  return p;
}

namespace {

double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double n2 = d.squaredNorm();
  const double t = n2 > 0 ? std::clamp((p - a).dot(d) / n2, 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

// The controller's nominal IK of a pose on its straight line: the branch nearest ref (the last sample).
Vec6 nominal_ik_near(const Robot& robot, const Eigen::Isometry3d& target, const Vec6& ref) {
  if (robot.ik().structure().spherical_wrist_parallel_23) {
    IkSolutions s = robot.ik().solve(target, IkOptions(ref, Branches::NearestReference));
    int k = s.status == IkStatus::Ok ? s.nearest(ref.data()) : -1;
    if (k < 0) {
      s = robot.ik().solve(target, IkOptions(ref));
      k = s.status == IkStatus::Ok ? s.nearest(ref.data()) : -1;
    }
    if (k >= 0) return s.sol[k].q_deg;
  } else {
    const CompensationResult r = compensate(*robot.nominal(), iso_to_pose(target), ref);
    if (r.status == CompStatus::Converged) return r.q_deg;
  }
  throw InputError("the controller's straight line between the targets leaves the nominal model's reach");
}

}  // namespace

double segment_deviation_mm(const Robot& robot, const Pose6& a, const Pose6& b, const Vec6& qa, const Vec6& qb,
                            PathKind kind, const EffectContext& ctx_a, const EffectContext& ctx_b) {
  const Model& cal = *robot.calibrated();
  Pose6 ta, tb;
  if (kind == PathKind::NominalLine) {
    ta = iso_to_pose(fk(*robot.nominal(), VecQ(qa * kDeg)));
    tb = iso_to_pose(fk(*robot.nominal(), VecQ(qb * kDeg)));
  }
  EffectContext ctx = ctx_b;
  Vec6 q = qa;
  double worst = 0;
  for (int k = 1; k < kPathSamples; ++k) {
    const double s = static_cast<double>(k) / kPathSamples;
    if (kind == PathKind::Joint)
      q = qa + s * (qb - qa);
    else
      q = nominal_ik_near(robot, pose_to_iso(interpolate_pose(ta, tb, s)), q);
    if (std::isfinite(ctx_a.temperature_c) && std::isfinite(ctx_b.temperature_c))
      ctx.temperature_c = ctx_a.temperature_c + s * (ctx_b.temperature_c - ctx_a.temperature_c);
    const Vec3 p = fk_model(cal, VecQ(q * kDeg), ctx).translation();
    worst = std::max(worst, distance_to_segment(p, a.xyz, b.xyz));
  }
  return worst;
}

ToleranceResult compensate_with_tolerance(const Robot& robot, const std::vector<Pose6>& poses,
                                          const std::vector<std::string>& where, const ProgramOptions& opt,
                                          const std::vector<double>& temperature_c, double tol, PathKind kind) {
  return compensate_with_tolerance(robot, poses, where, opt, temperature_c, tol,
                                   std::vector<PathKind>(poses.empty() ? 0 : poses.size() - 1, kind));
}

ToleranceResult compensate_with_tolerance(const Robot& robot, const std::vector<Pose6>& poses,
                                          const std::vector<std::string>& where, const ProgramOptions& opt,
                                          const std::vector<double>& temperature_c, double tol,
                                          const std::vector<PathKind>& segment_kinds,
                                          const std::vector<std::optional<Vec6>>& references) {
  if (!(tol > 0)) throw InputError("--tolerance must be a positive length in mm");
  std::vector<PathKind> kinds = segment_kinds;
  kinds.resize(poses.empty() ? 0 : poses.size() - 1, PathKind::Unchecked);
  ToleranceResult r;
  r.poses = poses;
  r.where = where;
  r.where.resize(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    r.original.push_back(static_cast<int>(i));
    if (r.where[i].empty()) r.where[i] = "pose " + std::to_string(i + 1);
  }
  std::vector<std::string> label = r.where;  // per pose: the input line it belongs to
  std::vector<double> temps(poses.size(), opt.temperature_c);
  for (size_t i = 0; i < temperature_c.size() && i < poses.size(); ++i) temps[i] = temperature_c[i];
  const Eigen::Isometry3d to_base = opt.instrument_frame ? robot.campaign().base().inverse()
                                                         : Eigen::Isometry3d::Identity();
  constexpr int kMaxRounds = 20;
  for (int round = 0;; ++round) {
    std::vector<std::optional<Vec6>> refs(r.poses.size());  // an input pose's reference; none for inserted ones
    for (size_t i = 0; i < refs.size(); ++i)
      if (r.original[i] >= 0 && static_cast<size_t>(r.original[i]) < references.size())
        refs[i] = references[static_cast<size_t>(r.original[i])];
    r.result = compensate_poses(robot, r.poses, r.where, opt, temps, refs);
    const auto& q = r.result.q_deg;
    std::vector<char> split(r.poses.size(), 0);
    double worst = 0;
    size_t worst_at = 0;
    for (size_t i = 0; i + 1 < r.poses.size(); ++i) {
      if (kinds[i] == PathKind::Unchecked) continue;
      EffectContext ca, cb;
      ca.temperature_c = temps[i], cb.temperature_c = temps[i + 1];
      if (opt.compensate && robot.calibrated()->needs_dir()) ca.dir = r.result.dir[i + 1], cb.dir = r.result.dir[i + 1];
      double d;
      try {
        d = segment_deviation_mm(robot, iso_to_pose(to_base * pose_to_iso(r.poses[i])),
                                 iso_to_pose(to_base * pose_to_iso(r.poses[i + 1])), q[i], q[i + 1], kinds[i], ca, cb);
      } catch (const InputError& e) {
        throw InputError(r.where[i + 1] + ": " + e.what());
      }
      if (d > tol) split[i] = 1;
      if (d > worst) worst = d, worst_at = i + 1;
    }
    if (round == 0) r.before_mm = worst;
    r.after_mm = worst;
    if (worst <= tol) return r;
    if (round == kMaxRounds) {
      char buf[200];
      std::snprintf(buf, sizeof buf, ": the path still leaves the desired segment by %.4g mm after %d subdivisions "
                    "(a singularity between the targets?)", worst, kMaxRounds);
      throw InputError(r.where[worst_at] + buf);
    }
    ToleranceResult next;
    std::vector<double> next_t;
    std::vector<std::string> next_label;
    std::vector<PathKind> next_kinds;
    for (size_t i = 0; i < r.poses.size(); ++i) {
      if (i > 0) next_kinds.push_back(kinds[i - 1]);
      if (i > 0 && split[i - 1]) {
        next_kinds.push_back(kinds[i - 1]);
        next.poses.push_back(interpolate_pose(r.poses[i - 1], r.poses[i], 0.5));
        next.original.push_back(-1);
        next.where.push_back(label[i] + " (a target inserted before it by --tolerance)");
        next_label.push_back(label[i]);
        next_t.push_back(0.5 * (temps[i - 1] + temps[i]));
        ++r.inserted;
      }
      next.poses.push_back(r.poses[i]);
      next.original.push_back(r.original[i]);
      next.where.push_back(r.where[i]);
      next_label.push_back(label[i]);
      next_t.push_back(temps[i]);
    }
    r.poses = std::move(next.poses);
    r.original = std::move(next.original);
    r.where = std::move(next.where);
    temps = std::move(next_t);
    label = std::move(next_label);
    kinds = std::move(next_kinds);
  }
}

}  // namespace kincal
