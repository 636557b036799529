// kincal: PointModel's gravity state and the Jacobian terms through the gravity torque.
// The deflection K tau(q) depends on the geometry through the gravity torque: moving a joint line
// moves the links (their centres of mass) and the axes the torque is taken about; moving the tool
// frame moves the payload. This adds d(point)/d(parameter) through K d(tau)/d(parameter), and the
// columns of the fitted gravity's mass moments (point_model.hpp), which act only through tau.
// K tau itself acts in row_frames() (point_model.cpp); these are its derivatives.
#include "point_eval.hpp"
#include "../kinematics/weight_torque.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace kincal {

bool gravity_fitted(const Model& nominal, GravityTorques mode) {
  bool masses = false;
  for (const JointSpec& j : nominal.spec().joints) masses = masses || j.mass_kg > 0;
  if (mode == GravityTorques::fit) return true;
  if (mode == GravityTorques::automatic) return !masses;
  if (!masses)
    throw InputError("identify: --gravity masses, but the model '" + nominal.spec().name +
                     "' has no link masses (no inertial data): use --gravity fit (or auto)");
  return false;
}

namespace detail {

std::vector<Vec3> zero_moment_centres(const Model& nominal, const ParamLayout& layout) {
  const int n = layout.dof;
  // zero moments: a_k = m (c_k - p_k) + M_{k+1} (p_{k+1} - p_k) = 0 with every fitted link's mass m
  std::vector<Vec3> com0(static_cast<size_t>(n), Vec3::Zero());
  for (int k : layout.moment_links) {
    const double beyond = n - 1 - k;  // the fitted links beyond k, kUnitMass each
    Vec3 c = nominal.point(k);
    if (k + 1 < n) c -= beyond * (nominal.point(k + 1) - nominal.point(k));
    com0[static_cast<size_t>(k)] = c;
  }
  return com0;
}

void PointEval::fitted_masses(const std::vector<double>& x) {  // the moments as a mass table (point_model.hpp)
  const int n = layout_.dof;
  for (int j = 0; j < n; ++j) spec_.joints[j].mass_kg = 0, spec_.joints[j].com.setZero();
  for (size_t i = 0; i < layout_.moment_links.size(); ++i) {
    const int k = layout_.moment_links[i];
    const double* a = &x[layout_.moments + 2 * i];
    spec_.joints[k].mass_kg = kUnitMass;
    spec_.joints[k].com = s_->com0[static_cast<size_t>(k)] + (a[0] * u_[k] + a[1] * v_[k]) * (kMomentUnit / kUnitMass);
  }
}

void PointEval::gravity_state(const Model& model, const Measurement& m, GravityState& gs) const {
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
  for (int k = 0; k < n; ++k) {
    gs.M[k] = sp.joints[k].mass_kg;
    gs.S[k] = gs.M[k] * (gr[k + 1] * sp.joints[k].com + gt[k + 1]);
  }
  detail::carried_loads(n, gs.S, gs.M);
  const Vec3& g = model.gravity();
  for (int j = 0; j < n; ++j) {
    gs.wc[j] = gr[j] * w_[j];
    gs.oc[j] = gr[j] * p_[j] + gt[j];
    gs.tau[j] = detail::weight_torque(gs.wc[j], gs.oc[j], gs.S[j], gs.M[j], g, gs.arm[j]);
  }
}

namespace {

/// What add_torque_terms' torque changes are dotted with at one pose. The effect on the point
/// (instrument frame) of a torque change dtau (N mm) on every loaded joint is the sum of
/// rb K_j jp_j dtau_j (kp; kw for the rotation); every torque change is linear in the motion (go, gv)
/// of line i and (dom, dv) of the links beyond it, dotted with B_j = g x wc_j,
/// C_j = wc_j x (arm_j x g), A_j = C_j + arm_j x B_j and OB_j = oc_j x B_j.
struct TorqueBasis {
  std::array<Vec3, kMaxJoints> kp, kw, A, B, C, OB;
  using Vecs = std::array<Vec3, kMaxJoints>;
  TorqueBasis(const Model& model, const Vecs& wc, const Vecs& oc, const Vecs& arm, const std::vector<int>& loaded,
              const Vecs& jp, const Vecs& jw, const Mat3& rb, bool rotation) {
    const Vec3& g = model.gravity();
    for (int j : loaded) {
      kp[j] = rb * jp[j] * model.compliance(j);
      if (rotation) kw[j] = rb * jw[j] * model.compliance(j);
      B[j] = g.cross(wc[j]);
      C[j] = wc[j].cross(arm[j].cross(g));
      A[j] = C[j] + arm[j].cross(B[j]);
      OB[j] = oc[j].cross(B[j]);
    }
  }
};

}  // namespace

void PointEval::add_torque_terms(const Model& model, const GravityState& gs, const std::array<Vec3, kMaxJoints>& jp,
                                  const std::array<Vec3, kMaxJoints>& jw, const Mat3& rb, double* jac,
                                  double* jac_rot) const {
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
  const Vec3& cp = gs.cp;
  const double mp = gs.mp;
  const Vec3& g = model.gravity();
  auto ad = [&](int k, const Vec3& om, const Vec3& v, Vec3& omo, Vec3& vo) {
    omo = gr[k] * om;
    vo = gr[k] * v + gt[k].cross(omo);
  };
  const TorqueBasis tb(model, gs.wc, gs.oc, gs.arm, layout_.loaded, jp, jw, rb, jac_rot != nullptr);
  const auto &kp = tb.kp, &kw = tb.kw, &A = tb.A, &B = tb.B, &C = tb.C, &OB = tb.OB;
  auto apply = [&](int col, const std::array<double, kMaxJoints>& dtau) {
    Vec3 dx = Vec3::Zero(), dw = Vec3::Zero();
    for (int j : layout_.loaded) {
      dx += kp[j] * dtau[j];
      if (jac_rot) dw += kw[j] * dtau[j];
    }
    J.col(col) += dx;
    if (jac_rot) W.col(col) += dw;
  };
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
  // the fitted gravity's moments: one of link k along d adds G_{k+1} d (kMomentUnit kg mm) to A_j of
  // every joint j <= k, so dtau_j = wc_j . (G_{k+1} d x g) = G_{k+1} d . B_j
  for (size_t i = 0; i < layout_.moment_links.size(); ++i) {
    const int k = layout_.moment_links[i];
    for (int c = 0; c < 2; ++c) {
      const Vec3 s = gr[k + 1] * (c == 0 ? u_[k] : v_[k]) * kMomentUnit;
      std::array<double, kMaxJoints> dtau{};
      for (int j : layout_.loaded)
        if (j <= k) dtau[j] = s.dot(B[j]);
      apply(layout_.moments + 2 * static_cast<int>(i) + c, dtau);
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

}  // namespace detail

std::vector<double> PointModel::probe(std::vector<double> x, const std::vector<bool>& fixed) const {
  const ParamLayout& L = s_->layout;
  if (!L.fit_gravity) return x;
  double held = 0;  // the held compliance (the scale), else the largest
  for (size_t i = 0; i < L.loaded.size(); ++i) {
    const int c = L.compliance + static_cast<int>(i);
    if (fixed[c] && x[c] != 0) held = x[c];
  }
  for (size_t i = 0; i < L.loaded.size() && held == 0; ++i) held = x[L.compliance + i];
  if (held == 0) held = kUnitCompliance;
  for (size_t i = 0; i < L.loaded.size(); ++i) {
    const int c = L.compliance + static_cast<int>(i);
    if (!fixed[c] && x[c] == 0) x[c] = held;
  }
  // generic moments of a robot's size: a fixed irregular pattern, none zero, none alike
  double reach = 0;
  for (int j = 0; j < L.dof; ++j) reach = std::max(reach, s_->nominal.point(j).norm());
  reach = std::max(reach, s_->nominal.tool().translation().norm());
  const double pattern[] = {0.83, -0.41, 0.57, 0.29, -0.66, 0.72, 0.38, -0.91, 0.47, 0.62, -0.35, 0.78};
  for (int i = L.moments; i < L.tool; ++i)
    if (!fixed[i] && x[i] == 0) x[i] = kUnitMass * std::max(reach, 100.0) * pattern[(i - L.moments) % 12] / kMomentUnit;
  return x;
}

}  // namespace kincal
