#include "kincal/compensation/pose.hpp"

#include "kincal/kinematics/kinematics.hpp"

#include <Eigen/LU>
#include <cmath>

#include "kincal/core/fastmath.hpp"
#include "kincal/core/solve6.hpp"

namespace kincal {

const char* to_string(CompStatus s) {
  switch (s) {
    case CompStatus::Converged: return "converged";
    case CompStatus::NotConverged: return "did not converge within the iteration limit";
    case CompStatus::SingularJacobian: return "singular Jacobian (the robot is at a singularity)";
    case CompStatus::OrientationSingular: return "orientation at B = +-90 deg, where ABC angles are singular";
    case CompStatus::NotSixJoints: return "Newton compensation needs a 6-joint robot";
  }
  return "?";
}

namespace {

inline double wrap180(double a) {  // to [-180, 180] without std::remainder (slow)
  if (a > 180.0 || a < -180.0) a -= 360.0 * std::floor((a + 180.0) / 360.0);
  return a;
}

// F (eq. 6) from the pose's position and its ABC angles in degrees
inline Vec6 deviation_from(const Vec3& xyz, const Vec3& abc, const Pose6& d) {
  Vec6 f;
  f.head<3>() = xyz - d.xyz;
  for (int i = 0; i < 3; ++i) f[3 + i] = wrap180(abc[i] - d.abc[i]);
  return f;
}

inline Vec6 deviation(const Eigen::Isometry3d& t, const Pose6& d) {
  return deviation_from(t.translation(), rotation_to_abc(t.linear()), d);
}

// The rotation vector of a rotation (rad), accurate near the identity, where Newton works.
inline Vec3 rotation_vector(const Mat3& r) {
  const Vec3 v(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));  // 2 sin(theta) axis
  const double c = 0.5 * (r(0, 0) + r(1, 1) + r(2, 2) - 1), s2 = 0.25 * v.squaredNorm();  // cos, sin^2
  if (s2 < 4e-4 && c > 0) {
    // theta / (2 sin theta) = asin(s) / (2 s) by its series in s^2 = sin^2 theta (|s| < 0.02: the
    // first omitted term, 35 s^8 / 2304, is below 1e-15): no arctangent, no square root
    const double f = 0.5 + s2 * (1.0 / 12 + s2 * (3.0 / 80 + s2 * (5.0 / 224)));
    return f * v;
  }
  if (c < -0.9) {  // near half a turn: the antisymmetric part loses the axis
    const Eigen::AngleAxisd aa(r);
    return aa.angle() * aa.axis();
  }
  const double s = std::sqrt(s2), th = fastmath::atan2(s, c);
  return (0.5 * th / s) * v;
}

inline Mat3 skew3(const Vec3& v) {
  Mat3 k;
  k << 0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0;
  return k;
}

// The left Jacobian of SO(3) and its inverse at phi: Exp(phi + d) = Exp(Jl d) Exp(phi), so an
// angular velocity w (base frame) of R_model changes phi = log(R_model R_d^T) by Jl^-1 w.
inline void left_jacobians(const Vec3& phi, Mat3& jl, Mat3& jl_inv) {
  const double t2 = phi.squaredNorm(), t = std::sqrt(t2);
  const Mat3 k = skew3(phi), k2 = k * k;
  double a, b, c;
  if (t < 1e-4) {
    a = 0.5 - t2 / 24, b = 1.0 / 6 - t2 / 120, c = 1.0 / 12 + t2 / 720;
  } else {
    double st, ct;
    fastmath::sincos(t, st, ct);
    a = (1 - ct) / t2, b = (t - st) / (t2 * t), c = 1 / t2 - (1 + ct) / (2 * t * st);
  }
  jl = Mat3::Identity() + a * k + b * k2;
  jl_inv = Mat3::Identity() - 0.5 * k + c * k2;
}

// F of the chosen residual from a pose of the model
inline Vec6 deviation_of(const Eigen::Isometry3d& t, const Pose6& d, Residual residual) {
  if (residual == Residual::Abc) return deviation(t, d);
  Vec6 f;
  f.head<3>() = t.translation() - d.xyz;
  f.tail<3>() = rotation_vector(t.linear() * abc_to_rotation(d.abc).transpose()) * (1 / kDeg);
  return f;
}

// The sines and cosines of A and B of a rotation (the ABC rates need them), read off the matrix;
// at gimbal lock (cb = 0) A is taken as 0, and Newton stops there with OrientationSingular.
struct AbcTrig {
  double ca = 1, sa = 0, cb = 1, sb = 0;
};
inline AbcTrig abc_trig(const Mat3& r) {
  AbcTrig tr;
  tr.cb = std::sqrt(r(0, 0) * r(0, 0) + r(1, 0) * r(1, 0));
  tr.sb = -r(2, 0);
  if (tr.cb >= kAbcPoleCos) {
    const double inv = 1 / tr.cb;
    tr.ca = r(0, 0) * inv;
    tr.sa = r(1, 0) * inv;
  }
  return tr;
}

inline VecQ to_rad(const Vec6& q) { return q * kDeg; }

// the result's figures of F at its angles
inline void set_residual(CompensationResult& res, const Vec6& f) {
  res.residual = f.norm();
  res.position_error_mm = f.head<3>().norm();
  res.orientation_error_deg = f.tail<3>().norm();
}

}  // namespace

