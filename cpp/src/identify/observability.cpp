// kincal: what the identified parameters' Jacobian says of the data (identifiability.hpp): the
// conditioning of what they determine, and whether they see the arm's overall scale.
#include "kincal/identify/identifiability.hpp"

#include "kincal/identify/point_model.hpp"

#include "linearization.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>

namespace kincal {

using detail::linearize;
using detail::normal_matrix_lower;

/// The scaling is about the first setup's base origin: the joint lines' points, the tool's and the
/// targets' offsets, the other placements, the stations; the compliances the inverse (the torques
/// scale with the arms, the deflection angles stay).
Eigen::VectorXd scale_direction(const PointModel& pm, const std::vector<double>& x) {
  const ParamLayout& L = pm.layout();
  const PointState at = pm.at(x);
  const ModelSpec& s = at.spec();
  Eigen::VectorXd v = Eigen::VectorXd::Zero(L.size);
  const Campaign& c = at.campaign();
  const Vec3 o = c.base().translation();
  for (int j = 0; j < L.dof; ++j) {
    const Vec3 w = s.joints[j].axis, p = s.joints[j].point;
    const Vec3 u = w.unitOrthogonal(), vv = w.cross(u);  // (the layout's own directions are its nominal's; a
    v[4 * j + 2] = p.dot(u);                              // small tilt changes them little)
    v[4 * j + 3] = p.dot(vv);
  }
  for (size_t i = 0; i < L.loaded.size(); ++i) v[L.compliance + static_cast<int>(i)] = -x[L.compliance + i];
  for (int i = L.moments; i < L.tool; ++i) v[i] = x[i];
  const Vec3 t = pose_to_iso(s.tool).translation();
  for (int k = 0; k < 3; ++k) v[L.tool + k] = t[k];
  for (int i = L.targets; i < L.effects; ++i) v[i] = x[i];
  for (int st = 1; st < L.n_setups; ++st) {
    const Vec3 ts = pose_to_iso(c.setups[static_cast<size_t>(st)].base_in_instrument).translation() - o;
    for (int k = 0; k < 3; ++k) v[L.base + 6 * st + k] = ts[k];
  }
  const std::vector<StationValue> sv = at.stations();
  for (size_t k = 0; k < sv.size(); ++k) {
    const int c = L.stations + 3 * static_cast<int>(k);
    if (sv[k].kind == MeasureKind::plane) {
      v[c + 2] = sv[k].offset - sv[k].normal.dot(o);
    } else {
      for (int i = 0; i < 3; ++i) v[c + i] = sv[k].point[i] - o[i];
    }
  }
  return v;
}

namespace {

/// What the rows (J) see of a uniform scaling at x, relative to what each parameter's part of it
/// would show alone: 0 when the scaling is not seen at all.
template <class Matrix>
double scale_visibility_of(const PointModel& pm, const Matrix& J, const std::vector<double>& x) {
  const Eigen::VectorXd v = scale_direction(pm, x);
  double parts = 0;
  for (Eigen::Index i = 0; i < v.size(); ++i) parts += J.col(i).squaredNorm() * v[i] * v[i];
  return parts > 0 ? (J * v).norm() / std::sqrt(parts) : 0.0;
}

template <class Matrix>
bool scale_seen_by(const PointModel& pm, const Matrix& J, const std::vector<double>& x) {
  return scale_visibility_of(pm, J, x) > 1e-3;
}

template <class Matrix>
void observability_of(const PointModel& pm, const Matrix& J, const MeasurementSet& data, IdentifyResult& res) {
  // the overall scale: what the rows see of a uniform scaling of every length, against what a point
  // measured at the robot's reach would see (a probe campaign without a known length sees nothing)
  res.scale_determined = scale_seen_by(pm, J, res.x);
  std::vector<int> free_idx;
  for (int i = 0; i < res.layout.size; ++i)  // what the data determine (not the priors)
    if (!res.fixed[i] && !(i < static_cast<int>(res.at_prior.size()) && res.at_prior[i])) free_idx.push_back(i);
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
}

}  // namespace

bool scale_seen(const PointModel& pm, const Eigen::MatrixXd& J, const std::vector<double>& x) {
  return scale_seen_by(pm, J, x);
}

double scale_visibility(const PointModel& pm, const Eigen::MatrixXd& J, const std::vector<double>& x) {
  return scale_visibility_of(pm, J, x);
}

void observability(const PointModel& pm, const MeasurementSet& data, const IdentifyOptions& opt, IdentifyResult& res,
                   const double* jacobian) {
  if (jacobian && data.artifact.empty()) {
    const Eigen::Index rows = static_cast<Eigen::Index>(residual_size(residual_kind(data)) * data.rows.size());
    observability_of(pm, Eigen::Map<const RowMatrix>(jacobian, rows, pm.layout().size), data, res);
  } else {
    observability_of(pm, linearize(pm, data, res.x, opt.orientation_weight).jacobian, data, res);
  }
}

bool without_lengths(const MeasurementSet& data, MeasurementSet& out) {
  out = data;
  out.artifact.clear();
  for (const ArtifactTerm& a : data.artifact)
    if (std::isnan(a.distance_mm)) out.artifact.push_back(a);
  return out.artifact.size() < data.artifact.size();
}

/// (identifiability.hpp)
void release_scale(const Eigen::MatrixXd& J, const Eigen::MatrixXd& J_touches, const IdentifyResult& generic,
                   const std::vector<bool>& before, IdentifyResult& res) {
  std::vector<int> free_cols, held;
  for (int i = 0; i < res.layout.size; ++i) {
    if (!res.fixed[i]) free_cols.push_back(i);
    else if (!before[static_cast<size_t>(i)] && !generic.fixed[i]) held.push_back(i);
  }
  // the distance of each held column from the free ones' span, every column scaled to unit norm
  auto left_of = [&](const Eigen::MatrixXd& M) {
    auto unit = [&](int i) -> Eigen::VectorXd {
      const double n = M.col(i).norm();
      return M.col(i) / (n > 0 ? n : 1.0);
    };
    Eigen::MatrixXd F(M.rows(), static_cast<Eigen::Index>(free_cols.size()));
    for (size_t k = 0; k < free_cols.size(); ++k) F.col(static_cast<Eigen::Index>(k)) = unit(free_cols[k]);
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(F);
    std::vector<double> left;
    for (int i : held) {
      const Eigen::VectorXd c = unit(i);
      left.push_back((c - F * qr.solve(c)).norm());
    }
    return left;
  };
  const std::vector<double> with = left_of(J), without = left_of(J_touches);
  int best = -1;
  double most = 0;
  for (size_t k = 0; k < held.size(); ++k)  // what the lengths see: ten times what the touches alone do
    if (with[k] > most && with[k] > 10 * without[k]) best = held[k], most = with[k];
  if (best < 0) return;
  res.fixed[best] = false;
  res.fixed_reason[best].clear();
}

}  // namespace kincal
