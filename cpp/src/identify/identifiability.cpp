// kincal: which identification parameters the data can determine (held before the solve), and the
// condition number and observability index of the free ones after it.
#include "kincal/identify/identifiability.hpp"

#include "linearization.hpp"

#include "kincal/identify/priors.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <set>

namespace kincal {

using detail::linearize;
using detail::normal_matrix_lower;

namespace {


/// Which targets the data measure (by target index).
std::vector<bool> measured_targets(const MeasurementSet& data) {
  std::vector<bool> used(data.n_targets, false);
  for (const auto& r : data.rows) used[r.target] = true;
  return used;
}

int count_poses(const MeasurementSet& d) {
  std::set<int> ids;
  for (const auto& r : d.rows) ids.insert(r.pose);
  return static_cast<int>(ids.size());
}

/// A compliance is only identifiable where gravity loads its joint: below min_torque_share of the
/// largest joint's torque over the measured poses it is held (its effect is lost in the geometry).
void fix_unloaded_compliances(const Model& nominal, const MeasurementSet& data, const IdentifyOptions& opt,
                              IdentifyResult& res) {
  const ParamLayout& L = res.layout;
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
      char buf[200];
      std::snprintf(buf, sizeof buf, "gravity torque too small to see it (at most %.3g N m, %.1f%% of joint %d's)",
                    tmax[j] / 1000.0, 100.0 * tmax[j] / top,
                    static_cast<int>(std::max_element(tmax.begin(), tmax.end()) - tmax.begin()) + 1);
      res.fix(L.compliance + static_cast<int>(i), buf);
    }
  }
}

/// With the gravity fitted, compliance x moment is what the points see (point_model.hpp): the first
/// free compliance is held as the scale, at its start value or kUnitCompliance (res.start), unless
/// the rows carry several payloads (their known masses then fix the scale).
void hold_gravity_scale(const MeasurementSet& data, IdentifyResult& res) {
  const ParamLayout& L = res.layout;
  std::set<double> payloads;
  for (const auto& r : data.rows)
    if (!std::isnan(r.payload_kg)) payloads.insert(r.payload_kg);
  for (size_t i = 0; i < L.loaded.size(); ++i) {
    const int c = L.compliance + static_cast<int>(i);
    if (res.fixed[c]) continue;
    if (res.start[c] == 0) res.start[c] = kUnitCompliance;
    if (payloads.size() < 2)
      res.fix(c, "the scale of the fitted mass moments (no masses: compliance x moment is what the points see)");
    return;
  }
}

/// The order in which the greedy selection keeps parameters: targets, compliances, extra effects,
/// the joint lines from the second on, then the frames and the first joint line (what is left of
/// them is a gauge of the others).
std::vector<int> preference_order(const ParamLayout& L, bool orientation) {
  std::vector<int> order;
  for (int i = L.targets; i < L.effects; ++i) order.push_back(i);
  for (int i = L.compliance; i < L.tool; ++i) order.push_back(i);
  for (int i = L.effects; i < L.size; ++i) order.push_back(i);
  for (int j = 1; j < L.dof; ++j)
    for (int k = 0; k < 4; ++k) order.push_back(4 * j + k);
  // with measured orientations the tool frame itself is measured (the 6-D rows' target is held at
  // zero): keep it, hold the base's gauge instead
  if (orientation)
    for (int i = L.tool; i < L.tool + 6; ++i) order.push_back(i);
  for (int i = L.base; i < L.targets; ++i) order.push_back(i);  // every setup's
  for (int k = 0; k < 4; ++k) order.push_back(k);
  if (!orientation)  // reflectors alone: the tool frame is redundant with their offsets
    for (int i = L.tool; i < L.tool + 6; ++i) order.push_back(i);
  return order;
}