Vec6 pose_deviation(const Model& cal, const Vec6& q_deg, const Pose6& desired, Residual residual,
                    const EffectContext& ctx) {
  return deviation_of(fk_model(cal, to_rad(q_deg), ctx), desired, residual);
}

namespace {

// F and its analytic Jacobian at one q, in fixed sizes: the Jacobian follows from the frames of the
// FK only when it is asked for, the orientation rates from the rotation itself. With compliance,
// transmission error or backlash the chain is evaluated at the joints' actual angles and the
// Jacobian chained with their derivative d(q + dq(q))/dq; thermal expansion scales the positions.
struct DeviationEvaluator {
  const Model& cal;
  const Pose6& desired;
  const EffectContext& ctx;
  const bool abc;      // the paper's ABC residual, else the rotation vector
  const bool effects;  // joint-angle effects (compliance, transmission error, backlash)
  const double scale;  // thermal expansion
  Mat3 rd_t;           // R_desired^T (rotation vector)
  ChainFrames frames;
  MatQ dqd;  // d(actual joint angles)/dq, with effects
  AbcTrig tr;
  Vec3 phi;  // rotation vector of R_model R_desired^T (rad)

  // with_effects false: the chain at the given angles as the actual ones (the geometry and the
  // thermal scale only), for the split iteration below
  DeviationEvaluator(const Model& m, const Pose6& d, const EffectContext& c, Residual r, bool with_effects = true)
      : cal(m),
        desired(d),
        ctx(c),
        abc(r == Residual::Abc),
        effects(with_effects && (m.has_compliance() || m.has_joint_effects())),
        scale(length_scale(m, c)) {
    if (!abc) rd_t = abc_to_rotation(d.abc).transpose();
  }

  // F at q_deg; with derivative, d(actual joint angles)/dq as well (the Jacobian needs it)
  Vec6 deviation_at(const Vec6& q_deg, bool derivative = true) {
    const VecQ qr = q_deg * kDeg;
    if (!effects)
      fk_frames(cal, qr, frames);
    else if (derivative)
      fk_frames(cal, joint_angles(cal, qr, ctx, &dqd), frames);
    else
      fk_frames_actual(cal, qr, ctx, frames);
    const Vec3 pos = scale * frames.tool.translation();
    if (abc) {
      tr = abc_trig(frames.tool.linear());
      // rotation_to_abc's angles, its division by the degree as a multiplication on this path
      return deviation_from(pos, rotation_to_abc_rad(frames.tool.linear()) * (1 / kDeg), desired);
    }
    phi = rotation_vector(frames.tool.linear() * rd_t);
    Vec6 f;
    f.head<3>() = pos - desired.xyz;
    f.tail<3>() = phi * (1 / kDeg);
    return f;
  }

  bool orientation_singular() const { return abc && std::abs(tr.cb) < kAbcPoleCos; }

