#include "kincal/feed/feed.hpp"

#include "kincal/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kincal {

Eigen::VectorXd time_optimal_feed(const Eigen::VectorXd& s, const RowMatrix& d1, const RowMatrix& d2, const Eigen::VectorXd& v,
                                  const Eigen::VectorXd& a, const Eigen::VectorXd& cap, double& time) {
  const Eigen::Index n = s.size(), dof = d1.cols();
  if (d1.rows() != n || d2.rows() != n || d2.cols() != dof || v.size() != dof || a.size() != dof ||
      (cap.size() != 0 && cap.size() != n))
    throw InputError("time_optimal_feed: inconsistent array sizes");
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::VectorXd x(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    double xm = cap.size() ? cap[k] * cap[k] : inf;
    for (Eigen::Index i = 0; i < dof; ++i) {
      const double p = std::abs(d1(k, i)), c = std::abs(d2(k, i));
      if (p > 0) xm = std::min(xm, (v[i] / p) * (v[i] / p));
      if (c > 0) xm = std::min(xm, a[i] / c);  // even s-ddot = 0 must keep q'' s-dot^2 within a
    }
    x[k] = xm;
  }
  auto bounds = [&](Eigen::Index k, double xk, double& lo, double& hi) {
    lo = -inf;
    hi = inf;
    for (Eigen::Index i = 0; i < dof; ++i) {
      const double p = d1(k, i), c = d2(k, i) * xk;
      if (std::abs(p) < 1e-12) continue;
      double l = (-a[i] - c) / p, h = (a[i] - c) / p;
      if (p < 0) std::swap(l, h);
      lo = std::max(lo, l);
      hi = std::min(hi, h);
    }
  };
  x[0] = 0;
  double lo, hi;
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    bounds(k, x[k], lo, hi);
    x[k + 1] = std::min(x[k + 1], std::max(0.0, x[k] + 2 * (s[k + 1] - s[k]) * hi));
  }
  x[n - 1] = 0;
  for (Eigen::Index k = n - 2; k >= 0; --k) {
    bounds(k + 1, x[k + 1], lo, hi);
    x[k] = std::min(x[k], std::max(0.0, x[k + 1] - 2 * (s[k + 1] - s[k]) * lo));
  }
  Eigen::VectorXd sd = x.cwiseMax(0.0).cwiseSqrt();
  time = 0;
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    const double avg = 0.5 * (sd[k] + sd[k + 1]);
    time += avg > 0 ? (s[k + 1] - s[k]) / avg : inf;
  }
  return sd;
}

}  // namespace kincal
