#include "kincal/model/model.hpp"

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>

#include <cmath>

namespace kincal {

namespace {

bool finite(const Vec3& v) { return v.allFinite(); }

Mat3 frame_along(const Vec3& z) {
  // A right-handed frame whose z is the given unit axis; x is deterministic.
  int k = 0;
  if (std::abs(z[1]) < std::abs(z[k])) k = 1;
  if (std::abs(z[2]) < std::abs(z[k])) k = 2;
  Vec3 x = Vec3::Unit(k).cross(z).normalized();
  Mat3 r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

bool parallel(const Vec3& a, const Vec3& b, double tol = 1e-9) { return a.cross(b).norm() < tol; }

}  // namespace

Model::Model(ModelSpec spec) : spec_(std::move(spec)) {
  n_ = static_cast<int>(spec_.joints.size());
  const std::string who = "robot '" + spec_.name + "': ";
  if (n_ < 1 || n_ > kMaxJoints)
    throw InputError(who + "a serial chain needs 1 to " + std::to_string(kMaxJoints) + " revolute joints, got " +
                     std::to_string(n_));
  take_effects(who);
  check_values(who);
  find_loaded_joints(who);
  compile_links();
  build_kdl_chain();
}

// Effects: joint_compliance entries set the joints' compliance; the others are checked and kept
void Model::take_effects(const std::string& who) {
  std::vector<EffectValue> rest;
  for (const EffectValue& ev : spec_.effects) {
    check_effect(ev.effect, n_, who);
    if (static_cast<int>(ev.p.size()) != ev.effect.size())
      throw InputError(who + ev.effect.label() + ": " + std::to_string(ev.p.size()) + " values for " +
                       std::to_string(ev.effect.size()) + " parameters");
    for (double v : ev.p)
      if (!std::isfinite(v)) throw InputError(who + ev.effect.label() + ": a value is NaN or infinite");
    for (const EffectValue& o : rest)
      if (o.effect.name == ev.effect.name && o.effect.joint == ev.effect.joint)
        throw InputError(who + ev.effect.label() + " is given twice");
    const EffectKind& kind = ev.effect.kind();
    if (kind.gravity_loaded_only) {  // joint_compliance: the joint's own compliance
      spec_.joints[ev.effect.joint].compliance_deg_per_knm = ev.p[0];
      continue;
    }
    rest.push_back(ev);
    if (kind.of_instrument())  // the measurement's: a Campaign carries it (campaign.hpp)
      throw InputError(who + ev.effect.label() + " is the instrument's, not the robot's: the campaign carries it");
    if (kind.scales_lengths()) {
      thermal_alpha_ = ev.p[0];
    } else {
      joint_effects_.push_back(ev);
      needs_dir_ = needs_dir_ || kind.reads_dir();
      if (kind.harmonic)  // a sine and a cosine amplitude per order, in the order of the harmonics
        for (size_t i = 0; i < ev.effect.harmonics.size(); ++i) {
          const int k = ev.effect.harmonics[i];
          harmonic_terms_.push_back({ev.effect.joint, k, ev.p[2 * i], ev.p[2 * i + 1]});
          const double k6 = std::pow(static_cast<double>(k), 6);
          harmonic_bound_[ev.effect.joint] += k6 * (std::abs(ev.p[2 * i]) + std::abs(ev.p[2 * i + 1])) / 720;
        }
    }
  }
  spec_.effects = rest;
  if (!std::isfinite(spec_.t_ref_c)) throw InputError(who + "the reference temperature is NaN or infinite");
}

// The joints, tool, payload and gravity: finite, consistent; the joints' axes and points
void Model::check_values(const std::string& who) {
  for (int j = 0; j < n_; ++j) {
    const JointSpec& js = spec_.joints[j];
    const std::string jn = who + "joint " + std::to_string(j + 1) + ": ";
    if (!finite(js.point) || !finite(js.axis) || !finite(js.com) || !std::isfinite(js.mass_kg) ||
        !std::isfinite(js.compliance_deg_per_knm) || !std::isfinite(js.lower_deg) || !std::isfinite(js.upper_deg))
      throw InputError(jn + "a value is NaN or infinite");
    if (js.axis.norm() < 1e-12) throw InputError(jn + "axis has zero length");
    if (!(js.lower_deg < js.upper_deg)) throw InputError(jn + "lower limit is not below upper limit");
    if (js.mass_kg < 0) throw InputError(jn + "negative mass");
    w_[j] = js.axis.normalized();
    p_[j] = js.point;
    k_[j] = js.compliance_deg_per_knm * kDeg / 1e6;  // deg per kN m -> rad per N mm
  }
  if (!finite(spec_.tool.xyz) || !finite(spec_.tool.abc) || !finite(spec_.gravity) || !finite(spec_.payload_com) ||
      !std::isfinite(spec_.payload_kg))
    throw InputError(who + "a tool, payload or gravity value is NaN or infinite");
  if (!spec_.home_deg.empty() && static_cast<int>(spec_.home_deg.size()) != n_)
    throw InputError(who + "home has " + std::to_string(spec_.home_deg.size()) + " angles for " +
                     std::to_string(n_) + " joints");
  tool_ = pose_to_iso(spec_.tool);
  g_ = spec_.gravity;
}

// Gravity-loaded joints: all but a leading run of joints whose axes stay along gravity.
void Model::find_loaded_joints(const std::string& who) {
  bool upstream_vertical = g_.norm() > 0;
  for (int j = 0; j < n_; ++j) {
    upstream_vertical = upstream_vertical && parallel(w_[j], g_.normalized(), 1e-9);
    loaded_[j] = !upstream_vertical;
    if (!loaded_[j] && spec_.joints[j].compliance_deg_per_knm != 0)
      throw InputError(who + "joint " + std::to_string(j + 1) +
                       " has a compliance but its axis is along gravity (no gravity torque)");
    has_compliance_ = has_compliance_ || spec_.joints[j].compliance_deg_per_knm != 0;
  }
}

// Compiled evaluator: a local frame F_j along every axis, T(q) = C0 Rz(q1) L1 Rz(q2) L2 ... Rz(qn) Ln
// with constant L_j = F_j^T F_{j+1} (L_n to the tool); then every link rotation but the last written
// as Rz(theta) Rx(alpha) Rz(phi) and the Rz merged into the joints: Rz(q_j) Trans(t_j) Rz(theta_j)
// = Rz(q_j + theta_j) Trans(Rz(-theta_j) t_j), and Rz(phi_j) Rz(q_{j+1}) = Rz(q_{j+1} + phi_j).
// The local frame of joint j becomes F_j Rz(theta_j), in which its link data are written.
void Model::compile_links() {
  std::array<Mat3, kMaxJoints> fr;
  fr.fill(Mat3::Identity());
  for (int j = 0; j < n_; ++j) fr[j] = frame_along(w_[j]);
  c0_r_ = fr[0];
  c0_t_ = p_[0];
  double carried = 0;  // phi of the previous link
  for (int j = 0; j < n_; ++j) {
    Link& l = links_[j];
    const bool last = j + 1 == n_;
    const Mat3 lr = last ? Mat3(fr[j].transpose() * tool_.linear()) : Mat3(fr[j].transpose() * fr[j + 1]);
    const Vec3 lt = fr[j].transpose() * ((last ? tool_.translation() : p_[j + 1]) - p_[j]);
    double theta = 0, alpha = 0, phi = 0;
    if (!last) {
      // lr = Rz(theta) Rx(alpha) Rz(phi): the third column is (s_theta s_alpha, -c_theta s_alpha, c_alpha)
      const double sa = std::hypot(lr(0, 2), lr(1, 2));
      theta = sa > 0 ? std::atan2(lr(0, 2), -lr(1, 2)) : 0.0;
      alpha = std::atan2(sa, lr(2, 2));
      // phi from what is left, so that the product is lr to rounding even when alpha is tiny
      const Mat3 rest = (Eigen::AngleAxisd(theta, Vec3::UnitZ()) * Eigen::AngleAxisd(alpha, Vec3::UnitX()))
                            .toRotationMatrix()
                            .transpose() *
                        lr;
      phi = std::atan2(rest(1, 0), rest(0, 0));
    } else {
      last_r_ = lr;
    }
    const Mat3 rz_back = Eigen::AngleAxisd(-theta, Vec3::UnitZ()).toRotationMatrix();
    l.offset = carried + theta;
    offset_cs_[j] = {std::cos(l.offset), std::sin(l.offset)};
    carried = phi;
    l.ca = std::cos(alpha);
    l.sa = std::sin(alpha);
    l.t = rz_back * lt;
    const JointSpec& js = spec_.joints[j];
    l.m = js.mass_kg;
    l.mc = js.mass_kg * (rz_back * (fr[j].transpose() * (js.com - p_[j])));
    if (last && spec_.payload_kg > 0) {
      const Vec3 pc = tool_ * spec_.payload_com;
      l.m += spec_.payload_kg;
      l.mc += spec_.payload_kg * (fr[j].transpose() * (pc - p_[j]));  // theta = 0 on the last joint
    }
  }
}

// The KDL chain: one segment per joint with identity tip (POE form), then the fixed tool.
void Model::build_kdl_chain() {
  chain_ = std::make_unique<KDL::Chain>();
  for (int j = 0; j < n_; ++j) {
    const Vec3& p = p_[j];
    const Vec3& w = w_[j];
    KDL::Joint joint(spec_.joints[j].name.empty() ? "joint" + std::to_string(j + 1) : spec_.joints[j].name,
                     KDL::Vector(p[0], p[1], p[2]), KDL::Vector(w[0], w[1], w[2]), KDL::Joint::RotAxis);
    chain_->addSegment(KDL::Segment("link" + std::to_string(j + 1), joint, KDL::Frame::Identity()));
  }
  const Mat3& tr = tool_.linear();
  const Vec3& tt = tool_.translation();
  KDL::Frame tf(KDL::Rotation(tr(0, 0), tr(0, 1), tr(0, 2), tr(1, 0), tr(1, 1), tr(1, 2), tr(2, 0), tr(2, 1), tr(2, 2)),
                KDL::Vector(tt[0], tt[1], tt[2]));
  chain_->addSegment(KDL::Segment("tool", KDL::Joint(KDL::Joint::Fixed), tf));
}

Model::~Model() = default;

int Model::compliance_count() const {
  int c = 0;
  for (int j = 0; j < n_; ++j) c += loaded_[j];
  return c;
}

bool Model::within_limits_deg(const VecQ& q, double tol) const {
  for (int j = 0; j < n_; ++j)
    if (q[j] < spec_.joints[j].lower_deg - tol || q[j] > spec_.joints[j].upper_deg + tol) return false;
  return true;
}

}  // namespace kincal
