// kincal: the probe stations of the identification (measurements without a tracker): each plane's
// reference normal, the stations' values at a parameter vector, a probe row's residual along its
// constraint with its Jacobian, the artifact's known lengths and angles, and the stations' start.
#include "point_eval.hpp"

#include "kincal/identify/stations.hpp"

#include "kincal/core/rigid.hpp"
#include "kincal/identify/so3.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>

namespace kincal {

int probe_residual(const StationValue& s, const Measurement& m, const Vec3& y, double* r) {
  switch (m.kind) {
    case MeasureKind::sphere:
      for (int k = 0; k < 3; ++k) r[k] = y[k] - s.point[k];
      return 3;
    case MeasureKind::plane:
      r[0] = s.normal.dot(y) - s.offset - m.radius_mm;
      return 1;
    case MeasureKind::distance:
      r[0] = (y - s.point).norm() - m.length_mm;
      return 1;
    default:
      break;
  }
  throw std::logic_error("probe_residual: not a probe row");
}

const StationValue* station_of(const std::vector<StationValue>& values, const MeasurementSet& data,
                               const Measurement& m) {
  if (m.station < 0 || m.station >= static_cast<int>(data.station_names.size())) return nullptr;
  for (const StationValue& v : values)
    if (v.name == data.station_names[static_cast<size_t>(m.station)] && v.kind == m.kind) return &v;
  return nullptr;
}

}  // namespace kincal

