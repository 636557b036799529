#include "kincal/model/model.hpp"

#include "kincal/core/fastmath.hpp"
#include "kincal/ik/ik.hpp"

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace kincal {

using json = nlohmann::json;


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
  // Effects: joint_compliance entries set the joints' compliance; the others are checked and kept
  {
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
      if (ev.effect.name == "joint_compliance") {
        spec_.joints[ev.effect.joint].compliance_deg_per_knm = ev.p[0];
        continue;
      }
      rest.push_back(ev);
      if (ev.effect.name == "thermal_expansion") {
        thermal_alpha_ = ev.p[0];
      } else {
        joint_effects_.push_back(ev);
        needs_dir_ = needs_dir_ || ev.effect.name == "backlash";
      }
    }
    spec_.effects = rest;
    if (!std::isfinite(spec_.t_ref_c)) throw InputError(who + "the reference temperature is NaN or infinite");
  }
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
      !std::isfinite(spec_.payload_kg) || !finite(spec_.base_in_instrument.xyz) ||
      !finite(spec_.base_in_instrument.abc))
    throw InputError(who + "a tool, payload, gravity or base value is NaN or infinite");
  if (!spec_.home_deg.empty() && static_cast<int>(spec_.home_deg.size()) != n_)
    throw InputError(who + "home has " + std::to_string(spec_.home_deg.size()) + " angles for " +
                     std::to_string(n_) + " joints");
  tool_ = pose_to_iso(spec_.tool);
  base_in_instrument_ = pose_to_iso(spec_.base_in_instrument);
  g_ = spec_.gravity;

  // Gravity-loaded joints: all but a leading run of joints whose axes stay along gravity.
  bool upstream_vertical = g_.norm() > 0;
  for (int j = 0; j < n_; ++j) {
    upstream_vertical = upstream_vertical && parallel(w_[j], g_.normalized(), 1e-9);
    loaded_[j] = !upstream_vertical;
    if (!loaded_[j] && spec_.joints[j].compliance_deg_per_knm != 0)
      throw InputError(who + "joint " + std::to_string(j + 1) +
                       " has a compliance but its axis is along gravity (no gravity torque)");
    has_compliance_ = has_compliance_ || spec_.joints[j].compliance_deg_per_knm != 0;
  }

  // Compiled evaluator: a local frame F_j along every axis, T(q) = C0 Rz(q1) L1 Rz(q2) L2 ... Rz(qn) Ln
  // with constant L_j = F_j^T F_{j+1} (L_n to the tool); then every link rotation but the last written
  // as Rz(theta) Rx(alpha) Rz(phi) and the Rz merged into the joints: Rz(q_j) Trans(t_j) Rz(theta_j)
  // = Rz(q_j + theta_j) Trans(Rz(-theta_j) t_j), and Rz(phi_j) Rz(q_{j+1}) = Rz(q_{j+1} + phi_j).
  // The local frame of joint j becomes F_j Rz(theta_j), in which its link data are written.
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

  // The KDL chain: one segment per joint with identity tip (POE form), then the fixed tool.
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

  // Closed-form IK structure: 6 joints, axes 2 and 3 parallel, axes 4, 5, 6 meeting in one point.
  if (n_ != 6) {
    ik_.reason = "closed-form IK needs 6 joints";
  } else if (!parallel(w_[1], w_[2], 1e-9)) {
    ik_.reason = "axes 2 and 3 are not parallel";
  } else if (parallel(w_[0], w_[1], 1e-6)) {
    ik_.reason = "axes 1 and 2 are parallel";
  } else if (parallel(w_[2], w_[3], 1e-6) || parallel(w_[3], w_[4], 1e-6) || parallel(w_[4], w_[5], 1e-6)) {
    ik_.reason = "consecutive wrist axes are parallel";
  } else {
    Mat3 a = Mat3::Zero();
    Vec3 b = Vec3::Zero();
    for (int j = 3; j < 6; ++j) {
      const Mat3 pr = Mat3::Identity() - w_[j] * w_[j].transpose();
      a += pr;
      b += pr * p_[j];
    }
    const Vec3 c = a.ldlt().solve(b);
    double dmax = 0;
    for (int j = 3; j < 6; ++j) dmax = std::max(dmax, ((Mat3::Identity() - w_[j] * w_[j].transpose()) * (c - p_[j])).norm());
    if (dmax > 1e-6) {
      ik_.reason = "axes 4, 5 and 6 do not meet in one point (off by " + std::to_string(dmax) + " mm)";
    } else {
      ik_.spherical_wrist_parallel_23 = true;
      ik_.wrist_center = c;
      fill_ik_constants(ik_, w_.data(), p_.data());
    }
  }
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