/// Greedy selection on the normal matrix of J's unit-scaled columns in order: the squared distance
/// of column i from the span of the chosen ones is N_ii - N_iS N_SS^-1 N_Si (an incremental
/// Cholesky factor). A column without effect, too close to the span or only weakly out of it is fixed.
void select_independent(const Eigen::MatrixXd& J, const std::vector<int>& order, const IdentifyOptions& opt,
                        IdentifyResult& res) {
  const int P = static_cast<int>(J.cols());
  Eigen::VectorXd nrm = J.colwise().norm().transpose();
  Eigen::MatrixXd N = normal_matrix_lower(J);
  N.triangularView<Eigen::StrictlyUpper>() = N.transpose();
  for (int a = 0; a < P; ++a)
    for (int b = 0; b < P; ++b) N(a, b) /= (nrm[a] > 0 ? nrm[a] : 1.0) * (nrm[b] > 0 ? nrm[b] : 1.0);
  std::vector<int> chosen;
  Eigen::MatrixXd Lc(P, P);  // rows: chosen index k; Lc(k, i) = component of column i on chosen k
  for (int i : order) {
    if (res.fixed[i]) continue;
    if (nrm[i] == 0) {
      res.fix(i, "no effect on the measured points");
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
      res.fix(i, "not identifiable: a combination of the other parameters");
      continue;
    }
    if (left < opt.weak_tolerance) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "barely identifiable: only %.1e of its effect is not a combination of the others", left);
      res.fix(i, buf);
      continue;
    }
    for (int a = 0; a < k; ++a) Lc(a, i) = li[a];
    Lc(k, i) = left;
    chosen.push_back(i);
  }
}

/// A generic campaign: 100 random poses in the joint limits, every measured target, the same kind
/// of rows (J_r^-1 keeps the rank for any abc) and temperatures, times and setups drawn from the data.
MeasurementSet generic_campaign(const Model& nominal, const MeasurementSet& data) {
  const int dof = nominal.dof();
  const std::vector<bool> measured = measured_targets(data);
  std::vector<bool> six_d(data.n_targets, false);  // the target of the 6-D rows (the tool frame)
  for (const auto& r : data.rows) six_d[r.target] = six_d[r.target] || (data.orientation && r.has_abc);
  MeasurementSet generic = without_rows(data);
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> ud(-0.45, 0.45);
  for (int p = 0; p < 100; ++p) {
    Measurement row;
    row.pose = p;
    row.q_deg.resize(dof);
    for (int j = 0; j < dof; ++j) {
      const JointSpec& js = nominal.spec().joints[j];
      row.q_deg[j] = 0.5 * (js.lower_deg + js.upper_deg) + ud(rng) * (js.upper_deg - js.lower_deg);
    }
    row.dir.resize(dof);
    for (int j = 0; j < dof; ++j) row.dir[j] = ud(rng) < 0 ? -1.0 : 1.0;
    const Measurement& like = data.rows[rng() % data.rows.size()];
    row.kind = like.kind;  // a probe row sees what its kind of constraint sees, wherever it is
    row.station = like.station;
    row.radius_mm = like.radius_mm;
    row.length_mm = like.length_mm;
    row.temperature_c = like.temperature_c;
    row.time_s = like.time_s;
    row.setup = like.setup;
    for (int t = 0; t < data.n_targets; ++t)
      if (measured[t]) row.target = t, row.has_abc = six_d[t], generic.rows.push_back(row);
  }
  return generic;
}


/// With priors: what these data leave redundant or barely seen (the greedy selection on the data,
/// parameters without a prior kept first so that the ones the prior determines are those left)
/// stays free, determined by its prior (res.at_prior), or is held when it has no prior. What a
/// generic campaign leaves redundant is held as without priors, except on probe data (`probe`) when
/// it has a prior: the generic campaign is a tracker's, its base frame free, while the stations
/// absorb the base frame otherwise, and a maximum a posteriori fit that holds a parameter at its
/// prior's centre forces the others to carry its share at their own prior's cost (four probed
/// faces: 0.174 mm held against a plain MAP fit's 0.052 on one draw, test_probe_map.py). On a
/// tracker's data those
/// are exact redundancies (the tool frame beside the targets): held, the model does not drift along
/// directions only a prior sees.
void at_prior(const Linearization& lin, const IdentifyResult& generic, const std::vector<int>& order,
              const IdentifyOptions& opt, const std::vector<double>& prior_sd, bool probe, IdentifyResult& res) {
  for (int i = 0; i < res.layout.size; ++i)
    if (generic.fixed[i] && !res.fixed[i] && !(probe && std::isfinite(prior_sd[i]))) res.fix(i, generic.fixed_reason[i]);
  std::vector<int> data_order;
  for (int pass = 0; pass < 2; ++pass)
    for (int i : order)
      if (std::isfinite(prior_sd[i]) == (pass == 1)) data_order.push_back(i);
  IdentifyResult on_data = res;
  select_independent(lin.jacobian, data_order, opt, on_data);
  for (int i = 0; i < res.layout.size; ++i) {
    if (res.fixed[i] || !on_data.fixed[i]) continue;
    if (std::isfinite(prior_sd[i]))
      res.at_prior[i] = true;
    else
      res.fix(i, "not determined by these poses (" + on_data.fixed_reason[i] + "), and no prior");
  }
}