namespace kincal::detail {

std::vector<Eigen::Isometry3d> start_placements(const PointStructure& s, const MeasurementSet& data) {
  std::vector<Eigen::Isometry3d> out;
  for (int k = 0; k < s.layout.n_setups; ++k) {
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    f.linear() = s.r0[static_cast<size_t>(k)];
    f.translation() = s.t0[static_cast<size_t>(k)];
    std::vector<size_t> rows;  // the measured points of the setup (a probe row has none)
    for (size_t i = 0; i < data.rows.size(); ++i)
      if (data.rows[i].setup == k && !is_probe(data.rows[i].kind)) rows.push_back(i);
    if (rows.size() >= 3) {  // fewer: the setup's frame starts at its reference
      Eigen::Matrix3Xd a(3, rows.size()), b(3, rows.size());
      for (size_t j = 0; j < rows.size(); ++j) {
        a.col(static_cast<Eigen::Index>(j)) = fk_compliant(s.nominal, data.rows[rows[j]].q_deg * kDeg).translation();
        b.col(static_cast<Eigen::Index>(j)) = data.rows[rows[j]].xyz;
      }
      f = rigid_fit(a, b);
    }
    out.push_back(f);
  }
  return out;
}

namespace {

/// The nominal points of a station's rows (the tool frame's origin moved by the row's target offset
/// in x, when given), each seen from its setup's placement.
Eigen::Matrix3Xd station_points(const PointStructure& s, const MeasurementSet& data,
                                const std::vector<Eigen::Isometry3d>& place, int station, Eigen::Matrix3Xd* flanges,
                                const std::vector<double>* x = nullptr) {
  std::vector<const Measurement*> rows;
  for (const Measurement& r : data.rows)
    if (r.station == station) rows.push_back(&r);
  Eigen::Matrix3Xd y(3, rows.size());
  if (flanges) flanges->resize(3, static_cast<Eigen::Index>(rows.size()));
  const Eigen::Isometry3d tool_inv = s.nominal.tool().inverse();
  for (size_t j = 0; j < rows.size(); ++j) {
    const Eigen::Isometry3d& b = place[static_cast<size_t>(rows[j]->setup)];
    const Eigen::Isometry3d t = fk_compliant(s.nominal, rows[j]->q_deg * kDeg);
    Vec3 offset = Vec3::Zero();
    if (x && rows[j]->target >= 0)
      offset = Eigen::Map<const Vec3>(x->data() + s.layout.targets + 3 * rows[j]->target);
    y.col(static_cast<Eigen::Index>(j)) = b * (t * offset);
    if (flanges) flanges->col(static_cast<Eigen::Index>(j)) = b * (t * tool_inv).translation();
  }
  return y;
}

/// Sum of (|y_j - p| - l_j)^2 after a few Gauss-Newton steps on the pivot p from `p` (updated).
double refine_pivot(const Eigen::Matrix3Xd& y, const std::vector<double>& len, Vec3& p) {
  double cost = 0;
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
    Vec3 Jtr = Vec3::Zero();
    cost = 0;
    for (Eigen::Index j = 0; j < y.cols(); ++j) {
      const Vec3 d = p - y.col(j);
      const double n = d.norm(), r = n - len[static_cast<size_t>(j)];
      const Vec3 g = n > 0 ? Vec3(d / n) : Vec3::UnitX();
      JtJ += g * g.transpose();
      Jtr += g * r;
      cost += r * r;
    }
    const Vec3 step = JtJ.ldlt().solve(Jtr);
    if (!step.allFinite()) break;
    p -= step;
    if (step.norm() < 1e-9) break;
  }
  return cost;
}

/// A ballbar's pivot from the ball centres y and the measured lengths. The linear sphere fit
/// (radius free) fails where the bar's directions lie near one cone (the centres near a circle:
/// along its axis the fit is undetermined), so the pivot is refined with the lengths from it and from
/// the two points on the circle's axis at the bar's length; of near-equal costs (the mirror images of
/// a circle) the one on the far side of the ball from the flange is taken.
Vec3 start_pivot(const Eigen::Matrix3Xd& y, const Eigen::Matrix3Xd& flanges, const std::vector<double>& len) {
  const Eigen::Index n = y.cols();
  const Vec3 c = y.rowwise().mean();
  // |y - p|^2 = l^2: 2 y.p - |p|^2 = |y|^2 - l^2, linear in p and |p|^2 (about the mean, for conditioning)
  Eigen::MatrixXd A(n, 4);
  Eigen::VectorXd b(n);
  double mean_len = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    const Vec3 yj = y.col(j) - c;
    A.row(j) << 2 * yj.transpose(), -1.0;
    b[j] = yj.squaredNorm() - len[static_cast<size_t>(j)] * len[static_cast<size_t>(j)];
    mean_len += len[static_cast<size_t>(j)] / static_cast<double>(n);
  }
  std::vector<Vec3> starts;
  const Eigen::VectorXd sol = A.colPivHouseholderQr().solve(b);
  if (sol.allFinite()) starts.push_back(c + sol.head<3>());
  const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(y.colwise() - c, Eigen::ComputeFullU);
  const Vec3 axis = svd.matrixU().col(2);
  const double rho2 = (y.colwise() - c).colwise().squaredNorm().mean();
  const double h = std::sqrt(std::max(0.0, mean_len * mean_len - rho2));
  starts.push_back(c + axis * h);
  starts.push_back(c - axis * h);
  Vec3 best = c;
  double best_cost = std::numeric_limits<double>::infinity(), best_side = 0;
  for (Vec3 p : starts) {
    const double cost = refine_pivot(y, len, p);
    if (!p.allFinite()) continue;
    // > 0 when the pivot lies beyond the ball, away from the flange
    const double side = ((y.colwise() - flanges.rowwise().mean()).rowwise().mean()).dot(p - c);
    const bool mirror = std::abs(cost - best_cost) <= 1e-6 * static_cast<double>(n) + 1e-3 * std::min(cost, best_cost);
    if (mirror ? side > best_side : cost < best_cost) best = p, best_cost = cost, best_side = side;
  }
  return best;
}

}  // namespace

void PointStructure::init_stations(const MeasurementSet* data) {
  const size_t n = layout.station_names.size();
  auto directions = [&] {
    station_normal = layout.station_normals;
    station_u.clear();
    station_v.clear();
    for (const Vec3& nrm : station_normal) station_u.push_back(nrm.unitOrthogonal()), station_v.push_back(nrm.cross(station_u.back()));
  };
  if (layout.station_normals.size() == n) return directions();  // given (another fit's layout)
  layout.station_normals.assign(n, Vec3::UnitZ());
  if (data && n > 0) compute_normals(*data);
  directions();
}

