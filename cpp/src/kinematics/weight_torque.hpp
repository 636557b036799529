// The gravity torque's rule, in one place for the deflected FK (kinematics.cpp) and the
// identification's Jacobian of compliance (identify/point_model_gravity.cpp).
#pragma once

#include <array>

#include "kincal/core/types.hpp"

namespace kincal::detail {

/// What each joint carries, from the tip: on entry S[k] and M[k] are link k's own first moment
/// (m_k c_k about the base origin, kg mm) and mass (kg) for k < n, and S[n], M[n] the payload's
/// (zero without one); on return they are the sums over links k..n.
template <std::size_t N>
inline void carried_loads(int n, std::array<Vec3, N>& S, std::array<double, N>& M) {
  for (int k = n - 1; k >= 0; --k) {
    S[k] += S[k + 1];
    M[k] += M[k + 1];
  }
}

/// The torque (N mm) of the weight a joint carries about its axis z (unit, base frame) through o:
/// arm = S - M o, tau = z . (arm x g), g in m/s^2. `arm` is returned for the derivatives.
inline double weight_torque(const Vec3& z, const Vec3& o, const Vec3& S, double M, const Vec3& g, Vec3& arm) {
  arm = S - M * o;
  return z.dot(arm.cross(g));
}

}  // namespace kincal::detail