/// One Gauss-Newton step of the columns `cols` of a linearization, each column scaled to unit norm:
/// the step (scaled units: divide by `nrm` for the parameters'), the columns' norms and the step's
/// covariance (the residual's variance after the step times the pseudo-inverse of the normal matrix).
struct ScaledStep {
  Eigen::VectorXd step, nrm;
  Eigen::MatrixXd cov;
};

ScaledStep scaled_step(const Linearization& lin, const std::vector<int>& cols) {
  Eigen::MatrixXd A(lin.jacobian.rows(), static_cast<Eigen::Index>(cols.size()));
  ScaledStep g;
  g.nrm.resize(A.cols());
  for (size_t c = 0; c < cols.size(); ++c) {
    g.nrm[c] = lin.jacobian.col(cols[c]).norm();
    A.col(c) = lin.jacobian.col(cols[c]) / (g.nrm[c] > 0 ? g.nrm[c] : 1.0);
  }
  const Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(lin.residuals.data(), A.rows());
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(A);
  g.step = -cod.solve(r);
  const double dofres = std::max<double>(1.0, static_cast<double>(A.rows() - cod.rank()));
  const double s2 = (r + A * g.step).squaredNorm() / dofres;
  g.cov = s2 * (A.transpose() * A).completeOrthogonalDecomposition().pseudoInverse();
  return g;
}

/// With the gravity fitted, at the moments the data show (xs): a free compliance is seen only through
/// compliance x moment of the links from its joint on, and its ratio to the held one only as far as
/// the held joint's torque shows those moments apart. Where the poses leave that ratio undetermined
/// (its linearized estimate with every free parameter less than 3 standard deviations from zero) the
/// points still see the product, but the solve would crawl along the valley compliance x moment =
/// const, out to a huge compliance on a vanishing moment (hundreds of iterations, a worse prediction):
/// the compliance is held at the held one's value instead (the moments carry the product).
void hold_undetermined_ratios(const PointModel& pm, const MeasurementSet& data, const IdentifyOptions& opt,
                              IdentifyResult& res, const std::vector<double>& xs) {
  const ParamLayout& L = res.layout;
  const Linearization lin = linearize(pm, data, xs, opt.orientation_weight);
  std::vector<int> cols;
  for (int i = 0; i < L.size; ++i)
    if (!res.fixed[i]) cols.push_back(i);
  const ScaledStep g = scaled_step(lin, cols);
  const Eigen::VectorXd &step = g.step, &nrm = g.nrm;
  const Eigen::MatrixXd& cov = g.cov;
  for (size_t c = 0; c < cols.size(); ++c) {
    const int i = cols[c];
    if (i < L.compliance || i >= L.moments || !(nrm[c] > 0)) continue;
    const double est = xs[i] + step[c] / nrm[c], sd = std::sqrt(std::max(0.0, cov(c, c))) / nrm[c];
    if (std::abs(est) >= 3 * sd) continue;
    char buf[200];
    std::snprintf(buf, sizeof buf, "its ratio to the held compliance not determined by these poses (%.2g +- %.2g "
                  "deg/kNm): held at the held one's value", est, sd);
    res.start[i] = xs[i];
    res.fix(i, buf);
  }
}