// ---------------------------------------------------------------------------------------------
// The built-in KR 500-class robot.
//
// Geometry: the public nominal dimensions of the KUKA KR 500 R2830 (KR 500 FORTEC) as drawn in
// KUKA's specification "KR 500 FORTEC" (working envelope drawing): A1-A2 offset 500 mm, A2 height
// 1045 mm above the mounting face, upper arm 1300 mm, A3-A4 offset 55 mm, forearm 1025 mm, wrist
// centre to flange 290 mm. Axis ranges and speeds from the same specification (A1 +-185 deg at
// 79 deg/s, A2 -130..+20 at 75, A3 -100..+144 at 70, A4 +-350 at 90, A5 +-120 at 90, A6 +-350 at
// 143). KUKA publishes no acceleration or jerk limits: ours are assumptions (full speed in 0.5 s,
// full acceleration in 0.1 s) and are marked so in the README; a limits file overrides them.
// Link masses and centres of mass are assumptions scaled to the robot's published 2.4 t; the
// payload is a tape-laying head of 300 kg (the Samak paper's KR 500 carries a Mikrosam ATL head),
// TCP 350 mm out from the flange. Zero configuration: arm stretched horizontally along +x, axes in
// KUKA's sense (A1 about -z, A2, A3, A5 about +y, A4, A6 about -x).
// ---------------------------------------------------------------------------------------------
ModelSpec kr500_spec() {
  ModelSpec s;
  s.name = "kr500";
  const double a1 = 500, d1 = 1045, a2 = 1300, a3 = 55, d4 = 1025, d6 = 290;
  const Vec3 wc(a1 + a2 + d4, 0, d1 + a3);
  struct Row {
    const char* name;
    Vec3 point, axis;
    double lo, hi, v, m;
    Vec3 com;
  };
  const Row rows[6] = {
      {"A1", Vec3(0, 0, 0), Vec3(0, 0, -1), -185, 185, 79, 700, Vec3(250, 0, 600)},
      {"A2", Vec3(a1, 0, d1), Vec3(0, 1, 0), -130, 20, 75, 350, Vec3(a1 + 650, 0, d1)},
      {"A3", Vec3(a1 + a2, 0, d1), Vec3(0, 1, 0), -100, 144, 70, 250, Vec3(a1 + a2 + 250, 0, d1 + a3)},
      {"A4", wc, Vec3(-1, 0, 0), -350, 350, 90, 60, Vec3(wc[0] - 300, 0, wc[2])},
      {"A5", wc, Vec3(0, 1, 0), -120, 120, 90, 30, wc},
      {"A6", wc, Vec3(-1, 0, 0), -350, 350, 143, 5, Vec3(wc[0] + d6 - 20, 0, wc[2])},
  };
  for (const Row& r : rows) {
    JointSpec j;
    j.name = r.name;
    j.point = r.point;
    j.axis = r.axis;
    j.lower_deg = r.lo;
    j.upper_deg = r.hi;
    j.max_velocity_deg_s = r.v;
    j.max_acceleration_deg_s2 = 2 * r.v;   // assumption: full speed in 0.5 s
    j.max_jerk_deg_s3 = 20 * r.v;          // assumption: full acceleration in 0.1 s
    j.mass_kg = r.m;
    j.com = r.com;
    s.joints.push_back(j);
  }
  // Tape-laying head: TCP 350 mm beyond the flange on the flange axis, tool z along the flange axis.
  s.tool.xyz = Vec3(wc[0] + d6 + 350, 0, wc[2]);
  s.tool.abc = Vec3(0, 90, 0);
  s.payload_kg = 300;
  s.payload_com = Vec3(0, 0, -150);  // between flange and TCP, in the tool frame
  s.home_deg = {0, -90, 90, 0, 90, 0};  // KUKA's upright home with the head pointing down
  return s;
}