  // angular velocity per unit of the orientation rows' rates (E), and its inverse
  void rates(Mat3& e, Mat3& e_inv) const {
    if (!abc) {
      left_jacobians(phi, e, e_inv);
      return;
    }
    // for R = Rz(a) Ry(b) Rx(c): E = [[0, -sa, ca cb], [0, ca, sa cb], [1, 0, -sb]],
    // E^-1 = [[ca sb/cb, sa sb/cb, 1], [-sa, ca, 0], [ca/cb, sa/cb, 0]]
    e << 0, -tr.sa, tr.ca * tr.cb, 0, tr.ca, tr.sa * tr.cb, 1, 0, -tr.sb;
    const double icb = 1 / tr.cb;
    e_inv << tr.ca * tr.sb * icb, tr.sa * tr.sb * icb, 1, -tr.sa, tr.ca, 0, tr.ca * icb, tr.sa * icb, 0;
  }

  // dF/dq at the last deviation_at (rows mm and degrees, columns per degree of q), and E for the
  // solve. With exact false (Newton's steps), the rotation vector's rates are taken as the angular
  // velocity itself (E = I): they differ by a factor I + O(|phi|) and phi -> 0 at the solution, so
  // the iteration converges as fast (quadratically) at a lower cost; the ABC rates are always exact.
  //
  // wrist: the position rows taken at the wrist (joint 5's origin), z_j x (wrist - o_j), which is
  // FactoredJacobian's row operation done: it adds d x w to the tool's velocity (d = tool - wrist,
  // w = E times the orientation rows, z_j for column j whatever E is). Returns whether E = I.
  bool jacobian(Mat6r& jf, Mat3& e, bool exact = true, bool wrist = false) const {
    Mat3 e_inv;
    // (far from the solution, as from a previous pose's joints, the exact rates: |phi| > 0.05 rad)
    const bool rated = abc || exact || phi.squaredNorm() > 2.5e-3;
    if (rated)
      rates(e, e_inv);
    else
      e.setIdentity();
    const Vec3 point = wrist ? frames.o[4] : Vec3(frames.tool.translation());
    const double ks = kDeg * scale;
#pragma GCC unroll 6
    for (int j = 0; j < 6; ++j) {
      const Vec3& z = frames.z[j];
      jf.col(j).head<3>() = z.cross(point - frames.o[j]) * ks;
      if (rated)
        jf.col(j).tail<3>() = e_inv * z;
      else
        jf.col(j).tail<3>() = z;
    }
    if (effects) jf = (jf * dqd.topLeftCorner<6, 6>()).eval();
    return !rated;
  }

  // Half the second derivative of F along a step (deg of q) at the last deviation_at, in F's units:
  // F(q - step) = F - J step + second_order(step) + O(step^3). Position: the tool point's
  // acceleration sum_ij s_i s_j z_min x (z_max x (p - o_max)); orientation: the angular one,
  // sum_i<j s_i s_j z_i x z_j (the rotation vector's own curvature is O(phi), small where Newton
  // works). With joint effects the step acts through their derivative, their own curvature omitted.
  Vec6 second_order(const Vec6& step_deg) const {
    Vec6 s = step_deg * kDeg;
    if (effects) s = dqd.topLeftCorner<6, 6>() * s;
    const Vec3 tip = frames.tool.translation();
    Vec3 w = Vec3::Zero(), acc = Vec3::Zero(), alpha = Vec3::Zero();
#pragma GCC unroll 6
    for (int j = 0; j < 6; ++j) {
      const Vec3 zs = s[j] * frames.z[j];
      const Vec3 v = zs.cross(tip - frames.o[j]);
      acc += (zs + 2 * w).cross(v);
      alpha += w.cross(zs);
      w += zs;
    }
    Vec6 h;
    h.head<3>() = (0.5 * scale) * acc;
    h.tail<3>() = alpha * (0.5 / kDeg);
    return h;
  }

  // d(actual joint angles)/dq at q_deg, for a Jacobian after an evaluation without it
  void derivative_at(const Vec6& q_deg) {
    if (effects) joint_angles(cal, q_deg * kDeg, ctx, &dqd);
  }
};

// The linear solve of one Jacobian, kept so that later steps can reuse it: jf step = f. The position
// rows are first moved from the tool point to the wrist (joint 5's origin): v_wrist = v_tool + d x w
// with d = tool - wrist and w = E (orientation rates), a row operation of determinant 1 on jf and f
// alike, after which the arm's position block alone is singular only where the arm is; then
// BlockSolver's 3x3 blocks. The Jacobian comes with its rows at the wrist already
// (DeviationEvaluator::jacobian's wrist); f's are moved here, by a cross product.
struct FactoredJacobian {
  Vec3 dk;        // d, in mm per degree of the orientation rates
  Mat3 e;         // E, where it is not the identity
  bool rates = false;
  BlockSolver blocks;