/// With the gravity fitted: the moments the data show at x (one Gauss-Newton step of every free
/// parameter but the compliances, each of those at the held one's value: the moments are linear
/// then), and, as fix_unloaded_compliances does with masses, the compliance of a joint whose torque
/// from them stays below opt.min_torque_share of the largest held. Returns x with those moments: the
/// point at which the data's columns are judged (at zero moments no compliance has an effect, and
/// at generic ones a joint that gravity barely loads would look identifiable).
std::vector<double> fitted_moments(const PointModel& pm, const MeasurementSet& data, const std::vector<double>& x,
                                   const IdentifyOptions& opt, IdentifyResult& res) {
  const ParamLayout& L = res.layout;
  std::vector<double> xs = pm.probe(x, res.fixed);  // compliances set; its generic moments dropped:
  for (int i = L.moments; i < L.tool; ++i) xs[i] = x[i];
  const Linearization lin = linearize(pm, data, xs, opt.orientation_weight);
  // the model's extra effects (maps, transmission errors, backlash, thermal expansion; the
  // instrument's drift stays with the frames) sit out of this step: a map of joint 2 took the
  // shoulder's deflection there, the moments of links 4-6 looked unseen, and the fit that followed
  // held joints 3-6's compliances (0.23 mm where the compliance alone fits 0.036 mm)
  auto model_effect = [&](int i) {
    return i >= L.effects && i < L.stations && !(L.drift >= 0 && i >= L.drift && i < L.drift + 6);
  };
  std::vector<int> cols;
  for (int i = 0; i < L.size; ++i)
    if (!res.fixed[i] && (i < L.compliance || i >= L.moments) && !model_effect(i)) cols.push_back(i);
  // a link's pair of moments is seen when it stands out of its noise: chi-square (2 degrees of
  // freedom) of the pair with the step's covariance above its 99% quantile; the others are held at
  // zero (the bilinear form is flat along a compliance whose moments vanish)
  const ScaledStep g = scaled_step(lin, cols);
  const Eigen::VectorXd &step = g.step, &nrm = g.nrm;
  const Eigen::MatrixXd& cov = g.cov;
  int seen = 0;
  for (size_t c = 0; c + 1 < cols.size(); ++c) {
    const int i = cols[c];
    if (i < L.moments || i >= L.tool || (i - L.moments) % 2 != 0 || cols[c + 1] != i + 1) continue;
    const Eigen::Vector2d a = step.segment<2>(static_cast<Eigen::Index>(c));
    const Eigen::Matrix2d ca = cov.block<2, 2>(static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(c));
    const Eigen::FullPivLU<Eigen::Matrix2d> lu(ca);
    const double chi2 = lu.isInvertible() ? a.dot(lu.solve(a)) : 0.0;
    if (chi2 > 9.21 && nrm[c] > 0 && nrm[c + 1] > 0) {
      xs[i] += step[c] / nrm[c];
      xs[i + 1] += step[c + 1] / nrm[c + 1];
      ++seen;
      continue;
    }
    char buf[160];
    std::snprintf(buf, sizeof buf, "moment not seen by these poses (chi-square %.1f of its pair, below 9.21)", chi2);
    res.fix(i, buf);
    res.fix(i + 1, buf);
  }
  // the joints' torques from those moments over the measured poses
  const Model fitted(pm.at(xs).spec());
  std::vector<double> tmax(L.dof, 0.0);
  VecQ tau;
  for (const auto& row : data.rows) {
    gravity_torque(fitted, row.q_deg * kDeg, tau);
    for (int j = 0; j < L.dof; ++j) tmax[j] = std::max(tmax[j], std::abs(tau[j]));
  }
  double top = 0;
  int top_j = 0;
  for (int j : L.loaded)
    if (seen > 0 && tmax[j] > top) top = tmax[j], top_j = j;  // none seen: every compliance held
  for (size_t i = 0; i < L.loaded.size(); ++i) {
    const int j = L.loaded[i], c = L.compliance + static_cast<int>(i);
    if (res.fixed[c] || (top > 0 && !(tmax[j] < opt.min_torque_share * top))) continue;
    char buf[200];
    if (top > 0)
      std::snprintf(buf, sizeof buf, "gravity torque too small to see it (fitted moments: %.1f%% of joint %d's)",
                    100.0 * tmax[j] / top, top_j + 1);
    else
      std::snprintf(buf, sizeof buf, "no gravity deflection seen by these poses (no fitted moment stands out)");
    res.fix(c, buf);
    xs[c] = x[c];
  }
  if (seen > 0) hold_undetermined_ratios(pm, data, opt, res, xs);
  return xs;
}