// ---------------------------------------------------------------------------------------------
// Built-in UR10 (Universal Robots, CB3 generation): the standard Denavit-Hartenberg parameters
// Universal Robots publishes ("DH parameters for calculations of kinematics and dynamics": d1 =
// 127.3 mm, a2 = -612 mm, a3 = -572.3 mm, d4 = 163.941 mm, d5 = 115.7 mm, d6 = 92.2 mm, alpha =
// 90, 0, 0, 90, -90, 0 deg; link masses 7.1, 12.7, 4.27, 2.0, 2.0, 0.365 kg with the centres of mass
// of the same page), joint ranges +-360 deg, speeds 120 deg/s (base, shoulder) and 180 deg/s
// (elbow, wrists) from the UR10 data sheet. Zero configuration and joint senses are UR's, so the
// angles a UR controller reports apply unchanged. The tool is the flange (tool0). Not a spherical
// wrist: no closed-form IK; identification and compensation do not need one.
// ---------------------------------------------------------------------------------------------
ModelSpec ur10_spec() {
  ModelSpec s;
  s.name = "ur10";
  const double d[6] = {127.3, 0, 0, 163.941, 115.7, 92.2};
  const double a[6] = {0, -612.0, -572.3, 0, 0, 0};
  const double alpha[6] = {kPi / 2, 0, 0, kPi / 2, -kPi / 2, 0};
  const double mass[6] = {7.1, 12.7, 4.27, 2.0, 2.0, 0.365};
  const Vec3 com[6] = {Vec3(21, 0, 27), Vec3(380, 0, 158), Vec3(240, 0, 68),
                       Vec3(0, 7, 18), Vec3(0, 7, 18), Vec3(0, 0, -26)};
  const double vel[6] = {120, 120, 180, 180, 180, 180};
  const char* names[6] = {"shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"};
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 6; ++i) {
    JointSpec j;
    j.name = names[i];
    j.point = t.translation();
    j.axis = t.linear().col(2);
    // DH frame i: Rz(theta) Tz(d) Tx(a) Rx(alpha) at theta = 0
    t = t * Eigen::Translation3d(0, 0, d[i]) * Eigen::Translation3d(a[i], 0, 0) *
        Eigen::AngleAxisd(alpha[i], Vec3::UnitX());
    j.lower_deg = -360;
    j.upper_deg = 360;
    j.max_velocity_deg_s = vel[i];
    j.max_acceleration_deg_s2 = 2 * vel[i];  // assumption, as for kr500
    j.max_jerk_deg_s3 = 20 * vel[i];
    j.mass_kg = mass[i];
    j.com = t * com[i];
    s.joints.push_back(j);
  }
  s.tool = iso_to_pose(t);
  s.home_deg = {0, -90, 90, -90, -90, 0};
  return s;
}

std::vector<std::string> builtin_names() { return {"kr500", "ur10"}; }

ModelSpec builtin_spec(const std::string& name) {
  if (name == "kr500") return kr500_spec();
  if (name == "ur10") return ur10_spec();
  std::string known;
  for (const auto& n : builtin_names()) known += (known.empty() ? "" : ", ") + n;
  throw InputError("unknown robot '" + name + "': not a built-in name (" + known +
                   "), a .urdf file or a model .json file");
}