void PointStructure::compute_normals(const MeasurementSet& d) {
  const MeasurementSet* data = &d;
  const size_t n = layout.station_names.size();
  const std::vector<Eigen::Isometry3d> place = start_placements(*this, *data);
  std::vector<double> x(static_cast<size_t>(layout.size), 0.0);  // the targets at their start
  for (size_t t = 0; t < target_start.size() && static_cast<int>(t) < layout.n_targets; ++t)
    for (int c = 0; c < 3; ++c) x[static_cast<size_t>(layout.targets) + 3 * t + static_cast<size_t>(c)] = target_start[t][c];
  for (size_t k = 0; k < n; ++k) {
    if (layout.station_kinds[k] != MeasureKind::plane) continue;
    Eigen::Matrix3Xd flanges;
    const Eigen::Matrix3Xd y = station_points(*this, *data, place, static_cast<int>(k), &flanges, &x);
    if (y.cols() < 3) continue;
    const Vec3 c = y.rowwise().mean();
    const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(y.colwise() - c, Eigen::ComputeFullU);
    Vec3 nrm = svd.matrixU().col(2);
    // towards the flange: the ball centres lie on the plane's side where the flange is
    if ((flanges.colwise() - y.rowwise().mean()).rowwise().mean().dot(nrm) < 0) nrm = -nrm;
    layout.station_normals[k] = nrm;
  }
}

void PointEval::init_stations() {
  const ParamLayout& L = layout_;
  station_.resize(L.station_names.size());
  for (size_t k = 0; k < station_.size(); ++k) {
    StationState& st = station_[k];
    const double* p = &x_[L.stations + 3 * k];
    st.v.name = L.station_names[k];
    st.v.kind = L.station_kinds[k];
    if (L.station_kinds[k] != MeasureKind::plane) {
      st.v.point = Vec3(p[0], p[1], p[2]);
      continue;
    }
    const Vec3 w = s_->station_normal[k] + p[0] * s_->station_u[k] + p[1] * s_->station_v[k];
    const double nw = w.norm();
    const Vec3 n = w / nw;
    st.v.normal = n;
    st.dn[0] = (s_->station_u[k] - n * n.dot(s_->station_u[k])) / nw;
    st.dn[1] = (s_->station_v[k] - n * n.dot(s_->station_v[k])) / nw;
    st.v.offset = p[2];
  }
}

int PointEval::probe_residuals(const Measurement& m, int size, double* r, double* J) const {
  const ParamLayout& L = layout_;
  if (m.station < 0 || m.station >= static_cast<int>(station_.size()))
    throw InputError("a probe row of station code " + std::to_string(m.station) + " but the layout has " +
                     std::to_string(station_.size()) + " station(s)");
  const int P = L.size, off = L.stations + 3 * m.station;
  const StationState& st = station_[static_cast<size_t>(m.station)];
  const Vec3 y = predict(m, J, nullptr, nullptr);
  std::fill_n(r, size, 0.0);
  const int used = probe_residual(st.v, m, y, r);
  if (!J) return used;
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> JJ(J, size, P);
  if (size > 3) JJ.bottomRows(size - 3).setZero();
  switch (m.kind) {
    case MeasureKind::sphere:
      JJ.block(0, off, 3, 3) -= Mat3::Identity();
      return used;
    case MeasureKind::plane:
      {
        JJ.row(0) = st.v.normal.transpose() * JJ.topRows(3);
        JJ(0, off) += st.dn[0].dot(y);
        JJ(0, off + 1) += st.dn[1].dot(y);
        JJ(0, off + 2) -= 1.0;
        JJ.middleRows(1, 2).setZero();
      }
      return used;
    case MeasureKind::distance: {
      const Vec3 v = y - st.v.point;
      const double len = v.norm();
      const Vec3 e = len > 0 ? Vec3(v / len) : Vec3::UnitX();
      JJ.row(0) = e.transpose() * JJ.topRows(3);
      for (int k = 0; k < 3; ++k) JJ(0, off + k) -= e[k];
      JJ.middleRows(1, 2).setZero();
      return used;
    }
    default:
      break;
  }
  throw std::logic_error("probe_residuals: not a probe row");
}