/// With the gravity fitted, the solve starts where the columns were judged (xp: the moments the data
/// show, every free compliance at the held one's value) rather than at zero moments, where no
/// compliance has an effect and the bilinear compliance x moment problem is at its saddle; what the
/// analysis held keeps its start value. x becomes that start; returns the data's linearization there.
Linearization start_at(const PointModel& pm, const MeasurementSet& data, const IdentifyOptions& opt, const IdentifyResult& res,
                       std::vector<double> xp, std::vector<double>& x, const Linearization& lin_xp) {
  if (xp == x) return lin_xp;
  const ParamLayout& L = res.layout;
  for (int i = 0; i < L.size; ++i)  // a compliance held at the held one's value: its start (hold_undetermined_ratios)
    if (res.fixed[i]) xp[i] = i >= L.compliance && i < L.moments ? res.start[i] : x[i];
  x = xp;
  return linearize(pm, data, x, opt.orientation_weight);
}

}  // namespace

void fix_unobservable(const Model& nominal, const MeasurementSet& data, const IdentifyOptions& opt,
                      IdentifyResult& res) {
  const ParamLayout& L = res.layout;
  const std::vector<bool> measured = measured_targets(data);
  for (int t = 0; t < data.n_targets; ++t)
    if (!measured[t])
      for (int k = 0; k < 3; ++k) res.fix(L.targets + 3 * t + k, "target never measured");
  // a 6-D row measures the tool frame itself: its target has no offset (the tool frame is identified
  // instead); reflector rows keep theirs, in that frame. One measured frame: 6-D rows of one target.
  int six_d = -1;
  for (const auto& r : data.rows) {
    if (!data.orientation || !r.has_abc || r.target == six_d) continue;
    if (six_d >= 0)
      throw InputError(data.source + (r.line ? ":" + std::to_string(r.line) : "") + ": 6-D rows of target " +
                       std::to_string(six_d) + " and of target " + std::to_string(r.target) +
                       ": the frame a 6-D row measures is the tool frame (the TCP), one target; measure the other "
                       "targets as points (a, b, c empty)");
    six_d = r.target;
  }
  if (six_d >= 0)
    for (int k = 0; k < 3; ++k) {
      res.start[L.targets + 3 * six_d + k] = 0;
      res.fix(L.targets + 3 * six_d + k, "the frame a 6-D row measures is the tool frame (no offset)");
    }
  // a placement is seen by the points and poses of its setup; its probe rows alone see it moved
  // with their stations (which the data place in the instrument frame of nothing measured)
  std::vector<int> placed(static_cast<size_t>(L.n_setups), 0);  // 0: no row, 1: probe rows only, 2: points
  for (const auto& r : data.rows)
    if (r.setup >= 0 && r.setup < L.n_setups)
      placed[static_cast<size_t>(r.setup)] = std::max(placed[static_cast<size_t>(r.setup)], is_probe(r.kind) ? 1 : 2);
  for (int s = 0; s < L.n_setups; ++s)
    if (placed[static_cast<size_t>(s)] < 2)
      for (int k = 0; k < 6; ++k)
        res.fix(L.base + 6 * s + k, placed[static_cast<size_t>(s)] == 0 ? kSetupNeverMeasured : kProbeOnlySetup);
  std::vector<bool> touched(L.station_names.size(), false);
  for (const auto& r : data.rows)
    if (r.station >= 0 && r.station < static_cast<int>(touched.size())) touched[static_cast<size_t>(r.station)] = true;
  for (size_t k = 0; k < touched.size(); ++k)
    if (!touched[k])
      for (int c = 0; c < 3; ++c) res.fix(L.stations + 3 * static_cast<int>(k) + c, "station never touched");
  if (!opt.compliance)
    for (int i = L.compliance; i < L.tool; ++i) res.fix(i, "not asked for (--effects)");
  else if (!opt.compliance_joints.empty())
    for (size_t i = 0; i < L.loaded.size(); ++i) {
      const auto& asked = opt.compliance_joints;
      if (std::find(asked.begin(), asked.end(), L.loaded[i]) == asked.end())
        res.fix(L.compliance + static_cast<int>(i), "not in the model");
    }
  // with the gravity fitted the model's masses are not what acts: the moments say how loaded a joint is
  if (opt.compliance && !L.loaded.empty() && !L.fit_gravity) fix_unloaded_compliances(nominal, data, opt, res);
  if (L.fit_gravity) hold_gravity_scale(data, res);
  for (const auto& name : opt.fix) {
    auto it = std::find(L.names.begin(), L.names.end(), name);
    if (it == L.names.end()) throw InputError("identify: no parameter named '" + name + "'");
    res.fix(static_cast<int>(it - L.names.begin()), "held by request");
  }
}