// ---------------------------------------------------------------------------------------------
// Model JSON
// ---------------------------------------------------------------------------------------------
namespace {

json v3(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }
json pose_json(const Pose6& p) { return json{{"xyz_mm", v3(p.xyz)}, {"abc_deg", v3(p.abc)}}; }

json effect_json(const Effect& e, const std::vector<double>& p) {
  json params = json::array();
  const auto names = e.parameter_names();
  const auto units = e.file_units();
  const auto scale = e.file_scale();
  for (size_t k = 0; k < p.size(); ++k)
    params.push_back(json{{"name", names[k]}, {"value", p[k] * scale[k]}, {"unit", units[k]}});
  json o{{"effect", e.name}, {"joint", e.joint >= 0 ? json(e.joint + 1) : json(nullptr)}, {"parameters", params}};
  if (e.name == "transmission_error") o["harmonics"] = e.harmonics;
  return o;
}

/// Version 2: every effect of the model, compliance included (effect, joint from 1, parameters with
/// units of the file: degrees, not radians)
json effects_json(const ModelSpec& s) {
  json out = json::array();
  for (size_t j = 0; j < s.joints.size(); ++j)
    if (s.joints[j].compliance_deg_per_knm != 0)
      out.push_back(effect_json(Effect{"joint_compliance", static_cast<int>(j), {}}, {s.joints[j].compliance_deg_per_knm}));
  for (const EffectValue& ev : s.effects) out.push_back(effect_json(ev.effect, ev.p));
  return out;
}

json spec_json(const ModelSpec& s) {
  json joints = json::array();
  for (const JointSpec& j : s.joints) {
    joints.push_back(json{{"name", j.name},
                          {"point_mm", v3(j.point)},
                          {"axis", v3(j.axis)},
                          {"limits_deg", json::array({j.lower_deg, j.upper_deg})},
                          {"max_velocity_deg_s", j.max_velocity_deg_s},
                          {"max_acceleration_deg_s2", j.max_acceleration_deg_s2},
                          {"max_jerk_deg_s3", j.max_jerk_deg_s3},
                          {"mass_kg", j.mass_kg},
                          {"com_mm", v3(j.com)},
                          {"compliance_deg_per_knm", j.compliance_deg_per_knm}});
  }
  return json{{"name", s.name},
              {"joints", joints},
              {"tool", pose_json(s.tool)},
              {"payload", json{{"mass_kg", s.payload_kg}, {"com_mm", v3(s.payload_com)}}},
              {"gravity_m_s2", v3(s.gravity)},
              {"base_in_instrument", pose_json(s.base_in_instrument)},
              {"home_deg", s.home_deg},
              {"effects", effects_json(s)},
              {"t_ref_c", s.t_ref_c}};
}

struct Reader {
  std::string source;
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InputError(source + ": " + where + ": " + what);
  }
  const json& at(const json& o, const char* key, const std::string& where) const {
    if (!o.is_object() || !o.contains(key)) fail(where, std::string("missing key '") + key + "'");
    return o.at(key);
  }
  double num(const json& o, const char* key, const std::string& where) const {
    const json& v = at(o, key, where);
    if (!v.is_number()) fail(where + "." + key, "not a number");
    return v.get<double>();
  }
  Vec3 vec(const json& o, const char* key, const std::string& where) const {
    const json& v = at(o, key, where);
    if (!v.is_array() || v.size() != 3) fail(where + "." + key, "needs 3 numbers");
    Vec3 r;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number()) fail(where + "." + key, "needs 3 numbers");
      r[i] = v[i].get<double>();
    }
    return r;
  }
  Pose6 pose(const json& o, const char* key, const std::string& where) const {
    const json& v = at(o, key, where);
    return Pose6{vec(v, "xyz_mm", where + "." + key), vec(v, "abc_deg", where + "." + key)};
  }
  ModelSpec spec(const json& o, const std::string& where) const {
    ModelSpec s;
    const json& name = at(o, "name", where);
    if (!name.is_string()) fail(where + ".name", "not a string");
    s.name = name.get<std::string>();
    const json& joints = at(o, "joints", where);
    if (!joints.is_array() || joints.empty()) fail(where + ".joints", "needs a non-empty list");
    for (size_t i = 0; i < joints.size(); ++i) {
      const std::string w = where + ".joints[" + std::to_string(i) + "]";
      const json& jo = joints[i];
      JointSpec j;
      if (jo.contains("name") && jo["name"].is_string()) j.name = jo["name"].get<std::string>();
      j.point = vec(jo, "point_mm", w);
      j.axis = vec(jo, "axis", w);
      const json& lim = at(jo, "limits_deg", w);
      if (!lim.is_array() || lim.size() != 2 || !lim[0].is_number() || !lim[1].is_number())
        fail(w + ".limits_deg", "needs [lower, upper]");
      j.lower_deg = lim[0].get<double>();
      j.upper_deg = lim[1].get<double>();
      j.max_velocity_deg_s = num(jo, "max_velocity_deg_s", w);
      j.max_acceleration_deg_s2 = num(jo, "max_acceleration_deg_s2", w);
      j.max_jerk_deg_s3 = num(jo, "max_jerk_deg_s3", w);
      j.mass_kg = num(jo, "mass_kg", w);
      j.com = vec(jo, "com_mm", w);
      j.compliance_deg_per_knm = num(jo, "compliance_deg_per_knm", w);
      s.joints.push_back(j);
    }
    s.tool = pose(o, "tool", where);
    const json& pl = at(o, "payload", where);
    s.payload_kg = num(pl, "mass_kg", where + ".payload");
    s.payload_com = vec(pl, "com_mm", where + ".payload");
    s.gravity = vec(o, "gravity_m_s2", where);
    s.base_in_instrument = pose(o, "base_in_instrument", where);
    const json& home = at(o, "home_deg", where);
    if (!home.is_array()) fail(where + ".home_deg", "needs a list");
    for (const json& h : home) {
      if (!h.is_number()) fail(where + ".home_deg", "needs numbers");
      s.home_deg.push_back(h.get<double>());
    }
    if (o.contains("t_ref_c")) s.t_ref_c = num(o, "t_ref_c", where);
    if (o.contains("effects")) {
      const json& effs = o["effects"];
      if (!effs.is_array()) fail(where + ".effects", "needs a list");
      for (size_t i = 0; i < effs.size(); ++i) s.effects.push_back(effect(effs[i], where + ".effects[" + std::to_string(i) + "]"));
    }
    return s;
  }
  EffectValue effect(const json& eo, const std::string& w) const {
    EffectValue ev;
    const json& name = at(eo, "effect", w);
    if (!name.is_string()) fail(w + ".effect", "not a string");
    ev.effect.name = name.get<std::string>();
    try {
      effect_kind(ev.effect.name);
    } catch (const InputError& e) {
      fail(w + ".effect", e.what());
    }
    const json& joint = at(eo, "joint", w);
    if (joint.is_null()) {
      ev.effect.joint = -1;
    } else if (joint.is_number_integer()) {
      ev.effect.joint = joint.get<int>() - 1;
    } else {
      fail(w + ".joint", "needs a joint number (from 1) or null");
    }
    if (eo.contains("harmonics")) {
      const json& h = eo["harmonics"];
      if (!h.is_array()) fail(w + ".harmonics", "needs a list of orders");
      ev.effect.harmonics.clear();
      for (const json& k : h) {
        if (!k.is_number_integer()) fail(w + ".harmonics", "needs integer orders");
        ev.effect.harmonics.push_back(k.get<int>());
      }
    }
    if (ev.effect.name != "transmission_error") ev.effect.harmonics.clear();
    const json& params = at(eo, "parameters", w);
    if (!params.is_array()) fail(w + ".parameters", "needs a list");
    const auto names = ev.effect.parameter_names();
    const auto units = ev.effect.file_units();
    const auto scale = ev.effect.file_scale();
    if (params.size() != names.size())
      fail(w + ".parameters", std::to_string(params.size()) + " values for " + std::to_string(names.size()) + " parameters");
    for (size_t k = 0; k < params.size(); ++k) {
      const std::string pw = w + ".parameters[" + std::to_string(k) + "]";
      const json& n = at(params[k], "name", pw);
      if (!n.is_string() || n.get<std::string>() != names[k]) fail(pw + ".name", "expected '" + names[k] + "'");
      const json& u = at(params[k], "unit", pw);
      if (!u.is_string() || u.get<std::string>() != units[k]) fail(pw + ".unit", "expected '" + units[k] + "'");
      ev.p.push_back(num(params[k], "value", pw) / scale[k]);
    }
    return ev;
  }
};

}  // namespace