double PointEval::artifact_residual(const ArtifactTerm& a, double* J) const {
  const ParamLayout& L = layout_;
  const int P = L.size, oa = L.stations + 3 * a.a, ob = L.stations + 3 * a.b;
  const StationState &sa = station_[static_cast<size_t>(a.a)], &sb = station_[static_cast<size_t>(a.b)];
  if (J) std::fill_n(J, P, 0.0);
  const bool planes = L.station_kinds[static_cast<size_t>(a.a)] == MeasureKind::plane;
  if (!std::isnan(a.angle_deg)) {  // the unsigned angle between the planes, on a 1 m lever (mm)
    const double c = sa.v.normal.dot(sb.v.normal), sign = c < 0 ? -1.0 : 1.0;
    const double ac = std::min(1.0, std::abs(c)), ang = std::acos(ac);
    if (J) {
      const double d = -kArtifactLever / std::max(std::sqrt(1 - ac * ac), 1e-9) * sign;  // d(angle)/dc
      for (int k = 0; k < 2; ++k) J[oa + k] = d * sb.v.normal.dot(sa.dn[k]), J[ob + k] = d * sa.v.normal.dot(sb.dn[k]);
    }
    return kArtifactLever * (ang - a.angle_deg * kDeg);
  }
  if (planes) {  // the faces n_a y = d_a and (nearly) parallel n_b y = d_b: |d_a - s d_b|, s = sign(n_a n_b)
    const double s = sa.v.normal.dot(sb.v.normal) < 0 ? -1.0 : 1.0, gap = sa.v.offset - s * sb.v.offset, sg = gap < 0 ? -1.0 : 1.0;
    if (J) J[oa + 2] = sg, J[ob + 2] = -s * sg;
    return std::abs(gap) - a.distance_mm;
  }
  const Vec3 v = sa.v.point - sb.v.point;
  const double len = v.norm();
  const Vec3 e = len > 0 ? Vec3(v / len) : Vec3::UnitX();
  if (J)
    for (int k = 0; k < 3; ++k) J[oa + k] = e[k], J[ob + k] = -e[k];
  return len - a.distance_mm;
}

std::vector<StationValue> PointEval::stations() const {
  std::vector<StationValue> out;
  for (const StationState& st : station_) out.push_back(st.v);
  return out;
}

void start_stations(const PointStructure& s, const MeasurementSet& data, const std::vector<Eigen::Isometry3d>& place,
                    std::vector<double>& x) {
  const ParamLayout& L = s.layout;
  for (size_t k = 0; k < L.station_names.size(); ++k) {
    const Eigen::Matrix3Xd y = station_points(s, data, place, static_cast<int>(k), nullptr, &x);
    if (y.cols() == 0) continue;
    double* p = &x[L.stations + 3 * k];
    const Vec3 c = y.rowwise().mean();
    if (L.station_kinds[k] == MeasureKind::plane) {
      double sum = 0;
      int j = 0;
      for (const Measurement& r : data.rows)
        if (r.station == static_cast<int>(k)) sum += s.station_normal[k].dot(y.col(j++)) - r.radius_mm;
      p[0] = p[1] = 0;
      p[2] = sum / static_cast<double>(y.cols());
      continue;
    }
    Vec3 start = c;
    if (L.station_kinds[k] == MeasureKind::distance && y.cols() >= 4) {
      Eigen::Matrix3Xd flanges;
      station_points(s, data, place, static_cast<int>(k), &flanges, &x);
      std::vector<double> len;
      for (const Measurement& r : data.rows)
        if (r.station == static_cast<int>(k)) len.push_back(r.length_mm);
      start = start_pivot(y, flanges, len);
    }
    for (int i = 0; i < 3; ++i) p[i] = start[i];
  }
}

}  // namespace kincal::detail
