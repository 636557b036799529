// kincal: the time-optimal rate of the path parameter s along a joint path (derivative analysis).
#pragma once

#include "kincal/core/types.hpp"

namespace kincal {


/// Time-optimal s-dot(s) from rest to rest on the grid s (n), with the path derivatives d1 = q'(s),
/// d2 = q''(s) (n x dof), under |q'_i s-dot| <= v_i, |q'_i s-ddot + q''_i s-dot^2| <= a_i and
/// s-dot <= cap(s): forward-backward integration of x = s-dot^2. Returns s-dot; time = traversal time.
Eigen::VectorXd time_optimal_feed(const Eigen::VectorXd& s, const RowMatrix& d1, const RowMatrix& d2, const Eigen::VectorXd& v,
                                  const Eigen::VectorXd& a, const Eigen::VectorXd& cap, double& time);

}  // namespace kincal