std::string spec_to_json(const ModelSpec& spec) { return spec_json(spec).dump(2); }

std::string robot_to_json(const Robot& robot) {
  json o{{"format", "kincal-model"}, {"version", 2}, {"nominal", spec_json(robot.nominal->spec())}};
  if (robot.identified()) o["calibrated"] = spec_json(robot.calibrated->spec());
  return o.dump(2) + "\n";
}

Robot robot_from_json(const std::string& text, const std::string& source) {
  json o;
  try {
    o = json::parse(text);
  } catch (const json::parse_error& e) {
    // nlohmann reports a byte offset; turn it into line:column
    size_t line = 1, col = 1;
    for (size_t i = 0; i < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw InputError(source + ":" + std::to_string(line) + ":" + std::to_string(col) + ": not valid JSON");
  } catch (const json::exception& e) {  // e.g. a number out of range (1e999)
    throw InputError(source + ": not valid JSON (" + e.what() + ")");
  }
  Reader r{source};
  if (!o.is_object() || !o.contains("format") || o["format"] != "kincal-model")
    throw InputError(source + ": not a kincal model (\"format\": \"kincal-model\" missing)");
  if (!o.contains("version") || !o["version"].is_number_integer() || o["version"].get<int>() < 1 ||
      o["version"].get<int>() > 2)
    throw InputError(source + ": model version " + (o.contains("version") ? o["version"].dump() : "missing") +
                     " is not supported (this kincal reads versions 1 and 2)");
  Robot robot;
  try {
    robot.nominal = std::make_shared<Model>(r.spec(r.at(o, "nominal", "model"), "nominal"));
    robot.calibrated = o.contains("calibrated")
                           ? std::make_shared<Model>(r.spec(o["calibrated"], "calibrated"))
                           : robot.nominal;
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.rfind(source, 0) == 0) throw;
    throw InputError(source + ": " + m);
  }
  if (robot.calibrated->dof() != robot.nominal->dof())
    throw InputError(source + ": nominal and calibrated models have different joint counts");
  return robot;
}

