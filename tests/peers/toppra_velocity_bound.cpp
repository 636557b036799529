// The peer for eq. 21 of the Samak paper: toppra's own C++ joint-velocity constraint
// (toppra::constraint::LinearJointVelocity, double precision, from the cmeel-toppra wheel on PyPI)
// evaluated on a path given by its first derivative q'(s) at the grid points.
//
// stdin:  "dof n", then one line of dof symmetric velocity limits v (rad/s, bounds [-v, v]),
//         then n lines "s q'_1 .. q'_dof" (rad per unit s).
// stdout: n lines "x_lo x_hi": toppra's bounds on x = s-dot^2 at each grid point.
#include <toppra/constraint/linear_joint_velocity.hpp>
#include <toppra/geometric_path.hpp>

#include <cstdio>
#include <iostream>
#include <stdexcept>

namespace {

// A path known only by q'(s) at the grid points: toppra's velocity constraint needs nothing else.
class GivenDerivative : public toppra::GeometricPath {
 public:
  GivenDerivative(toppra::Vector s, toppra::Matrix d1)
      : toppra::GeometricPath(static_cast<int>(d1.cols())), s_(std::move(s)), d1_(std::move(d1)) {}

  toppra::Vector eval_single(toppra::value_type s, int order) const override {
    if (order != 1) throw std::invalid_argument("only the first derivative is given");
    for (Eigen::Index i = 0; i < s_.size(); ++i)
      if (s_[i] == s) return d1_.row(i).transpose();
    throw std::invalid_argument("not a grid point");
  }

  toppra::Bound pathInterval() const override {
    toppra::Bound b;
    b << s_[0], s_[s_.size() - 1];
    return b;
  }

 private:
  toppra::Vector s_;
  toppra::Matrix d1_;
};

}  // namespace

int main() {
  int dof = 0, n = 0;
  if (!(std::cin >> dof >> n) || dof < 1 || n < 2) {
    std::cerr << "toppra_velocity_bound: expected 'dof n' on the first line\n";
    return 1;
  }
  toppra::Vector v(dof), s(n);
  toppra::Matrix d1(n, dof);
  for (int k = 0; k < dof; ++k) std::cin >> v[k];
  for (int i = 0; i < n; ++i) {
    std::cin >> s[i];
    for (int k = 0; k < dof; ++k) std::cin >> d1(i, k);
  }
  if (!std::cin) {
    std::cerr << "toppra_velocity_bound: truncated input\n";
    return 1;
  }
  toppra::constraint::LinearJointVelocity constraint(-v, v);
  GivenDerivative path(s, d1);
  toppra::Vectors a, b, c, g;
  toppra::Matrices F;
  toppra::Bounds ubound, xbound;
  constraint.allocateParams(static_cast<std::size_t>(n), a, b, c, F, g, ubound, xbound);
  constraint.computeParams(path, s, a, b, c, F, g, ubound, xbound);
  for (int i = 0; i < n; ++i) std::printf("%.17g %.17g\n", xbound[i][0], xbound[i][1]);
  return 0;
}
