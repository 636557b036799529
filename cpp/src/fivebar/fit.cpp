// kincal: nonlinear least-squares fit of the hidden robot's four lengths with Ceres (beyond the
// paper's linear per-dyad synthesis: the distance between model and measured position itself).
#include "kincal/fivebar/fit.hpp"
#include "kincal/fivebar/fivebar.hpp"
#include "kincal/model/model.hpp"

#include <ceres/ceres.h>

#include <cmath>

namespace kincal {

namespace {

class PointCost : public ceres::SizedCostFunction<2, 4> {
 public:
  explicit PointCost(const FiveBarPoint& p) : p_(p) {}
  bool Evaluate(double const* const* x, double* r, double** jac) const override {
    const FiveBar m{x[0][0], x[0][1], x[0][2], x[0][3], +1, +1, -1};
    const double t1 = p_.t1_deg * kDeg, t2 = p_.t2_deg * kDeg;
    Vec2 c;
    if (!fivebar_fk(m, t1, t2, c)) return false;
    r[0] = c.x() - p_.measured.x();
    r[1] = c.y() - p_.measured.y();
    if (jac && jac[0]) {
      Eigen::Matrix<double, 2, 4> j;
      if (!fivebar_length_jacobian(m, t1, t2, j)) return false;
      Eigen::Map<Eigen::Matrix<double, 2, 4, Eigen::RowMajor>> out(jac[0]);
      out = j;
    }
    return true;
  }

 private:
  FiveBarPoint p_;
};

}  // namespace

FiveBar fivebar_fit_nonlinear(const std::vector<FiveBarPoint>& pts, const FiveBar& start, double* rms) {
  if (pts.size() < 2) throw InputError("nonlinear fit: at least 2 points for 4 lengths");
  double x[4] = {start.a, start.b, start.c, start.d};
  ceres::Problem problem;
  for (const auto& p : pts) problem.AddResidualBlock(new PointCost(p), nullptr, x);
  for (int k = 0; k < 4; ++k) problem.SetParameterLowerBound(x, k, 1e-3);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = 100;
  so.function_tolerance = 1e-14;
  so.parameter_tolerance = 1e-14;
  ceres::Solver::Summary sum;
  ceres::Solve(so, &problem, &sum);
  if (!sum.IsSolutionUsable()) throw InputError("nonlinear fit: Ceres failed (" + sum.BriefReport() + ")");
  if (rms) *rms = std::sqrt(2 * sum.final_cost / pts.size());
  return FiveBar{x[0], x[1], x[2], x[3], +1, +1, -1};
}

}  // namespace kincal