Linearization fix_unidentifiable(const PointModel& pm, const Model& nominal, const MeasurementSet& data,
                                 std::vector<double>& x, const IdentifyOptions& opt, IdentifyResult& res,
                                 const std::vector<double>& prior_sd, const Touches* touches) {
  const ParamLayout& L = res.layout;
  // penalised parameters (a ridge determines them where the data do not) are left out of the
  // analysis: always free, they never make another parameter look redundant
  std::vector<int> order;
  for (int i : preference_order(L, data.orientation)) {
    bool penalised = false;
    for (const auto& [name, w] : opt.penalties) penalised = penalised || (w > 0 && L.names[i] == name);
    if (!penalised) order.push_back(i);
  }
  // what the generic campaign determines but the data do not means the data are too few or too alike
  // with the gravity fitted, judged at the moments the data show (fitted_moments)
  std::vector<double> xp = res.layout.fit_gravity ? fitted_moments(pm, data, x, opt, res) : x;
  const bool priors = any_prior(prior_sd);
  // without priors, a probe campaign's known lengths set the overall scale: what else its rows
  // determine is judged on the touches where the touches alone put the frames, the generic campaign
  // made of them too (near the weak threshold the lengths' rows, and the frames they pulled, tipped
  // another parameter over it: joint6.tilt_u held with the length, free without, the ball centres
  // 0.015 mm apart after the similarity)
  bool by_lengths = !priors && touches && !L.fit_gravity;
  Linearization judged;
  Eigen::MatrixXd every_row;  // the touches and the lengths, at the touches' frames
  if (by_lengths) {  // (where the touches see the scale too, as a tracker's points do, nothing changes)
    judged = linearize(pm, touches->rows, touches->at, opt.orientation_weight);
    every_row = linearize(pm, data, touches->at, opt.orientation_weight).jacobian;
    by_lengths =
        scale_visibility(pm, judged.jacobian, touches->at) < 0.1 * scale_visibility(pm, every_row, touches->at);
  }
  IdentifyResult generic = res;
  select_independent(linearize(pm, generic_campaign(nominal, by_lengths ? touches->rows : data),
                               by_lengths ? touches->at : xp, opt.orientation_weight)
                         .jacobian, order, opt, generic);
  Linearization lin = linearize(pm, data, xp, opt.orientation_weight);
  res.at_prior.assign(L.size, false);
  if (priors) {
    at_prior(lin, generic, order, opt, prior_sd, data.has_probe(), res);
    return start_at(pm, data, opt, res, xp, x, lin);
  }
  // the data choose among the parameters in the generic campaign's basis first: where they determine
  // as many as it does, they may still pick other columns in the plain order (a sphere station beside
  // a tracker's points: joint 6's move_v before base.z, the two a combination of the other joints'
  // and the target's in these data, not in the generic campaign's), which is no loss of rank
  std::vector<int> data_order;
  for (int pass = 0; pass < 2; ++pass)
    for (int i : order)
      if (generic.fixed[i] == (pass == 1)) data_order.push_back(i);
  const std::vector<bool> before = res.fixed;
  select_independent(by_lengths ? judged.jacobian : lin.jacobian, data_order, opt, res);
  if (by_lengths) release_scale(every_row, judged.jacobian, generic, before, res);
  lin = start_at(pm, data, opt, res, xp, x, lin);
  std::string missing;
  int n_missing = 0;
  // a probe campaign without a known length leaves the scale to one held parameter (its generic
  // campaign, rows scattered away from their stations, sees it): that one is no error
  bool scale_free = data.has_probe() && !scale_seen(pm, lin.jacobian, x);
  // only what the data make exactly redundant counts (near the weak threshold the two may differ)
  for (int i = 0; i < L.size; ++i)
    if (res.fixed[i] && !generic.fixed[i] && res.fixed_reason[i].rfind("not identifiable", 0) == 0) {
      if (scale_free) {
        res.fixed_reason[i] = "held for the overall scale: no known length in these probe data (--artifact)";
        scale_free = false;
        continue;
      }
      missing += (n_missing++ ? ", " : "") + L.names[i];
    }
  if (n_missing)
    throw InputError(data.source + ": the " + std::to_string(data.rows.size()) + " measured points of " +
                     std::to_string(count_poses(data)) + " poses cannot determine " + missing +
                     ": too few or too similar poses to identify the model");
  return lin;
}


}  // namespace kincal
