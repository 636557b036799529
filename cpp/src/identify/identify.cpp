// kincal: measurement files, the campaign simulator and Ceres identification.
// With fivebar_fit.cpp one of the two translation units that include Ceres (builds stay quick).
#include "kincal/identify/identify.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <thread>

namespace kincal {

namespace {

Mat3 skew(const Vec3& v) {
  Mat3 s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

Mat3 so3_exp(const Vec3& phi) {
  const double th = phi.norm();
  if (th < 1e-300) return Mat3::Identity();
  return Eigen::AngleAxisd(th, phi / th).toRotationMatrix();
}

Vec3 so3_log(const Mat3& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

/// Right Jacobian of SO(3): Exp(phi + d) = Exp(phi) Exp(Jr(phi) d) to first order.
Mat3 so3_right_jacobian(const Vec3& phi) {
  const double th = phi.norm();
  const Mat3 s = skew(phi);
  double a, b;
  if (th < 1e-4) {
    a = 0.5 - th * th / 24.0;
    b = 1.0 / 6.0 - th * th / 120.0;
  } else {
    a = (1.0 - std::cos(th)) / (th * th);
    b = (th - std::sin(th)) / (th * th * th);
  }
  return Mat3::Identity() - a * s + b * s * s;
}

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Measurement files
// ---------------------------------------------------------------------------------------------
namespace {
MeasurementSet measurements_from_table(const CsvTable& t, int dof) {
  const std::string& source = t.source;
  MeasurementSet m;
  m.source = source;
  const int cpose = t.require("pose");
  std::vector<int> cq;
  for (int j = 0; j < dof; ++j) cq.push_back(t.require("q" + std::to_string(j + 1)));
  if (t.find("q" + std::to_string(dof + 1)) >= 0)
    throw InputError(source + ":1: column q" + std::to_string(dof + 1) + " but the robot has " +
                     std::to_string(dof) + " joints");
  const int cx = t.require("x"), cy = t.require("y"), cz = t.require("z");
  const int ca = t.find("a"), cb = t.find("b"), cc = t.find("c");
  const bool abc = ca >= 0 && cb >= 0 && cc >= 0;
  if (!abc && (ca >= 0 || cb >= 0 || cc >= 0))
    throw InputError(source + ":1: an orientation needs all three columns a, b, c");
  m.orientation = abc;
  const int ctarget = t.find("target"), cpay = t.find("payload_kg"), ctemp = t.find("temperature_c");
  std::vector<int> cdir;
  for (int j = 0; j < dof; ++j) cdir.push_back(t.find("dir" + std::to_string(j + 1)));
  const bool have_dir = std::all_of(cdir.begin(), cdir.end(), [](int c) { return c >= 0; });
  int max_target = 0;
  for (size_t r = 0; r < t.cells.size(); ++r) {
    Measurement row;
    const double pid = t.number(r, cpose);
    if (pid != std::floor(pid)) throw InputError(t.where(r) + ": column 'pose': not an integer");
    row.pose = static_cast<int>(pid);
    row.q_deg.resize(dof);
    for (int j = 0; j < dof; ++j) row.q_deg[j] = t.number(r, cq[j]);
    row.xyz = Vec3(t.number(r, cx), t.number(r, cy), t.number(r, cz));
    if (abc) {
      row.has_abc = true;
      row.abc = Vec3(t.number(r, ca), t.number(r, cb), t.number(r, cc));
    }
    if (ctarget >= 0) {
      const double tv = t.number(r, ctarget);
      if (tv < 0 || tv != std::floor(tv) || tv > 99)
        throw InputError(t.where(r) + ": column 'target': expected an integer 0..99");
      row.target = static_cast<int>(tv);
      max_target = std::max(max_target, row.target);
    }
    if (cpay >= 0) {
      row.payload_kg = t.number(r, cpay);
      if (row.payload_kg < 0) throw InputError(t.where(r) + ": column 'payload_kg': negative mass");
    }
    if (ctemp >= 0) row.temperature_c = t.number(r, ctemp);
    if (have_dir) {
      row.dir.resize(dof);
      for (int j = 0; j < dof; ++j) {
        row.dir[j] = t.number(r, cdir[j]);
        if (row.dir[j] != 1 && row.dir[j] != -1)
          throw InputError(t.where(r) + ": column 'dir" + std::to_string(j + 1) + "': expected +1 or -1");
      }
    }
    row.line = t.line[r];
    m.rows.push_back(row);
  }
  if (m.rows.empty()) throw InputError(source + ": no measurements");
  m.n_targets = max_target + 1;
  return m;
}

}  // namespace

MeasurementSet parse_measurements(const std::string& text, const std::string& source, int dof) {
  return measurements_from_table(parse_csv(text, source), dof);
}

MeasurementSet read_measurements(const std::string& path, int dof) {
  return measurements_from_table(read_csv(path), dof);
}

std::string format_measurements(const MeasurementSet& m, int dof) {
  std::string s = "pose";
  for (int j = 0; j < dof; ++j) s += ",q" + std::to_string(j + 1);
  s += m.orientation ? ",x,y,z,a,b,c,target" : ",x,y,z,target";
  bool pay = false;
  for (const auto& r : m.rows) pay = pay || !std::isnan(r.payload_kg);
  if (pay) s += ",payload_kg";
  const bool dir = !m.rows.empty() && m.rows[0].dir.size() == dof;
  const bool temp = !m.rows.empty() && !std::isnan(m.rows[0].temperature_c);
  if (temp) s += ",temperature_c";
  if (dir)
    for (int j = 0; j < dof; ++j) s += ",dir" + std::to_string(j + 1);
  s += "\n";
  for (const auto& r : m.rows) {
    s += std::to_string(r.pose);
    for (int j = 0; j < dof; ++j) s += "," + fmt(r.q_deg[j]);
    for (int k = 0; k < 3; ++k) s += "," + fmt(r.xyz[k]);
    if (m.orientation)
      for (int k = 0; k < 3; ++k) s += "," + fmt(r.abc[k]);
    s += "," + std::to_string(r.target);
    if (pay) s += "," + fmt(r.payload_kg);
    if (temp) s += "," + fmt(r.temperature_c);
    if (dir)
      for (int j = 0; j < dof; ++j) s += r.dir[j] > 0 ? ",1" : ",-1";
    s += "\n";
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Simulation: every effect of the truth in one place
// ---------------------------------------------------------------------------------------------
namespace {

/// Joint-angle offsets (rad) of the effects at a row, and the thermal scale factor.
void effect_offsets(const std::vector<Effect>& eff, const double* p, const Measurement& m, double t_ref, VecQ& dq,
                    double& scale) {
  scale = 1.0;
  double b[128];
  for (const Effect& e : eff) {
    if (e.name == "thermal_expansion") {
      if (std::isnan(m.temperature_c)) throw InputError("thermal_expansion needs the temperature_c column");
      scale *= 1.0 + p[0] * (m.temperature_c - t_ref);
    } else {
      if (e.name == "backlash" && m.dir.size() != m.q_deg.size()) throw InputError("backlash needs the dir1..dirN columns");
      joint_basis(e, m.q_deg[e.joint] * kDeg, e.name == "backlash" ? m.dir[e.joint] : 0.0, b);
      for (int k = 0; k < e.size(); ++k) dq[e.joint] += p[k] * b[k];
    }
    p += e.size();
  }
}

/// The context of a row for the model's effects (its dir and temperature).
EffectContext row_context(const Measurement& row) {
  EffectContext c;
  c.dir = row.dir;
  c.temperature_c = row.temperature_c;
  return c;
}

}  // namespace

Vec3 simulate_point(const Model& truth, const Measurement& row, const Vec3& target) {
  const EffectContext ctx = row_context(row);
  const Eigen::Isometry3d tool = fk(truth, joint_angles(truth, row.q_deg * kDeg, ctx));
  // thermal expansion: every length of the robot, the target's offset included, scales
  return truth.base_in_instrument() * (length_scale(truth, ctx) * (tool * target));
}

ModelSpec with_effects(const ModelSpec& truth, const std::vector<EffectValue>& effects, double t_ref) {
  ModelSpec s = truth;
  if (effects.empty()) return s;
  bool thermal = false;
  for (const auto& e : s.effects) thermal = thermal || e.effect.name == "thermal_expansion";
  if (!thermal) s.t_ref_c = t_ref;
  for (const auto& e : effects) s.effects.push_back(e);
  return s;
}

MeasurementSet simulate(const Model& truth_in, const SimulationOptions& opt) {
  if (opt.poses < 1) throw InputError("simulate: the number of poses must be positive");
  const Model truth(with_effects(truth_in.spec(), opt.effects, opt.t_ref));
  if (opt.targets.empty()) throw InputError("simulate: at least one target");
  MeasurementSet m;
  m.source = "simulated";
  m.n_targets = static_cast<int>(opt.targets.size());
  m.orientation = opt.orientation_noise_deg >= 0;
  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> ud(-0.5, 0.5), u01(0.0, 1.0);
  std::normal_distribution<double> nd(0.0, 1.0);
  const int n = truth.dof();
  for (int p = 0; p < opt.poses; ++p) {
    VecQ q(n);
    for (int j = 0; j < n; ++j) {
      const JointSpec& js = truth.spec().joints[j];
      const double mid = 0.5 * (js.lower_deg + js.upper_deg), span = js.upper_deg - js.lower_deg;
      q[j] = mid + ud(rng) * span * opt.limit_margin;
    }
    VecQ dir(n);
    for (int j = 0; j < n; ++j) dir[j] = u01(rng) < 0.5 ? -1.0 : 1.0;
    // the temperature drifts through [t_min, t_max] over the campaign (a warm-up, then noise)
    const double frac = opt.poses > 1 ? static_cast<double>(p) / (opt.poses - 1) : 0.0;
    const double temp = opt.t_min + (opt.t_max - opt.t_min) * std::sqrt(frac) + 0.3 * nd(rng);
    for (int t = 0; t < m.n_targets; ++t) {
      Measurement row;
      row.pose = p;
      row.q_deg = q;
      row.dir = dir;
      row.temperature_c = temp;
      row.target = t;
      row.xyz = simulate_point(truth, row, opt.targets[t]);
      row.xyz += Vec3(nd(rng), nd(rng), nd(rng)) * opt.noise_mm;
      if (opt.orientation_noise_deg >= 0) {
        // the measured tool frame (a 6-D probe): truth orientation, then a small random rotation
        const Mat3 r = truth.base_in_instrument().linear() * fk_model(truth, row.q_deg * kDeg, row_context(row)).linear();
        const Vec3 e = Vec3(nd(rng), nd(rng), nd(rng)) * opt.orientation_noise_deg * kDeg;
        row.has_abc = true;
        row.abc = rotation_to_abc(so3_exp(e) * r);
      }
      if (opt.outlier_fraction > 0 && u01(rng) < opt.outlier_fraction)
        row.xyz += Vec3(nd(rng), nd(rng), nd(rng)).normalized() * opt.outlier_mm;
      m.rows.push_back(row);
    }
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// Parameter layout and the measurement model
// ---------------------------------------------------------------------------------------------
ParamLayout::ParamLayout(const Model& nominal, int nt, const std::vector<Effect>& eff, double tr)
    : dof(nominal.dof()), n_targets(nt), effect_list(eff), t_ref(tr) {
  for (int j = 0; j < dof; ++j)
    if (nominal.gravity_loaded(j)) loaded.push_back(j);
  joints = 0;
  compliance = 4 * dof;
  tool = compliance + static_cast<int>(loaded.size());
  base = tool + 6;
  targets = base + 6;
  effects = targets + 3 * n_targets;
  size = effects;
  for (const Effect& e : effect_list) {
    check_effect(e, dof, "");
    if (e.name == "joint_compliance")
      throw InputError("joint_compliance is identified through IdentifyOptions::compliance, not as an extra effect");
    effect_offset.push_back(size);
    size += e.size();
  }
  for (int j = 0; j < dof; ++j) {
    const std::string p = "joint" + std::to_string(j + 1);
    for (const char* s : {".tilt_u", ".tilt_v"}) names.push_back(p + s), units.push_back("rad");
    for (const char* s : {".move_u", ".move_v"}) names.push_back(p + s), units.push_back("mm");
  }
  for (int j : loaded) names.push_back("joint" + std::to_string(j + 1) + ".compliance"), units.push_back("deg/kNm");
  for (const std::string f : {"tool", "base"}) {
    for (const char* s : {".x", ".y", ".z"}) names.push_back(f + s), units.push_back("mm");
    for (const char* s : {".rx", ".ry", ".rz"}) names.push_back(f + s), units.push_back("rad");
  }
  for (int t = 0; t < n_targets; ++t)
    for (const char* s : {".x", ".y", ".z"}) names.push_back("target" + std::to_string(t) + s), units.push_back("mm");
  for (const Effect& e : effect_list) {
    const std::string p = e.joint >= 0 ? "joint" + std::to_string(e.joint + 1) + "." : "";
    for (const auto& n : e.parameter_names()) names.push_back(p + n);
    for (const auto& u : e.units()) units.push_back(u);
  }
}

PointModel::PointModel(const Model& nominal, int n_targets, const std::vector<Effect>& effects, double t_ref)
    : nominal_(nominal), layout_(nominal, n_targets, effects, t_ref) {
  const int n = nominal.dof();
  for (int j = 0; j < n; ++j) {
    const Vec3 w = nominal.axis(j);
    u_.push_back(w.unitOrthogonal());
    v_.push_back(w.cross(u_.back()));
  }
  w_.resize(n);
  p_.resize(n);
  std::vector<double> x(layout_.size, 0.0);
  for (size_t i = 0; i < layout_.loaded.size(); ++i)
    x[layout_.compliance + i] = nominal.spec().joints[layout_.loaded[i]].compliance_deg_per_knm;
  set_params(x);
}

void PointModel::set_params(const std::vector<double>& x) {
  x_ = x;
  spec_ = nominal_.spec();
  spec_.effects.clear();  // the layout's effects act through x, never twice through the model
  const int n = layout_.dof;
  for (int j = 0; j < n; ++j) {
    const double* a = &x[4 * j];
    w_[j] = (nominal_.axis(j) + a[0] * u_[j] + a[1] * v_[j]).normalized();
    p_[j] = nominal_.point(j) + a[2] * u_[j] + a[3] * v_[j];
    spec_.joints[j].axis = w_[j];
    spec_.joints[j].point = p_[j];
    spec_.joints[j].compliance_deg_per_knm = 0;
  }
  for (size_t i = 0; i < layout_.loaded.size(); ++i)
    spec_.joints[layout_.loaded[i]].compliance_deg_per_knm = x[layout_.compliance + i];
  const Vec3 phim(x[layout_.tool + 3], x[layout_.tool + 4], x[layout_.tool + 5]);
  rm_ = nominal_.tool().linear() * so3_exp(phim);
  jrm_ = so3_right_jacobian(phim);
  tm_ = nominal_.tool().translation() + Vec3(x[layout_.tool], x[layout_.tool + 1], x[layout_.tool + 2]);
  const Vec3 phib(x[layout_.base + 3], x[layout_.base + 4], x[layout_.base + 5]);
  rb_ = nominal_.base_in_instrument().linear() * so3_exp(phib);
  jrb_ = so3_right_jacobian(phib);
  tb_ = nominal_.base_in_instrument().translation() + Vec3(x[layout_.base], x[layout_.base + 1], x[layout_.base + 2]);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rm_;
  t.translation() = tm_;
  spec_.tool = iso_to_pose(t);
  t.linear() = rb_;
  t.translation() = tb_;
  spec_.base_in_instrument = iso_to_pose(t);
  current_ = std::make_shared<const Model>(spec_);
  for (auto& pm : payload_models_) {
    ModelSpec s = spec_;
    s.payload_kg = pm.first;
    pm.second = std::make_shared<const Model>(s);
  }
}

void PointModel::prepare_payloads(const MeasurementSet& data) {
  std::set<double> pays;
  for (const auto& r : data.rows)
    if (!std::isnan(r.payload_kg) && r.payload_kg != spec_.payload_kg) pays.insert(r.payload_kg);
  payload_models_.clear();
  for (double p : pays) payload_models_.emplace_back(p, nullptr);
  set_params(x_);
}

const Model& PointModel::model_for(double payload) const {
  if (std::isnan(payload) || payload == spec_.payload_kg) return *current_;
  for (const auto& pm : payload_models_)
    if (pm.first == payload) return *pm.second;
  throw std::logic_error("PointModel: payload not prepared");
}

ModelSpec PointModel::spec() const { return spec_; }

// The deflection K tau(q) depends on the geometry through the gravity torque: moving a joint line
// moves the links (their centres of mass) and the axes the torque is taken about; moving the tool
// frame moves the payload. This adds d(point)/d(parameter) through K d(tau)/d(parameter).
void PointModel::chain_frames(const VecQ& q, std::array<Mat3, kMaxJoints + 1>& gr,
                              std::array<Vec3, kMaxJoints + 1>& gt) const {
  gr[0].setIdentity();
  gt[0].setZero();
  for (int j = 0; j < layout_.dof; ++j) {
    const Mat3 e = axis_rotation(w_[j], q[j]);
    const Vec3 et = p_[j] - e * p_[j];
    gr[j + 1] = gr[j] * e;
    gt[j + 1] = gr[j] * et + gt[j];
  }
}

void PointModel::gravity_state(const Model& model, const Measurement& m, GravityState& gs) const {
  const int n = layout_.dof;
  const ModelSpec& sp = model.spec();
  chain_frames(m.q_deg * kDeg, gs.gr, gs.gt);
  const auto& gr = gs.gr;
  const auto& gt = gs.gt;
  const double mp = std::isnan(m.payload_kg) ? sp.payload_kg : m.payload_kg;
  gs.mp = mp;
  // current centres of mass; S[i] = sum_{k>=i} m_k c_k, M[i] = sum_{k>=i} m_k (payload on the last link)
  gs.cp = gr[n] * (rm_ * sp.payload_com + tm_) + gt[n];
  gs.S[n] = mp * gs.cp;
  gs.M[n] = mp;
  for (int k = n - 1; k >= 0; --k) {
    const double mk = sp.joints[k].mass_kg;
    gs.S[k] = gs.S[k + 1] + mk * (gr[k + 1] * sp.joints[k].com + gt[k + 1]);
    gs.M[k] = gs.M[k + 1] + mk;
  }
  const Vec3& g = model.gravity();
  for (int j = 0; j < n; ++j) {
    gs.wc[j] = gr[j] * w_[j];
    gs.oc[j] = gr[j] * p_[j] + gt[j];
    gs.arm[j] = gs.S[j] - gs.M[j] * gs.oc[j];
    gs.tau[j] = gs.wc[j].dot(gs.arm[j].cross(g));  // N mm, the same as gravity_torque()
  }
}

void PointModel::add_torque_terms(const Model& model, const GravityState& gs, const std::array<Vec3, kMaxJoints>& jp,
                                  const std::array<Vec3, kMaxJoints>& jw, double* jac, double* jac_rot) const {
  const int n = layout_.dof, P = layout_.size;
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J(jac, 3, P);
  double dummy[3];
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> W(jac_rot ? jac_rot : dummy, 3,
                                                                         jac_rot ? P : 1);
  // the torque is taken at the commanded angles (frames of gs), the point moves at the deflected ones
  const auto& gr = gs.gr;
  const auto& gt = gs.gt;
  const auto& S = gs.S;
  const auto& M = gs.M;
  const auto& wc = gs.wc;
  const auto& oc = gs.oc;
  const auto& arm = gs.arm;
  const Vec3& cp = gs.cp;
  const double mp = gs.mp;
  const Vec3& g = model.gravity();
  auto ad = [&](int k, const Vec3& om, const Vec3& v, Vec3& omo, Vec3& vo) {
    omo = gr[k] * om;
    vo = gr[k] * v + gt[k].cross(omo);
  };
  // effect on the point (instrument frame) of a torque change dtau (N mm) on every loaded joint:
  // the sum of rb K_j jp_j dtau_j, those vectors formed once per pose
  std::array<Vec3, kMaxJoints> kp, kw;
  for (int j : layout_.loaded) {
    kp[j] = rb_ * jp[j] * model.compliance(j);
    if (jac_rot) kw[j] = rb_ * jw[j] * model.compliance(j);
  }
  auto apply = [&](int col, const std::array<double, kMaxJoints>& dtau) {
    Vec3 dx = Vec3::Zero(), dw = Vec3::Zero();
    for (int j : layout_.loaded) {
      dx += kp[j] * dtau[j];
      if (jac_rot) dw += kw[j] * dtau[j];
    }
    J.col(col) += dx;
    if (jac_rot) W.col(col) += dw;
  };
  // Every torque change below is linear in the motion (go, gv) of line i and (dom, dv) of the links
  // beyond it; the vectors it is dotted with depend on the pose only and are formed once:
  // B_j = g x wc_j, C_j = wc_j x (arm_j x g), A_j = C_j + arm_j x B_j.
  std::array<Vec3, kMaxJoints> A, B, C, OB;
  for (int j : layout_.loaded) {
    B[j] = g.cross(wc[j]);
    C[j] = wc[j].cross(arm[j].cross(g));
    A[j] = C[j] + arm[j].cross(B[j]);
    OB[j] = oc[j].cross(B[j]);
  }
  for (int i = 0; i < n; ++i) {
    const Vec3 wraw = nominal_.axis(i) + x_[4 * i] * u_[i] + x_[4 * i + 1] * v_[i];
    const double nn = wraw.norm();
    std::array<Vec3, kMaxJoints> SB;  // S_i x B_j for the joints up to i
    for (int j : layout_.loaded)
      if (j <= i) SB[j] = S[i].cross(B[j]);
    for (int c = 0; c < 4; ++c) {
      const Vec3& d = (c % 2 == 0) ? u_[i] : v_[i];
      Vec3 om, v;
      if (c < 2) {
        om = w_[i].cross((d - w_[i] * w_[i].dot(d)) / nn);
        v = p_[i].cross(om);
      } else {
        om.setZero();
        v = d;
      }
      Vec3 go, gv, ao, av;  // Gamma: the line itself; Delta: the links beyond it
      ad(i, om, v, go, gv);
      ad(i + 1, om, v, ao, av);
      const Vec3 dom = go - ao, dv = gv - av;
      std::array<double, kMaxJoints> dtau{};
      for (int j : layout_.loaded) {
        if (j > i) {
          // dom x wc_j . (arm_j x g) + wc_j . ((dom x arm_j) x g)
          dtau[j] = dom.dot(A[j]);
        } else if (j == i) {
          // go x wc_j . (arm_j x g) + wc_j . (darm x g), darm = M_j dv + dom x S_j - M_j (gv + go x oc_j)
          dtau[j] = go.dot(C[j]) + M[j] * (dv - gv).dot(B[j]) + dom.dot(SB[j]) - M[j] * go.dot(OB[j]);
        } else {
          // wc_j . (darm x g), darm = M_i dv + dom x S_i
          dtau[j] = M[i] * dv.dot(B[j]) + dom.dot(SB[j]);
        }
      }
      apply(4 * i + c, dtau);
    }
  }
  if (mp != 0) {
    for (int c = 0; c < 6; ++c) {
      Vec3 om = Vec3::Zero(), v = Vec3::Zero();
      if (c < 3) {
        v[c] = 1;
      } else {
        om = rm_ * jrm_.col(c - 3);
        v = tm_.cross(om);
      }
      Vec3 lo, lv;
      ad(n, om, v, lo, lv);
      const Vec3 dcp = mp * (lv + lo.cross(cp));
      std::array<double, kMaxJoints> dtau{};
      for (int j : layout_.loaded) dtau[j] = wc[j].dot(dcp.cross(g));
      apply(layout_.tool + c, dtau);
    }
  }
}

void PointModel::row_frames(const Model& model, const Measurement& m, GravityState& gs,
                            std::array<Mat3, kMaxJoints + 1>& gr, std::array<Vec3, kMaxJoints + 1>& gt,
                            double& scale) const {
  const int n = layout_.dof;
  VecQ qe = m.q_deg * kDeg;
  const bool torque = !layout_.loaded.empty();
  if (torque) {
    gravity_state(model, m, gs);
    for (int j = 0; j < n; ++j) qe[j] += model.compliance(j) * gs.tau[j];
  }
  scale = 1.0;
  const bool effects = !layout_.effect_list.empty();
  if (effects) {
    VecQ dq = VecQ::Zero(n);
    effect_offsets(layout_.effect_list, &x_[layout_.effects], m, layout_.t_ref, dq, scale);
    qe += dq;
  }
  // G_j = exp(xi_1 qe_1) ... exp(xi_j qe_j), G_0 = identity
  if (torque && !model.has_compliance() && !effects) {
    gr = gs.gr;
    gt = gs.gt;
  } else {
    chain_frames(qe, gr, gt);
  }
}

void PointModel::set_frames_only(bool on, const MeasurementSet* data) {
  frames_only_ = on;
  flange_.clear();
  flange_rows_ = nullptr;
  if (!on || !data || data->rows.empty()) return;
  const int n = layout_.dof;
  flange_.resize(data->rows.size());
  for (size_t i = 0; i < data->rows.size(); ++i) {
    const Measurement& m = data->rows[i];
    GravityState gs;
    std::array<Mat3, kMaxJoints + 1> gr;
    std::array<Vec3, kMaxJoints + 1> gt;
    row_frames(model_for(m.payload_kg), m, gs, gr, gt, flange_[i].scale);
    flange_[i].r = gr[n];
    flange_[i].t = gt[n];
  }
  flange_rows_ = data->rows.data();
}

const PointModel::Flange* PointModel::cached_flange(const Measurement& m) const {
  if (flange_.empty()) return nullptr;
  const auto a = reinterpret_cast<std::uintptr_t>(&m), b = reinterpret_cast<std::uintptr_t>(flange_rows_);
  if (a < b || (a - b) % sizeof(Measurement) != 0) return nullptr;
  const size_t i = (a - b) / sizeof(Measurement);
  return i < flange_.size() ? &flange_[i] : nullptr;
}

Vec3 PointModel::predict(const Measurement& m, double* jac, Mat3* rot, double* jac_rot) const {
  const Model& model = model_for(m.payload_kg);
  const int n = layout_.dof;
  const VecQ q = m.q_deg * kDeg;
  GravityState gs;
  double scale;
  std::array<Mat3, kMaxJoints + 1> gr;
  std::array<Vec3, kMaxJoints + 1> gt;
  if (const Flange* f = frames_only_ ? cached_flange(m) : nullptr) {
    gr[n] = f->r;  // only the flange frame is read on the frames-only path
    gt[n] = f->t;
    scale = f->scale;
  } else {
    row_frames(model, m, gs, gr, gt, scale);
  }
  const Vec3 tkv(x_[layout_.targets + 3 * m.target], x_[layout_.targets + 3 * m.target + 1],
                 x_[layout_.targets + 3 * m.target + 2]);
  const Vec3 x0 = rm_ * tkv + tm_;
  const Mat3& rn = gr[n];
  const Vec3 xr = rn * x0 + gt[n];  // the point of the unscaled robot
  const Vec3 x = scale * xr;
  const Vec3 y = rb_ * x + tb_;
  if (rot) *rot = rb_ * rn * rm_;
  if (!jac) return y;
  const int P = layout_.size;
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J(jac, 3, P);
  J.setZero();
  // angular velocity of the tool frame (instrument frame) per parameter, when asked for
  const bool ang = jac_rot != nullptr;
  double dummy[3];
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> W(ang ? jac_rot : dummy, 3, ang ? P : 1);
  if (ang) {
    W.setZero();
    W.block<3, 3>(0, layout_.base + 3) = rb_ * jrb_;
  }
  const Mat3 rbn = rb_ * rn;
  J.block<3, 3>(0, layout_.base) = Mat3::Identity();
  J.block<3, 3>(0, layout_.base + 3) = -rb_ * skew(x) * jrb_;
  J.block<3, 3>(0, layout_.targets + 3 * m.target) = scale * rbn * rm_;
  if (frames_only_) {
    J.block<3, 3>(0, layout_.tool + 3) = -scale * rbn * rm_ * skew(tkv) * jrm_;
    if (ang) W.block<3, 3>(0, layout_.tool + 3) = rbn * rm_ * jrm_;
    return y;
  }
  // x in the frames G_j: xl_j = G_j^-1 x
  std::array<Vec3, kMaxJoints + 1> xl;
  for (int j = 0; j <= n; ++j) xl[j] = gr[j].transpose() * (xr - gt[j]);
  for (int j = 0; j < n; ++j) {
    const Vec3 wraw = nominal_.axis(j) + x_[4 * j] * u_[j] + x_[4 * j + 1] * v_[j];
    const double nn = wraw.norm();
    for (int k = 0; k < 2; ++k) {
      const Vec3& d = k == 0 ? u_[j] : v_[j];
      const Vec3 dw = (d - w_[j] * w_[j].dot(d)) / nn;
      const Vec3 om = w_[j].cross(dw);  // the line turns about p_j
      const Vec3 dx = gr[j] * om.cross(xl[j] - p_[j]) - gr[j + 1] * om.cross(xl[j + 1] - p_[j]);
      J.col(4 * j + k) = rb_ * dx;
      if (ang) W.col(4 * j + k) = rb_ * (gr[j] * om - gr[j + 1] * om);
      const Vec3 dxt = gr[j] * d - gr[j + 1] * d;  // the line moves along d
      J.col(4 * j + 2 + k) = rb_ * dxt;
    }
  }
  // velocity of the point per unit rotation of each joint (current configuration, base frame)
  std::array<Vec3, kMaxJoints> jp;
  for (int j = 0; j < n; ++j) jp[j] = gr[j] * w_[j].cross(xl[j] - p_[j]);
  for (size_t i = 0; i < layout_.loaded.size(); ++i) {
    const int j = layout_.loaded[i];
    const double dq = gs.tau[j] * kDeg / 1e6;  // per deg/kNm
    J.col(layout_.compliance + static_cast<int>(i)) = rb_ * jp[j] * dq;
    if (ang) W.col(layout_.compliance + static_cast<int>(i)) = rb_ * (gr[j] * w_[j]) * dq;
  }
  J.block<3, 3>(0, layout_.tool) = rbn;
  J.block<3, 3>(0, layout_.tool + 3) = -rbn * rm_ * skew(tkv) * jrm_;
  if (ang) W.block<3, 3>(0, layout_.tool + 3) = rbn * rm_ * jrm_;
  std::array<Vec3, kMaxJoints> jw;  // angular velocity per unit rotation of each joint (base frame)
  for (int j = 0; j < n; ++j) jw[j] = gr[j] * w_[j];
  if (!layout_.loaded.empty() && model.has_compliance()) add_torque_terms(model, gs, jp, jw, J.data(), ang ? W.data() : nullptr);
  for (size_t e = 0; e < layout_.effect_list.size(); ++e) {
    const Effect& ef = layout_.effect_list[e];
    const int c = layout_.effect_offset[e];
    if (ef.name != "thermal_expansion") {  // joint-angle effects: dq_j = p . basis
      double b[128];
      joint_basis(ef, q[ef.joint], ef.name == "backlash" ? m.dir[ef.joint] : 0.0, b);
      for (int k = 0; k < ef.size(); ++k) J.col(c + k) = rb_ * jp[ef.joint] * b[k];
      if (ang)
        for (int k = 0; k < ef.size(); ++k) W.col(c + k) = rb_ * jw[ef.joint] * b[k];
    } else {
      J.col(c) = rb_ * xr * (m.temperature_c - layout_.t_ref);
    }
  }
  if (scale != 1.0) {
    // every column through the robot's point scales with it (not the base's, not thermal's own)
    J.leftCols(layout_.base) *= scale;
    for (size_t e = 0; e < layout_.effect_list.size(); ++e)
      if (layout_.effect_list[e].name != "thermal_expansion")
        J.middleCols(layout_.effect_offset[e], layout_.effect_list[e].size()) *= scale;
  }
  return y;
}

std::vector<double> PointModel::start(const MeasurementSet& data) const {
  std::vector<double> x(layout_.size, 0.0);
  for (size_t i = 0; i < layout_.loaded.size(); ++i)
    x[layout_.compliance + i] = nominal_.spec().joints[layout_.loaded[i]].compliance_deg_per_knm;
  // nominal prediction of the tool point in the base frame, matched to the measurements (Horn)
  const size_t m = data.rows.size();
  Eigen::Matrix3Xd a(3, m), b(3, m);
  for (size_t i = 0; i < m; ++i) {
    a.col(i) = fk_compliant(nominal_, data.rows[i].q_deg * kDeg).translation();
    b.col(i) = data.rows[i].xyz;
  }
  const Vec3 ca = a.rowwise().mean(), cb = b.rowwise().mean();
  const Mat3 h = (a.colwise() - ca) * (b.colwise() - cb).transpose();
  Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 d = Mat3::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  const Mat3 r = svd.matrixV() * d * svd.matrixU().transpose();
  const Vec3 t = cb - r * ca;
  const Vec3 dt = t - nominal_.base_in_instrument().translation();
  const Vec3 phi = so3_log(nominal_.base_in_instrument().linear().transpose() * r);
  for (int k = 0; k < 3; ++k) x[layout_.base + k] = dt[k], x[layout_.base + 3 + k] = phi[k];
  return x;
}

std::vector<double> point_errors(const Model& model, const std::vector<Vec3>& targets, const MeasurementSet& data) {
  std::vector<double> e;
  e.reserve(data.rows.size());
  std::map<double, std::shared_ptr<const Model>> variants;
  for (const auto& r : data.rows) {
    const Model* m = &model;
    if (!std::isnan(r.payload_kg) && r.payload_kg != model.spec().payload_kg) {
      auto& v = variants[r.payload_kg];
      if (!v) {
        ModelSpec s = model.spec();
        s.payload_kg = r.payload_kg;
        v = std::make_shared<const Model>(s);
      }
      m = v.get();
    }
    const Vec3 t = r.target < static_cast<int>(targets.size()) ? targets[r.target] : Vec3::Zero();
    e.push_back((simulate_point(*m, r, t) - r.xyz).norm());
  }
  return e;
}

// ---------------------------------------------------------------------------------------------
// Identification
// ---------------------------------------------------------------------------------------------
namespace {

/// Inverse of the right Jacobian of SO(3).
Mat3 so3_right_jacobian_inv(const Vec3& e) {
  const double th = e.norm();
  const Mat3 s = skew(e);
  const double c = th < 1e-4 ? 1.0 / 12.0 + th * th / 720.0
                             : 1.0 / (th * th) - (1.0 + std::cos(th)) / (2.0 * th * std::sin(th));
  return Mat3::Identity() + 0.5 * s + c * s * s;
}

}  // namespace

int row_residuals(const PointModel& pm, const Measurement& m, double weight, bool orientation, double* r, double* J) {
  const int P = pm.layout().size;
  Mat3 rot;
  thread_local std::vector<double> jw;
  if (J && orientation) jw.resize(3 * static_cast<size_t>(P));
  const Vec3 y = pm.predict(m, J, orientation ? &rot : nullptr, (J && orientation) ? jw.data() : nullptr);
  for (int k = 0; k < 3; ++k) r[k] = y[k] - m.xyz[k];
  if (!orientation) return 3;
  if (!m.has_abc) throw InputError("a row without a measured orientation in a 6-D measurement set");
  const Vec3 e = so3_log(abc_to_rotation(m.abc).transpose() * rot);
  for (int k = 0; k < 3; ++k) r[3 + k] = weight * e[k];
  if (J) {
    // e' = log(Rm^T Exp(w) R) ~ e + Jr^-1(e) R^T w
    const Mat3 d = weight * so3_right_jacobian_inv(e) * rot.transpose();
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> W(jw.data(), 3, P);
    Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>> JJ(J, 6, P);
    // predict() wrote the 3 position rows at J: move them into the 6-row layout
    Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> pos =
        Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>>(J, 3, P);
    JJ.topRows(3) = pos;
    JJ.bottomRows(3) = d * W;
  }
  return 6;
}

namespace {

/// Run f(i) for i in [0, n) on all cores (rows are independent; PointModel::predict is const).
/// J^T J with only its lower triangle filled (half the work of the product; what a self-adjoint
/// solver reads).
Eigen::MatrixXd normal_matrix_lower(const Eigen::MatrixXd& j) {
  Eigen::MatrixXd n = Eigen::MatrixXd::Zero(j.cols(), j.cols());
  n.selfadjointView<Eigen::Lower>().rankUpdate(j.transpose());
  return n;
}

template <class F>
void parallel_rows(size_t n, F&& f) {
  const size_t threads = std::min<size_t>(std::max(1u, std::thread::hardware_concurrency()), n / 256 + 1);
  if (threads <= 1) {
    for (size_t i = 0; i < n; ++i) f(i);
    return;
  }
  std::vector<std::thread> pool;
  const size_t chunk = (n + threads - 1) / threads;
  for (size_t t = 1; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (size_t i = t * chunk; i < std::min(n, (t + 1) * chunk); ++i) f(i);
    });
  for (size_t i = 0; i < std::min(n, chunk); ++i) f(i);
  for (auto& th : pool) th.join();
}

/// Fills residuals and Jacobians of every row once per evaluation point (the cost functions read).
class AllRows : public ceres::EvaluationCallback {
 public:
  /// x: the full parameter vector (held values stay, free ones are written back by finish());
  /// Ceres sees only the free parameters (z), so no manifold is needed.
  AllRows(PointModel& pm, const MeasurementSet& d, std::vector<double>& x, std::vector<int> free_idx, double weight)
      : pm_(pm), d_(d), x_(x), free_(std::move(free_idx)), P_(pm.layout().size), F_(static_cast<int>(free_.size())),
        RS_(d.orientation ? 6 : 3), w_(weight), r_(RS_ * d.rows.size()), j_(RS_ * d.rows.size() * F_) {
    for (int i : free_) z_.push_back(x_[i]);
  }
  void PrepareForEvaluation(bool jacobians, bool /*new_point*/) override {
    // rows already evaluated at this very point (Ceres's repeated calls, or the seed) are kept
    if (valid_ && z_ == at_ && (!jacobians || have_j_)) return;
    for (int k = 0; k < F_; ++k) x_[free_[k]] = z_[k];
    pm_.set_params(x_);
    parallel_rows(d_.rows.size(), [&](size_t i) {
      thread_local std::vector<double> full;
      if (jacobians) full.resize(6 * static_cast<size_t>(P_));
      row_residuals(pm_, d_.rows[i], w_, RS_ == 6, &r_[RS_ * i], jacobians ? full.data() : nullptr);
      if (jacobians)
        for (int r = 0; r < RS_; ++r)
          for (int k = 0; k < F_; ++k) j_[(RS_ * i + r) * F_ + k] = full[r * P_ + free_[k]];
    });
    valid_ = true;
    have_j_ = jacobians;
    at_ = z_;
  }
  /// Rows already evaluated at the start point (residuals r and the full Jacobian J of every
  /// parameter, from full_jacobian at the same x): the first evaluation reuses them.
  void seed(const Eigen::MatrixXd& J, const std::vector<double>& r) {
    for (size_t i = 0; i < RS_ * d_.rows.size(); ++i) {
      r_[i] = r[i];
      for (int k = 0; k < F_; ++k) j_[i * F_ + k] = J(static_cast<Eigen::Index>(i), free_[k]);
    }
    valid_ = have_j_ = true;
    at_ = z_;
  }
  void finish() {
    for (int k = 0; k < F_; ++k) x_[free_[k]] = z_[k];
    pm_.set_params(x_);
  }
  double* z() { return z_.data(); }
  const double* residual(size_t i) const { return &r_[RS_ * i]; }
  const double* jacobian(size_t i) const { return &j_[RS_ * i * F_]; }
  int row_size() const { return RS_; }
  int size() const { return F_; }
  size_t rows() const { return d_.rows.size(); }

 private:
  PointModel& pm_;
  const MeasurementSet& d_;
  std::vector<double>& x_;
  std::vector<int> free_;
  int P_, F_, RS_;
  double w_;
  std::vector<double> z_, r_, j_, at_;  // at_: the point r_ (and j_ if have_j_) were evaluated at
  bool valid_ = false, have_j_ = false;
};

class RowCost : public ceres::CostFunction {
 public:
  RowCost(const AllRows& all, size_t i) : all_(all), i_(i) {
    set_num_residuals(all.row_size());
    mutable_parameter_block_sizes()->push_back(all.size());
  }
  bool Evaluate(double const* const*, double* residuals, double** jacobians) const override {
    std::copy_n(all_.residual(i_), all_.row_size(), residuals);
    if (jacobians && jacobians[0]) std::copy_n(all_.jacobian(i_), all_.row_size() * all_.size(), jacobians[0]);
    return true;
  }

 private:
  const AllRows& all_;
  size_t i_;
};

class Progress : public ceres::IterationCallback {
 public:
  explicit Progress(const std::function<void(int, double)>& f) : f_(f) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (f_) f_(s.iteration, s.cost);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(int, double)>& f_;
};

std::unique_ptr<ceres::LossFunction> make_loss(const IdentifyOptions& opt) {
  if (opt.loss == "huber") return std::make_unique<ceres::HuberLoss>(opt.loss_scale_mm);
  if (opt.loss == "cauchy") return std::make_unique<ceres::CauchyLoss>(opt.loss_scale_mm);
  if (opt.loss != "none" && !opt.loss.empty())
    throw InputError("identify: unknown loss '" + opt.loss + "' (none, huber, cauchy)");
  return nullptr;
}

ceres::Problem::Options problem_options(AllRows& all) {
  ceres::Problem::Options popt;
  popt.evaluation_callback = &all;
  popt.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popt.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  return popt;
}

/// Levenberg-Marquardt on the free parameters of all (written back into its x by finish()).
void solve(ceres::Problem& problem, AllRows& all, ceres::LossFunction* loss, const IdentifyOptions& opt,
           ceres::Solver::Summary& summary, bool report) {
  for (size_t i = 0; i < all.rows(); ++i) problem.AddResidualBlock(new RowCost(all, i), loss, all.z());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = 1e-12;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-12;
  so.num_threads = 1;
  Progress prog(opt.progress);
  if (report && opt.progress) so.callbacks.push_back(&prog);
  ceres::Solve(so, &problem, &summary);
  all.finish();
}

int count_poses(const MeasurementSet& d) {
  std::set<int> ids;
  for (const auto& r : d.rows) ids.insert(r.pose);
  return static_cast<int>(ids.size());
}

/// Full identification Jacobian (3 or 6 rows per measurement) at x; the residuals too when asked.
Eigen::MatrixXd full_jacobian(PointModel& pm, const MeasurementSet& d, const std::vector<double>& x, double weight,
                              std::vector<double>* residuals = nullptr) {
  pm.set_params(x);
  const int P = pm.layout().size, RS = d.orientation ? 6 : 3;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(RS * d.rows.size(), P);
  if (residuals) residuals->assign(RS * d.rows.size(), 0.0);
  parallel_rows(d.rows.size(), [&](size_t i) {
    thread_local std::vector<double> full, r(6);
    full.resize(6 * static_cast<size_t>(P));
    row_residuals(pm, d.rows[i], weight, RS == 6, r.data(), full.data());
    std::copy_n(full.data(), RS * P, J.data() + RS * i * P);
    if (residuals) std::copy_n(r.data(), RS, residuals->data() + RS * i);
  });
  return J;
}

}  // namespace

IdentifyResult identify(const Model& nominal, const MeasurementSet& data, const IdentifyOptions& opt) {
  for (const auto& r : data.rows)
    if (r.q_deg.size() != nominal.dof())
      throw InputError(data.source + ":" + std::to_string(r.line) + ": " + std::to_string(r.q_deg.size()) +
                       " joint angles but the robot has " + std::to_string(nominal.dof()));
  // the extra effects: those asked for, then those the starting model carries (held at their values)
  std::vector<Effect> effects = opt.effects;
  const auto same = [](const Effect& a, const Effect& b) { return a.name == b.name && a.joint == b.joint; };
  for (const EffectValue& ev : nominal.spec().effects) {
    bool asked = false;
    for (const Effect& e : effects) asked = asked || same(e, ev.effect);
    if (!asked) effects.push_back(ev.effect);
  }
  double t_ref = nominal.spec().t_ref_c;
  bool thermal = false;
  for (const Effect& e : effects) {
    check_effect(e, nominal.dof(), "");
    if (e.name == "thermal_expansion") thermal = true;
  }
  if (thermal && nominal.thermal_alpha() == 0) {
    double sum = 0;
    for (const auto& r : data.rows) {
      if (std::isnan(r.temperature_c))
        throw InputError(data.source + ":" + std::to_string(r.line) + ": thermal_expansion needs the temperature_c column");
      sum += r.temperature_c;
    }
    t_ref = sum / data.rows.size();
  }
  if (thermal)
    for (const auto& r : data.rows)
      if (std::isnan(r.temperature_c))
        throw InputError(data.source + ":" + std::to_string(r.line) + ": thermal_expansion needs the temperature_c column");
  for (const Effect& e : effects)
    if (e.name == "backlash")
      for (const auto& r : data.rows)
        if (r.dir.size() != nominal.dof())
          throw InputError(data.source + ":" + std::to_string(r.line) + ": backlash needs the dir1..dir" +
                           std::to_string(nominal.dof()) + " columns");
  IdentifyResult res(ParamLayout(nominal, data.n_targets, effects, t_ref));
  const ParamLayout& L = res.layout;
  const int P = L.size;
  PointModel pm(nominal, data.n_targets, effects, t_ref);
  pm.prepare_payloads(data);
  res.start = pm.start(data);
  res.fixed.assign(P, false);
  res.fixed_reason.assign(P, "");
  // effects the starting model carries start from its values; those not asked for are held there
  for (size_t e = 0; e < L.effect_list.size(); ++e)
    for (const EffectValue& ev : nominal.spec().effects)
      if (same(ev.effect, L.effect_list[e]) && static_cast<int>(ev.p.size()) == L.effect_list[e].size()) {
        const bool asked = e < opt.effects.size();
        for (size_t k = 0; k < ev.p.size(); ++k) {
          const size_t i = static_cast<size_t>(L.effect_offset[e]) + k;
          res.start[i] = ev.p[k];
          if (!asked) res.fixed[i] = true, res.fixed_reason[i] = "carried by the starting model (not asked for)";
        }
      }
  std::vector<double> x = res.start;
  std::vector<int> targets_used(data.n_targets, 0);
  for (const auto& r : data.rows) targets_used[r.target] = 1;
  for (int t = 0; t < data.n_targets; ++t)
    if (!targets_used[t])
      for (int k = 0; k < 3; ++k) res.fixed[L.targets + 3 * t + k] = true, res.fixed_reason[L.targets + 3 * t + k] = "target never measured";
  if (!opt.compliance)
    for (int i = L.compliance; i < L.tool; ++i) res.fixed[i] = true, res.fixed_reason[i] = "not asked for (--effects)";
  else if (!opt.compliance_joints.empty())
    for (size_t i = 0; i < L.loaded.size(); ++i)
      if (std::find(opt.compliance_joints.begin(), opt.compliance_joints.end(), L.loaded[i]) == opt.compliance_joints.end()) {
        const int k = L.compliance + static_cast<int>(i);
        res.fixed[k] = true;
        res.fixed_reason[k] = "not in the model";
      }
  // a compliance is only identifiable where gravity loads its joint: below min_torque_share of the
  // largest joint's torque over the measured poses it is held (its effect is lost in the geometry)
  if (opt.compliance && !L.loaded.empty()) {
    std::vector<double> tmax(L.dof, 0.0);
    VecQ tau;
    for (const auto& r : data.rows) {
      gravity_torque(nominal, r.q_deg * kDeg, tau);
      for (int j = 0; j < L.dof; ++j) tmax[j] = std::max(tmax[j], std::abs(tau[j]));
    }
    const double top = *std::max_element(tmax.begin(), tmax.end());
    for (size_t i = 0; i < L.loaded.size(); ++i) {
      const int j = L.loaded[i];
      if (tmax[j] < opt.min_torque_share * top) {
        const int k = L.compliance + static_cast<int>(i);
        res.fixed[k] = true;
        char buf[200];
        std::snprintf(buf, sizeof buf, "gravity torque too small to see it (at most %.3g N m, %.1f%% of joint %d's)",
                      tmax[j] / 1000.0, 100.0 * tmax[j] / top,
                      static_cast<int>(std::max_element(tmax.begin(), tmax.end()) - tmax.begin()) + 1);
        res.fixed_reason[k] = buf;
      }
    }
  }
  for (const auto& name : opt.fix) {
    auto it = std::find(L.names.begin(), L.names.end(), name);
    if (it == L.names.end()) throw InputError("identify: no parameter named '" + name + "'");
    res.fixed[it - L.names.begin()] = true;
    res.fixed_reason[it - L.names.begin()] = "held by request";
  }

  // --- stage 1: base frame and targets on the nominal geometry (the "before" of the summary, and a
  // start where the targets are where they are, so that the analysis below sees the real geometry)
  {
    std::vector<int> frames;
    // with measured orientations the probe's mounting (the tool frame's rotation) is a frame too
    if (data.orientation)
      for (int i = L.tool + 3; i < L.tool + 6; ++i) frames.push_back(i);
    for (int i = L.base; i < L.effects; ++i)
      if (i < L.targets || !res.fixed[i]) frames.push_back(i);
    ceres::Solver::Summary s1;
    AllRows all1(pm, data, x, frames, opt.orientation_weight);
    ceres::Problem p1(problem_options(all1));
    std::unique_ptr<ceres::LossFunction> loss1 = make_loss(opt);
    pm.set_params(x);
    pm.set_frames_only(true, &data);  // only the base and target columns are needed here
    solve(p1, all1, loss1.get(), opt, s1, false);
    pm.set_frames_only(false);
    res.nominal_x = x;
    pm.set_params(x);
    res.nominal_fitted = pm.spec();
    res.nominal_fitted.name = nominal.spec().name;
    for (int t = 0; t < data.n_targets; ++t)
      res.nominal_targets.emplace_back(x[L.targets + 3 * t], x[L.targets + 3 * t + 1], x[L.targets + 3 * t + 2]);
    double ss = 0;
    for (const auto& r : data.rows) {
      const double e = (pm.predict(r, nullptr) - r.xyz).norm();
      ss += e * e;
      res.nominal_max_mm = std::max(res.nominal_max_mm, e);
    }
    res.nominal_rms_mm = std::sqrt(ss / data.rows.size());
  }

  Eigen::MatrixXd start_jacobian;  // at the start of stage 2, also its first evaluation
  std::vector<double> start_residuals;
  // --- identifiability: greedy selection of independent scaled columns in a preferred order, on
  // the data and on a generic campaign (random poses, the same targets): what the generic campaign
  // determines but the data do not means the data are too few or too alike ---
  {
    std::vector<int> order;
    for (int i = L.targets; i < L.effects; ++i) order.push_back(i);
    for (int i = L.compliance; i < L.tool; ++i) order.push_back(i);
    for (int i = L.effects; i < P; ++i) order.push_back(i);
    for (int j = 1; j < L.dof; ++j)
      for (int k = 0; k < 4; ++k) order.push_back(4 * j + k);
    // with measured orientations the tool's rotation is seen: keep it, hold the base's gauge instead
    if (data.orientation)
      for (int i = L.tool + 3; i < L.tool + 6; ++i) order.push_back(i);
    for (int i = L.base; i < L.base + 6; ++i) order.push_back(i);
    for (int k = 0; k < 4; ++k) order.push_back(k);
    for (int i = L.tool; i < L.tool + (data.orientation ? 3 : 6); ++i) order.push_back(i);
    // greedy on the normal matrix of the unit-scaled columns: the squared distance of column i from
    // the span of the chosen ones is N_ii - N_iS N_SS^-1 N_Si (an incremental Cholesky factor)
    auto select = [&](const Eigen::MatrixXd& J, std::vector<bool>& fixed, std::vector<std::string>& reason) {
      Eigen::VectorXd nrm = J.colwise().norm().transpose();
      Eigen::MatrixXd N = normal_matrix_lower(J);
      N.triangularView<Eigen::StrictlyUpper>() = N.transpose();
      for (int a = 0; a < P; ++a)
        for (int b = 0; b < P; ++b) N(a, b) /= (nrm[a] > 0 ? nrm[a] : 1.0) * (nrm[b] > 0 ? nrm[b] : 1.0);
      std::vector<int> chosen;
      Eigen::MatrixXd Lc(P, P);  // rows: chosen index k; Lc(k, i) = component of column i on chosen k
      for (int i : order) {
        if (fixed[i]) continue;
        if (nrm[i] == 0) {
          fixed[i] = true;
          reason[i] = "no effect on the measured points";
          continue;
        }
        double left2 = N(i, i);
        const int k = static_cast<int>(chosen.size());
        Eigen::VectorXd li(k);
        for (int a = 0; a < k; ++a) {
          double v = N(chosen[a], i);
          for (int b = 0; b < a; ++b) v -= Lc(b, chosen[a]) * li[b];
          li[a] = v / Lc(a, chosen[a]);
          left2 -= li[a] * li[a];
        }
        const double left = std::sqrt(std::max(0.0, left2));
        if (left < opt.rank_tolerance) {
          fixed[i] = true;
          reason[i] = "not identifiable: a combination of the other parameters";
          continue;
        }
        if (left < opt.weak_tolerance) {
          fixed[i] = true;
          char buf[160];
          std::snprintf(buf, sizeof buf, "barely identifiable: only %.1e of its effect is not a combination of the others", left);
          reason[i] = buf;
          continue;
        }
        for (int a = 0; a < k; ++a) Lc(a, i) = li[a];
        Lc(k, i) = left;
        chosen.push_back(i);
      }
    };
    MeasurementSet generic;
    generic.n_targets = data.n_targets;
    generic.orientation = data.orientation;  // the same kind of rows (J_r^-1 keeps the rank for any abc)
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> ud(-0.45, 0.45);
    for (int p = 0; p < 100; ++p) {
      Measurement row;
      row.pose = p;
      row.q_deg.resize(L.dof);
      for (int j = 0; j < L.dof; ++j) {
        const JointSpec& js = nominal.spec().joints[j];
        row.q_deg[j] = 0.5 * (js.lower_deg + js.upper_deg) + ud(rng) * (js.upper_deg - js.lower_deg);
      }
      row.dir.resize(L.dof);
      for (int j = 0; j < L.dof; ++j) row.dir[j] = ud(rng) < 0 ? -1.0 : 1.0;
      row.temperature_c = data.rows[rng() % data.rows.size()].temperature_c;
      row.has_abc = data.orientation;
      for (int t = 0; t < data.n_targets; ++t)
        if (targets_used[t]) row.target = t, generic.rows.push_back(row);
    }
    std::vector<bool> gfixed = res.fixed;
    std::vector<std::string> greason = res.fixed_reason;
    select(full_jacobian(pm, generic, x, opt.orientation_weight), gfixed, greason);
    start_jacobian = full_jacobian(pm, data, x, opt.orientation_weight, &start_residuals);
    select(start_jacobian, res.fixed, res.fixed_reason);
    std::string missing;
    int n_missing = 0;
    // only what the data make exactly redundant counts (near the weak threshold the two may differ)
    for (int i = 0; i < P; ++i)
      if (res.fixed[i] && !gfixed[i] && res.fixed_reason[i].rfind("not identifiable", 0) == 0)
        missing += (n_missing++ ? ", " : "") + L.names[i];
    if (n_missing)
      throw InputError(data.source + ": the " + std::to_string(data.rows.size()) + " measured points of " +
                       std::to_string(count_poses(data)) + " poses cannot determine " + missing +
                       ": too few or too similar poses to identify the model");
  }
  std::vector<int> free_idx, fixed_idx;
  for (int i = 0; i < P; ++i) (res.fixed[i] ? fixed_idx : free_idx).push_back(i);
  const int nres = (data.orientation ? 6 : 3) * static_cast<int>(data.rows.size());
  if (nres <= static_cast<int>(free_idx.size()))
    throw InputError(data.source + ": " + std::to_string(data.rows.size()) + " measured points give " +
                     std::to_string(nres) + " equations for " + std::to_string(free_idx.size()) +
                     " free parameters: too few to identify the model");

  // --- stage 2: everything identifiable ---
  ceres::Solver::Summary summary;
  std::unique_ptr<ceres::LossFunction> loss = make_loss(opt);
  AllRows all(pm, data, x, free_idx, opt.orientation_weight);
  all.seed(start_jacobian, start_residuals);
  ceres::Problem problem(problem_options(all));
  solve(problem, all, loss.get(), opt, summary, true);
  res.iterations = static_cast<int>(summary.iterations.size()) - 1;
  res.initial_cost = summary.initial_cost;
  res.final_cost = summary.final_cost;
  res.termination = summary.BriefReport();
  res.x = x;
  pm.set_params(x);
  res.calibrated = pm.spec();
  res.calibrated.name = nominal.spec().name + "-calibrated";
  for (int t = 0; t < data.n_targets; ++t)
    res.targets.emplace_back(x[L.targets + 3 * t], x[L.targets + 3 * t + 1], x[L.targets + 3 * t + 2]);
  res.t_ref = t_ref;
  for (size_t e = 0; e < L.effect_list.size(); ++e)
    res.effects.push_back({L.effect_list[e], std::vector<double>(x.begin() + L.effect_offset[e],
                                                                 x.begin() + L.effect_offset[e] + L.effect_list[e].size())});
  res.calibrated.effects = res.effects;  // the model carries every identified effect
  res.calibrated.t_ref_c = t_ref;
  {
    const Model cal(res.calibrated);
    const std::vector<double> e = point_errors(cal, res.targets, data);
    double ss = 0;
    for (double v : e) ss += v * v, res.max_mm = std::max(res.max_mm, v);
    res.rms_mm = std::sqrt(ss / e.size());
  }

  // --- condition, observability, covariance ---
  res.stddev.assign(P, std::nan(""));
  {
    const Eigen::MatrixXd J = full_jacobian(pm, data, x, opt.orientation_weight);
    Eigen::MatrixXd Jf(J.rows(), free_idx.size());
    for (size_t k = 0; k < free_idx.size(); ++k) {
      const double nrm = J.col(free_idx[k]).norm();
      Jf.col(k) = J.col(free_idx[k]) / (nrm > 0 ? nrm : 1.0);
    }
    // singular values from the eigenvalues of the (small) normal matrix
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normal_matrix_lower(Jf), Eigen::EigenvaluesOnly);
    const Eigen::VectorXd s = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    res.condition_number = s.maxCoeff() / s.minCoeff();
    double logsum = 0;
    for (int k = 0; k < s.size(); ++k) logsum += std::log(s(k));
    res.observability_index = std::exp(logsum / s.size()) / std::sqrt(static_cast<double>(data.rows.size()));
    pm.set_params(x);
  }
  if (opt.covariance) {
    ceres::Covariance::Options co;
    co.algorithm_type = ceres::DENSE_SVD;  // the held parameters are out of the block: full rank
    co.null_space_rank = 0;
    co.min_reciprocal_condition_number = 1e-14;
    ceres::Covariance cov(co);
    std::vector<std::pair<const double*, const double*>> blocks = {{all.z(), all.z()}};
    if (cov.Compute(blocks, &problem)) {
      const int F = static_cast<int>(free_idx.size());
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> C(F, F);
      cov.GetCovarianceBlock(all.z(), all.z(), C.data());
      const double dofres = std::max(1, nres - F);
      const double s2 = 2.0 * summary.final_cost / dofres;
      C *= s2;
      for (int a = 0; a < F; ++a) res.stddev[free_idx[a]] = std::sqrt(std::max(0.0, C(a, a)));
      for (int a = 0; a < F; ++a)
        for (int b = a + 1; b < F; ++b) {
          const double r = C(a, b) / std::sqrt(C(a, a) * C(b, b));
          if (std::abs(r) >= opt.correlation_threshold)
            res.correlations.push_back({L.names[free_idx[a]], L.names[free_idx[b]], r});
        }
    }
  }
  return res;
}

}  // namespace kincal