Robot load_robot(const std::string& name) {
  auto ends_with = [&](const char* s) {
    const std::string e(s);
    return name.size() >= e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
  };
  if (ends_with(".json")) {
    std::ifstream f(name);
    if (!f) throw InputError(name + ": cannot open the model file");
    std::stringstream ss;
    ss << f.rdbuf();
    return robot_from_json(ss.str(), name);
  }
  if (ends_with(".urdf"))
    throw InputError(name + ": URDF robots are read by the Python package (kincal); convert with "
                     "`kincal fk`/`identify` to a model .json for kincal-compensate");
  auto m = std::make_shared<Model>(builtin_spec(name));
  return Robot{m, m};
}

}  // namespace kincal

#include <random>

namespace kincal {

ModelSpec perturbed_spec(const ModelSpec& spec, unsigned seed, double sigma_mm, double sigma_deg, double compliance) {
  ModelSpec s = spec;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> ud(0.5, 1.5);
  const Model m(spec);
  for (int j = 0; j < m.dof(); ++j) {
    JointSpec& js = s.joints[j];
    const Vec3 w = m.axis(j);
    const Vec3 u = w.unitOrthogonal(), v = w.cross(u);
    const Vec3 tilt = (nd(rng) * u + nd(rng) * v) * sigma_deg * kDeg;
    js.axis = Eigen::AngleAxisd(tilt.norm(), tilt.norm() > 0 ? tilt.normalized() : u) * w;
    js.point += (nd(rng) * u + nd(rng) * v) * sigma_mm;
    if (compliance > 0 && m.gravity_loaded(j)) js.compliance_deg_per_knm = compliance * ud(rng);
  }
  for (int k = 0; k < 3; ++k) s.tool.xyz[k] += nd(rng) * sigma_mm;
  for (int k = 0; k < 3; ++k) s.tool.abc[k] += nd(rng) * sigma_deg;
  s.name = spec.name + "-perturbed";
  return s;
}

}  // namespace kincal
