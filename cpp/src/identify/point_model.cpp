// kincal: the identification's measurement model: the parameter layout, PointModel's prediction
// of a row with its analytic Jacobian (geometry, compliance through the gravity torque, tool and
// base frames of every setup, targets, extra effects, the instrument's drift) and the residuals of a
// row and of a whole measurement set.
#include "point_eval.hpp"

#include "../core/thread_pool.hpp"

#include "kincal/identify/so3.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>

namespace kincal {

namespace {

/// Joint-angle offsets (rad) of the effects at a row, and the thermal scale factor.
void effect_offsets(const std::vector<Effect>& eff, const double* p, const Measurement& m, double t_ref, VecQ& dq,
                    double& scale) {
  scale = 1.0;
  double b[128];
  for (const Effect& e : eff) {
    const EffectKind& kind = e.kind();
    if (kind.scales_lengths()) {
      if (std::isnan(m.temperature_c)) throw InputError(e.name + " needs the temperature_c column");
      scale *= 1.0 + p[0] * (m.temperature_c - t_ref);
    } else if (!kind.of_instrument()) {  // the drift moves the instrument, not the robot
      if (kind.reads_dir() && m.dir.size() != m.q_deg.size()) throw InputError(e.name + " needs the dir1..dirN columns");
      joint_basis(e, m.q_deg[e.joint] * kDeg, kind.reads_dir() ? m.dir[e.joint] : 0.0, b);
      for (int k = 0; k < e.size(); ++k) dq[e.joint] += p[k] * b[k];
    }
    p += e.size();
  }
}

}  // namespace

ParamLayout::ParamLayout(const Model& nominal, const LayoutOptions& o)
    : dof(nominal.dof()), n_targets(o.n_targets), fit_gravity(o.fit_gravity), effect_list(o.effects), t_ref(o.t_ref),
      t_mean(o.t_mean) {
  if (o.setups.size() > 1) setup_names = o.setups;
  n_setups = setup_names.empty() ? 1 : static_cast<int>(setup_names.size());
  for (int j = 0; j < dof; ++j)
    if (nominal.gravity_loaded(j)) loaded.push_back(j);
  joints = 0;
  compliance = 4 * dof;
  moments = compliance + static_cast<int>(loaded.size());
  if (fit_gravity && !loaded.empty())
    for (int k = loaded.front(); k < dof; ++k) moment_links.push_back(k);
  tool = moments + 2 * static_cast<int>(moment_links.size());
  base = tool + 6;
  targets = base + 6 * n_setups;
  effects = targets + 3 * n_targets;
  size = effects;
  station_names = o.station_names;
  station_kinds = o.station_kinds;
  station_normals = o.station_normals;
  if (station_kinds.size() != station_names.size()) throw std::logic_error("ParamLayout: a station without its kind");
  for (const Effect& e : effect_list) {
    check_effect(e, dof, "");
    if (e.kind().gravity_loaded_only)
      throw InputError("joint_compliance is identified through IdentifyOptions::compliance, not as an extra effect");
    if (e.kind().of_instrument()) {
      if (drift >= 0) throw InputError(e.name + " is given twice");
      drift = size;
    }
    effect_offset.push_back(size);
    size += e.size();
  }
  for (int j = 0; j < dof; ++j) {
    const std::string p = "joint" + std::to_string(j + 1);
    for (const char* s : {".tilt_u", ".tilt_v"}) names.push_back(p + s), units.push_back("rad");
    for (const char* s : {".move_u", ".move_v"}) names.push_back(p + s), units.push_back("mm");
  }
  for (int j : loaded) names.push_back("joint" + std::to_string(j + 1) + ".compliance"), units.push_back("deg/kNm");
  for (int k : moment_links)
    for (const char* s : {".moment_u", ".moment_v"}) names.push_back("link" + std::to_string(k + 1) + s), units.push_back("t m");
  std::vector<std::string> frames = {"tool"};
  if (setup_names.empty()) frames.push_back("base");
  for (const std::string& sn : setup_names) frames.push_back("base[" + sn + "]");
  for (const std::string& f : frames) {
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
  stations = size;
  size += 3 * static_cast<int>(station_names.size());
  for (size_t k = 0; k < station_names.size(); ++k) {
    const std::string p = "station[" + station_names[k] + "]";
    if (station_kinds[k] == MeasureKind::plane) {
      for (const char* s : {".tilt_u", ".tilt_v"}) names.push_back(p + s), units.push_back("rad");
      names.push_back(p + ".offset"), units.push_back("mm");
    } else {
      for (const char* s : {".x", ".y", ".z"}) names.push_back(p + s), units.push_back("mm");
    }
  }
}

namespace detail {

PointStructure::PointStructure(const Model& nom, const LayoutOptions& options, const MeasurementSet* data,
                               const Campaign& reference)
    : nominal(nom), layout(nom, options) {
  const int n = nominal.dof();
  // every setup's corrections are relative to the model's frame of that name, or its base frame
  for (int s = 0; s < layout.n_setups; ++s) {
    Eigen::Isometry3d f = reference.base();
    if (!layout.setup_names.empty())
      for (const SetupFrame& sf : reference.setups)
        if (sf.name == layout.setup_names[static_cast<size_t>(s)]) f = pose_to_iso(sf.base_in_instrument);
    r0.push_back(f.linear());
    t0.push_back(f.translation());
  }
  for (int j = 0; j < n; ++j) {
    const Vec3 w = nominal.axis(j);
    u.push_back(w.unitOrthogonal());
    v.push_back(w.cross(u.back()));
  }
  com0 = zero_moment_centres(nominal, layout);
  if (data) {
    std::set<double> pays;
    for (const auto& r : data->rows)
      if (!std::isnan(r.payload_kg) && r.payload_kg != nominal.spec().payload_kg) pays.insert(r.payload_kg);
    payloads.assign(pays.begin(), pays.end());
  }
  target_start = options.target_start;
  init_stations(data);
}

PointEval::PointEval(std::shared_ptr<const PointStructure> s, const std::vector<double>& x,
                     std::shared_ptr<const FlangeCache> flanges)
    : s_(std::move(s)), nominal_(s_->nominal), layout_(s_->layout), u_(s_->u), v_(s_->v), x_(x),
      flanges_(std::move(flanges)) {
  if (static_cast<int>(x.size()) != layout_.size)
    throw InputError("PointModel: " + std::to_string(x.size()) + " parameters for a layout of " +
                     std::to_string(layout_.size));
  spec_ = nominal_.spec();
  spec_.effects.clear();  // the layout's effects act through x, never twice through the model
  const int n = layout_.dof;
  w_.resize(n);
  p_.resize(n);
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
  if (layout_.fit_gravity) fitted_masses(x);
  const Vec3 phim(x[layout_.tool + 3], x[layout_.tool + 4], x[layout_.tool + 5]);
  rm_ = nominal_.tool().linear() * so3::exp(phim);
  jrm_ = so3::right_jacobian(phim);
  tm_ = nominal_.tool().translation() + Vec3(x[layout_.tool], x[layout_.tool + 1], x[layout_.tool + 2]);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rm_;
  t.translation() = tm_;
  spec_.tool = iso_to_pose(t);
  campaign_.setups.clear();
  place_.resize(static_cast<size_t>(layout_.n_setups));
  for (int s = 0; s < layout_.n_setups; ++s) {
    Placement& b = place_[static_cast<size_t>(s)];
    const double* xb = &x[layout_.base + 6 * s];
    const Vec3 phib(xb[3], xb[4], xb[5]);
    b.r = s_->r0[static_cast<size_t>(s)] * so3::exp(phib);
    b.jr = so3::right_jacobian(phib);
    b.t = s_->t0[static_cast<size_t>(s)] + Vec3(xb[0], xb[1], xb[2]);
    t.linear() = b.r;
    t.translation() = b.t;
    // the first setup's frame is the model's base_in_instrument; several are listed by name
    if (s == 0) campaign_.base_in_instrument = iso_to_pose(t);
    if (!layout_.setup_names.empty()) campaign_.setups.push_back({layout_.setup_names[static_cast<size_t>(s)], iso_to_pose(t)});
  }
  current_ = std::make_shared<const Model>(spec_);
  for (double pay : s_->payloads) {
    ModelSpec ps = spec_;
    ps.payload_kg = pay;
    payload_models_.emplace_back(pay, std::make_shared<const Model>(ps));
  }
  init_stations();
}

const Model& PointEval::model_for(double payload) const {
  if (std::isnan(payload) || payload == spec_.payload_kg) return *current_;
  for (const auto& pm : payload_models_)
    if (pm.first == payload) return *pm.second;
  throw InputError("a row with a payload of " + std::to_string(payload) +
                   " kg that the measurement model was not built for (PointModel's payload_rows)");
}

void PointEval::chain_frames(const VecQ& q, std::array<Mat3, kMaxJoints + 1>& gr,
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

void PointEval::row_frames(const Model& model, const Measurement& m, GravityState& gs,
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

std::shared_ptr<const FlangeCache> PointEval::compute_flanges(const MeasurementSet& data) const {
  auto out = std::make_shared<FlangeCache>();
  const int n = layout_.dof;
  out->rows.resize(data.rows.size());
  out->first = data.rows.data();
  parallel_rows(data.rows.size(), kRowsPerThread, [&](size_t begin, size_t end, size_t) {
    for (size_t i = begin; i < end; ++i) {
      const Measurement& m = data.rows[i];
      FlangeCache::Flange& f = out->rows[i];
      GravityState gs;
      std::array<Mat3, kMaxJoints + 1> gr;
      std::array<Vec3, kMaxJoints + 1> gt;
      row_frames(model_for(m.payload_kg), m, gs, gr, gt, f.scale);
      f.r = gr[n];
      f.t = gt[n];
    }
  });
  return out;
}

const FlangeCache::Flange* PointEval::cached_flange(const Measurement& m) const {
  if (!flanges_ || flanges_->rows.empty()) return nullptr;
  const std::vector<FlangeCache::Flange>& flange_ = flanges_->rows;
  const auto a = reinterpret_cast<std::uintptr_t>(&m), b = reinterpret_cast<std::uintptr_t>(flanges_->first);
  if (a < b || (a - b) % sizeof(Measurement) != 0) return nullptr;
  const size_t i = (a - b) / sizeof(Measurement);
  return i < flange_.size() ? &flange_[i] : nullptr;
}

const PointEval::Placement& PointEval::placement(const Measurement& m) const {
  if (m.setup < 0 || m.setup >= layout_.n_setups)
    throw InputError("a row of setup code " + std::to_string(m.setup) + " but the layout has " +
                     std::to_string(layout_.n_setups) + " setup(s)");
  return place_[static_cast<size_t>(m.setup)];
}

void PointEval::drifted(const Measurement& m, const Placement& pl, Mat3& rb, Vec3& tb, double& tau, Vec3& dw) const {
  if (std::isnan(m.time_s)) throw InputError("drift needs the time_s column");
  tau = (m.time_s - layout_.t_mean) / 3600.0;
  const double* d = &x_[layout_.drift];
  dw = tau * Vec3(d[3], d[4], d[5]);
  rb = so3::exp(dw) * pl.r;
  tb = pl.t + tau * Vec3(d[0], d[1], d[2]);
}

void PointEval::drift_columns(double tau, const Vec3& dw, const Vec3& rx, double* jac, double* jac_rot) const {
  // y = Exp(tau w) R x + t + tau v: Exp(a + d) = Exp(Jl(a) d) Exp(a), Jl(a) = Jr(-a)
  const int P = layout_.size;
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J(jac, 3, P);
  const Mat3 jl = so3::right_jacobian(-dw);
  J.block<3, 3>(0, layout_.drift) = tau * Mat3::Identity();
  J.block<3, 3>(0, layout_.drift + 3) = -tau * so3::skew(rx) * jl;
  if (jac_rot) {
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> W(jac_rot, 3, P);
    W.block<3, 3>(0, layout_.drift + 3) = tau * jl;
  }
}

Vec3 PointEval::predict(const Measurement& m, double* jac, Mat3* rot, double* jac_rot) const {
  const Model& model = model_for(m.payload_kg);
  const int n = layout_.dof;
  const VecQ q = m.q_deg * kDeg;
  GravityState gs;
  double scale;
  std::array<Mat3, kMaxJoints + 1> gr;
  std::array<Vec3, kMaxJoints + 1> gt;
  if (const FlangeCache::Flange* f = cached_flange(m)) {
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
  // the row's placement: its setup's frame, moved by the drift at the row's time (local copies: the
  // compiler then knows that no Jacobian store changes them)
  const Placement& pl = placement(m);
  Mat3 rb = pl.r;
  Vec3 tb = pl.t;
  const Mat3 jrb = pl.jr;
  const bool drift = layout_.drift >= 0;
  double tau = 0;
  Vec3 dw = Vec3::Zero();  // the drift's rotation vector at the row's time
  if (drift) drifted(m, pl, rb, tb, tau, dw);
  const int base = layout_.base + 6 * m.setup;
  const Vec3 y = rb * x + tb;
  if (rot) *rot = rb * rn * rm_;
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
    W.block<3, 3>(0, base + 3) = rb * jrb;
  }
  const Mat3 rbn = rb * rn;
  J.block<3, 3>(0, base) = Mat3::Identity();
  J.block<3, 3>(0, base + 3) = -rb * so3::skew(x) * jrb;
  if (drift) drift_columns(tau, dw, rb * x, jac, ang ? jac_rot : nullptr);
  J.block<3, 3>(0, layout_.targets + 3 * m.target) = scale * rbn * rm_;
  if (flanges_) {
    J.block<3, 3>(0, layout_.tool) = scale * rbn;  // with measured orientations the tool frame is a frame
    J.block<3, 3>(0, layout_.tool + 3) = -scale * rbn * rm_ * so3::skew(tkv) * jrm_;
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
      J.col(4 * j + k) = rb * dx;
      if (ang) W.col(4 * j + k) = rb * (gr[j] * om - gr[j + 1] * om);
      const Vec3 dxt = gr[j] * d - gr[j + 1] * d;  // the line moves along d
      J.col(4 * j + 2 + k) = rb * dxt;
    }
  }
  // velocity of the point per unit rotation of each joint (current configuration, base frame)
  std::array<Vec3, kMaxJoints> jp;
  for (int j = 0; j < n; ++j) jp[j] = gr[j] * w_[j].cross(xl[j] - p_[j]);
  for (size_t i = 0; i < layout_.loaded.size(); ++i) {
    const int j = layout_.loaded[i];
    const double dq = gs.tau[j] * kDeg / 1e6;  // per deg/kNm
    J.col(layout_.compliance + static_cast<int>(i)) = rb * jp[j] * dq;
    if (ang) W.col(layout_.compliance + static_cast<int>(i)) = rb * (gr[j] * w_[j]) * dq;
  }
  J.block<3, 3>(0, layout_.tool) = rbn;
  J.block<3, 3>(0, layout_.tool + 3) = -rbn * rm_ * so3::skew(tkv) * jrm_;
  if (ang) W.block<3, 3>(0, layout_.tool + 3) = rbn * rm_ * jrm_;
  std::array<Vec3, kMaxJoints> jw;  // angular velocity per unit rotation of each joint (base frame)
  for (int j = 0; j < n; ++j) jw[j] = gr[j] * w_[j];
  if (!layout_.loaded.empty() && model.has_compliance())
    add_torque_terms(model, gs, jp, jw, rb, J.data(), ang ? W.data() : nullptr);
  if (!layout_.effect_list.empty()) effect_columns(m, q, rb, xr, jp, jw, scale, jac, ang ? jac_rot : nullptr);
  if (scale != 1.0) J.leftCols(layout_.base) *= scale;  // every column through the robot's point scales with it
  return y;
}

void PointEval::effect_columns(const Measurement& m, const VecQ& q, const Mat3& rb, const Vec3& xr,
                               const std::array<Vec3, kMaxJoints>& jp, const std::array<Vec3, kMaxJoints>& jw,
                               double scale, double* jac, double* jac_rot) const {
  const int P = layout_.size;
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J(jac, 3, P);
  double dummy[3];
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> W(jac_rot ? jac_rot : dummy, 3, jac_rot ? P : 1);
  for (size_t e = 0; e < layout_.effect_list.size(); ++e) {
    const Effect& ef = layout_.effect_list[e];
    const int c = layout_.effect_offset[e];
    const EffectKind& kind = ef.kind();
    if (kind.of_instrument()) continue;  // the instrument's: predict()'s drift columns
    if (!kind.scales_lengths()) {  // joint-angle effects: dq_j = p . basis, scaled with the robot's point
      double b[128];
      joint_basis(ef, q[ef.joint], kind.reads_dir() ? m.dir[ef.joint] : 0.0, b);
      for (int k = 0; k < ef.size(); ++k) J.col(c + k) = scale * (rb * jp[ef.joint] * b[k]);
      if (jac_rot)
        for (int k = 0; k < ef.size(); ++k) W.col(c + k) = rb * jw[ef.joint] * b[k];
    } else {  // thermal's own column: not scaled
      J.col(c) = rb * xr * (m.temperature_c - layout_.t_ref);
    }
  }
}

}  // namespace detail

PointModel::PointModel(const Model& nominal, const LayoutOptions& options, const MeasurementSet* data,
                       const Campaign& reference)
    : s_(std::make_shared<const detail::PointStructure>(nominal, options, data, reference)) {}

std::vector<double> PointModel::start(const MeasurementSet& data, const std::vector<Vec3>& targets) const {
  const ParamLayout& L = s_->layout;
  std::vector<double> x(L.size, 0.0);
  if (!targets.empty() && static_cast<int>(targets.size()) != L.n_targets)
    throw InputError("identify: " + std::to_string(targets.size()) + " target start(s) for the data's " +
                     std::to_string(L.n_targets) + " target(s)");
  for (size_t t = 0; t < targets.size(); ++t)
    for (int k = 0; k < 3; ++k) x[static_cast<size_t>(L.targets) + 3 * t + static_cast<size_t>(k)] = targets[t][k];
  for (size_t i = 0; i < L.loaded.size(); ++i)
    x[L.compliance + i] = s_->nominal.spec().joints[L.loaded[i]].compliance_deg_per_knm;
  // each setup's frame from the nominal prediction of the tool point matched to its points (Horn)
  const std::vector<Eigen::Isometry3d> place = detail::start_placements(*s_, data);
  for (int s = 0; s < L.n_setups; ++s) {
    const Eigen::Isometry3d& f = place[static_cast<size_t>(s)];
    const Vec3 dt = f.translation() - s_->t0[static_cast<size_t>(s)];
    const Vec3 phi = so3::log(s_->r0[static_cast<size_t>(s)].transpose() * f.linear());
    const int o = L.base + 6 * s;
    for (int k = 0; k < 3; ++k) x[o + k] = dt[k], x[o + 3 + k] = phi[k];
  }
  detail::start_stations(*s_, data, place, x);
  return x;
}

const ParamLayout& PointModel::layout() const { return s_->layout; }

PointState PointModel::at(const std::vector<double>& x) const {
  return PointState(std::make_shared<const detail::PointEval>(s_, x));
}

PointState PointModel::at_frames_only(const std::vector<double>& x, const MeasurementSet& data) const {
  return PointState(std::make_shared<const detail::PointEval>(s_, x, detail::PointEval(s_, x).compute_flanges(data)));
}

const ParamLayout& PointState::layout() const { return e_->structure().layout; }
const std::vector<double>& PointState::x() const { return e_->x(); }
const ModelSpec& PointState::spec() const { return e_->spec(); }
const Campaign& PointState::campaign() const { return e_->campaign(); }
PointState PointState::with_params(const std::vector<double>& x) const {
  return PointState(std::make_shared<const detail::PointEval>(e_->structure_ptr(), x, e_->flanges()));
}
Vec3 PointState::predict(const Measurement& m, double* jac, Mat3* rot, double* jac_rot) const {
  return e_->predict(m, jac, rot, jac_rot);
}
int PointState::probe_residuals(const Measurement& m, int size, double* r, double* J) const {
  return e_->probe_residuals(m, size, r, J);
}
double PointState::artifact_residual(const ArtifactTerm& a, double* J) const { return e_->artifact_residual(a, J); }
std::vector<StationValue> PointState::stations() const { return e_->stations(); }

}  // namespace kincal