  // returns |det jf| (0 when singular); identity: E = I
  double factor(const DeviationEvaluator& ev, const Mat6r& jf, const Mat3& e_rates, bool identity) {
    dk = (kDeg * ev.scale) * (ev.frames.tool.translation() - ev.frames.o[4]);
    rates = !identity;
    if (rates) e = e_rates;
    return blocks.factor(jf);
  }

  // f becomes the step
  void solve(Vec6& f) const {
    if (rates)
      f.head<3>() += dk.cross(e * f.tail<3>());
    else
      f.head<3>() += dk.cross(f.tail<3>());
    blocks.solve(f);
  }
};

// Newton's iteration with the Jacobian reused while it serves (a chord step): a new Jacobian is
// taken at the start and whenever the last step contracted |F| by less than opt.reuse_contraction;
// the Jacobian changes little over the steps near a solution, so each reused step costs an
// evaluation of F only. The stopping rule is the same |F|^2 < epsilon on the exact F.
// with_effects false: on the chain alone (the split below). When converged, f_out (if given) gets F
// at the solution, j_out its Jacobian and trig_out the solution's sines and cosines (from its FK);
// j_out's rotation-vector rows as Newton's steps take them (E = I: E differs from I by |phi| / 2,
// below 1e-9 where |F| has met the stop; the ABC rows exact).
CompensationResult newton(const Model& cal, const Pose6& desired, const Vec6& q0_deg, const CompensationOptions& opt,
                          const EffectContext& ctx, bool with_effects, Vec6* f_out = nullptr,
                          Mat6r* j_out = nullptr, JointTrig* trig_out = nullptr) {
  CompensationResult res;
  Vec6 q = q0_deg;
  DeviationEvaluator ev(cal, desired, ctx, opt.residual, with_effects);
  FactoredJacobian fac;
  Mat6r jf;
  Mat3 e;
  double f2_last = 0;
  bool reused = true;  // the last step's Jacobian was a reused one (none yet)
  const double reuse2 = opt.reuse_contraction * opt.reuse_contraction;
  // the joint effects' derivative d(actual)/dq once, at the start, in the fast iteration: it is I +
  // O(1e-3) and moves by O(1e-5) over the steps, so the Jacobian's error is far below the chord's
  for (int it = 0;; ++it) {
    const bool with_derivative = reuse2 == 0 || (it == 0 && reused);  // a fresh Jacobian is certain
    const Vec6 f = ev.deviation_at(q, with_derivative);
    const double f2 = f.squaredNorm();
    auto finish = [&](CompStatus status) {
      if (status == CompStatus::Converged && f_out) {
        *f_out = f;
        Mat3 e;
        ev.jacobian(*j_out, e, false);
        if (trig_out) {
          trig_out->q = to_rad(q);
          trig_out->s = ev.frames.s;
          trig_out->c = ev.frames.c;
        }
      }
      res.q_deg = q;
      res.iterations = it;
      set_residual(res, f);
      res.status = status;
      return res;
    };
    if (f2 < opt.epsilon) return finish(CompStatus::Converged);
    if (it >= opt.max_iterations) return finish(CompStatus::NotConverged);
    if (ev.orientation_singular()) return finish(CompStatus::OrientationSingular);
    // a chord step only near the solution (|F| < 1e-3 mm or deg, where the Jacobian barely changes
    // over a step): from farther, as near a singularity, a stale Jacobian can lead to another branch
    const bool fresh = reused || !(f2 < reuse2 * f2_last) || !(f2 < 1e-6);
    if (fresh) {
      if (reuse2 == 0 && !with_derivative) ev.derivative_at(q);
      const bool identity = ev.jacobian(jf, e, false, true);
      const double det = fac.factor(ev, jf, e, identity);
      if (!(det > 1e-18) || !std::isfinite(det)) return finish(CompStatus::SingularJacobian);
    }
    reused = !fresh;
    f2_last = f2;
    Vec6 step = f;
    fac.solve(step);
    // the first, largest step: its second-order term as well (of the rotation vector's rows; the ABC
    // angles' own curvature is not in it)
    if (it == 0 && opt.second_order && opt.residual == Residual::RotationVector) {
      Vec6 more = ev.second_order(step);
      fac.solve(more);
      // a correction as large as the step itself: near a singularity, where the series does not hold
      if (more.squaredNorm() < 0.25 * step.squaredNorm()) {
        step += more;
        reused = true;  // F left at 1e-5..1e-3 of its start: a fresh Jacobian converges in one more step
      }
    }
    if (!step.allFinite()) return finish(CompStatus::SingularJacobian);
    q -= step;
  }
}

// With compliance or joint effects the model's pose is the chain's at the actual angles,
// F(q) = F_chain(a(q)), and a(q) = q + d(q) with d of 1e-2 deg and its derivative D of 1e-4..1e-3. So
// the pose is solved for the actual angles first, a*, by Newton's iteration on the chain alone (the
// geometric cost: no gravity torque and no effect's derivative in it), then the commands from
// r(q) = a(q) - a* = 0 by a chord iteration, q <- q - (I + D_band)^-1 r(q), each step a gravity torque
// and the joint effects only. D_band is D's band at a* (each joint's derivative with respect to itself
// and its neighbours, JointAnglesNear::at_reference), which holds about 90% of D on the kr500 (the
// coupling of the shoulder and the elbow), so each step contracts r about tenfold more than the plain
// fixed point q <- q - r(q): two evaluations of a(q) per pose where that took four. F at q follows from
// the chain's F and Jacobian at a*: F(q) = F(a*) + J(a*) r(q) + O(|r|^2), that remainder below 5e-11
// mm where it is used (|r| < 1e-5 deg, 3 m reach; where the stop is reached |J r| < 6e-8 mm, so |r|
// is far smaller but near a singularity). Where r does not contract tenfold per step (an effect as
// steep as the joint itself) or the chain's iteration fails, Newton's iteration on the whole model.
constexpr int kJointSteps = 8;
constexpr double kJointStepTrusted = 1e-5;  // deg: the largest |a(q) - a*| at which F(q) is taken as above

CompensationResult compensate_split(const Model& cal, const Pose6& desired, const Vec6& q0_deg,
                                    const CompensationOptions& opt, const EffectContext& ctx) {
  Vec6 fa;
  Mat6r ja;
  JointTrig trig;
  CompensationResult res = newton(cal, desired, q0_deg, opt, ctx, false, &fa, &ja, &trig);
  if (res.status != CompStatus::Converged) {
    // where the chain's iteration stops, the commands one fixed-point step from its angles, and the
    // whole model's F there. Newton's iteration on the whole model is the same but for a joint-space
    // map within 1e-3 of the identity, and fails where the chain's does: of 2000 poses of the
    // compliant kr500 from their nominal IK solutions (seed 7), 34 fail both ways, and the one more
    // the chain's fails had the whole model's converge 1573 deg from its start (no solution a program
    // wants). Not tried again: a failure runs to the iteration limit, and a second run doubled the
    // time of every failing pose.
    const VecQ a = to_rad(res.q_deg);
    res.q_deg -= (joint_angles(cal, a, ctx) - a) * (1 / kDeg);
    const Vec6 f = pose_deviation(cal, res.q_deg, desired, opt.residual, ctx);
    set_residual(res, f);
    return res;
  }
  const Vec6 a_star = res.q_deg;
  const Vec6 a_rad = trig.q;  // a* (rad), with the sines and cosines of the chain's last FK
  const JointAnglesNear actual(cal, trig, ctx);
  // r(a*) and D_band there; the steps (I + D_band)^-1 r by the series I - D_band + D_band^2 (its
  // remainder D_band^3 r is 1e-9 of r at |D| ~ 1e-3; a D too large for it shows as a step that does
  // not contract tenfold, and the whole model's Newton takes over)
  JointBand band;
  Vec6 r = (actual.at_reference(band) - a_rad) * (1 / kDeg), r_last = r;
  Vec6 q = a_star;
  for (int k = 0; k < kJointSteps; ++k) {
    if (k > 0) {
      r = (actual.at6(q * kDeg) - a_rad) * (1 / kDeg);
      // F(q) near a*, row by row: the first step's fails on its first row (1e-4 mm against 3e-8)
      Vec6 f;
      double f2 = r.cwiseAbs().maxCoeff() < kJointStepTrusted ? 0.0 : opt.epsilon;
      for (int i = 0; i < 6 && f2 < opt.epsilon; ++i) {
        f[i] = fa[i] + ja.row(i).dot(r);
        f2 += f[i] * f[i];
      }
      if (f2 < opt.epsilon) {
        res.q_deg = q;
        res.joint_iterations = k;
        set_residual(res, f);
        return res;
      }
      if (!(r.squaredNorm() < 0.01 * r_last.squaredNorm())) break;
    }
    r_last = r;
    q -= band.inverse_times(r);
  }
  return newton(cal, desired, q0_deg, opt, ctx, true);
}

}  // namespace

Mat6 pose_deviation_jacobian(const Model& cal, const Vec6& q_deg, const Pose6& desired, Residual residual,
                             const EffectContext& ctx) {
  if (cal.dof() != 6) throw std::invalid_argument("pose_deviation_jacobian needs a 6-joint robot");
  check_context(cal, ctx, "");
  DeviationEvaluator ev(cal, desired, ctx, residual);
  ev.deviation_at(q_deg);
  Mat6r jf;
  Mat3 e;
  ev.jacobian(jf, e);
  return jf;
}

Vec6 pose_deviation_second_order(const Model& cal, const Vec6& q_deg, const Pose6& desired, const Vec6& step_deg,
                                 Residual residual, const EffectContext& ctx) {
  if (cal.dof() != 6) throw std::invalid_argument("pose_deviation_second_order needs a 6-joint robot");
  if (residual != Residual::RotationVector)
    throw std::invalid_argument("pose_deviation_second_order: the rotation-vector residual only");
  check_context(cal, ctx, "");
  DeviationEvaluator ev(cal, desired, ctx, residual);
  ev.deviation_at(q_deg);
  return ev.second_order(step_deg);
}

CompensationResult compensate(const Model& cal, const Pose6& desired, const Vec6& q0_deg, const CompensationOptions& opt,
                              const EffectContext& ctx) {
  CompensationResult res;
  res.q_deg = q0_deg;
  if (cal.dof() != 6) {
    res.status = CompStatus::NotSixJoints;
    return res;
  }
  if (cal.needs_dir() || cal.needs_temperature()) check_context(cal, ctx, "");
  if (!opt.finite_difference) {
    if (opt.split_effects && (cal.has_compliance() || cal.has_joint_effects()))
      return compensate_split(cal, desired, q0_deg, opt, ctx);
    return newton(cal, desired, q0_deg, opt, ctx, true);
  }
  // the paper's iteration with its finite-difference Jacobian (eq. 7)
  Vec6 q = q0_deg;
  Mat6r jf;
  for (int it = 0;; ++it) {
    Vec6 f = deviation_of(fk_model(cal, to_rad(q), ctx), desired, opt.residual);
    res.q_deg = q;
    res.iterations = it;
    set_residual(res, f);
    if (f.squaredNorm() < opt.epsilon) {
      res.status = CompStatus::Converged;
      return res;
    }
    if (it >= opt.max_iterations) {
      res.status = CompStatus::NotConverged;
      return res;
    }
    // eq. 7: column i = (F(q + delta e_i) - F(q)) / delta
    for (int i = 0; i < 6; ++i) {
      Vec6 qi = q;
      qi[i] += opt.delta;
      Vec6 fi = deviation_of(fk_model(cal, to_rad(qi), ctx), desired, opt.residual);
      jf.col(i) = (fi - f) / opt.delta;
    }
    const double det = solve6(jf, f);
    if (!(det > 1e-18) || !std::isfinite(det) || !f.allFinite()) {
      res.status = CompStatus::SingularJacobian;
      return res;
    }
    q -= f;
  }
}

}  // namespace kincal
