// kincal: the rotation-group helpers of the identification (inline, allocation-free): the skew
// matrix, exponential and logarithm of SO(3) and its right Jacobian with the inverse. The tool and
// base rotations are parametrised as R = R0 Exp(phi); orientation residuals are log(Rm^T R).
#pragma once

#include "kincal/core/types.hpp"

#include <cmath>

namespace kincal::so3 {

/// The matrix of v x (the cross product by v).
inline Mat3 skew(const Vec3& v) {
  Mat3 s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

/// The rotation by the rotation vector phi.
inline Mat3 exp(const Vec3& phi) {
  const double th = phi.norm();
  if (th < 1e-300) return Mat3::Identity();
  return Eigen::AngleAxisd(th, phi / th).toRotationMatrix();
}

/// The rotation vector of r.
inline Vec3 log(const Mat3& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

/// Right Jacobian of SO(3): Exp(phi + d) = Exp(phi) Exp(Jr(phi) d) to first order.
inline Mat3 right_jacobian(const Vec3& phi) {
  const double th = phi.norm();
  const Mat3 s = skew(phi);
  double a, b;
  if (th < 1e-4) {
    a = 0.5 - th * th / 24.0;
    b = 1.0 / 6.0 - th * th / 120.0;
  } else {
    a = (1.0 - std::cos(th)) / (th * th);
    b = (th - std::sin(th)) / (th * th * th);
  }
  return Mat3::Identity() - a * s + b * s * s;
}

/// Inverse of the right Jacobian of SO(3).
inline Mat3 right_jacobian_inv(const Vec3& e) {
  const double th = e.norm();
  const Mat3 s = skew(e);
  const double c = th < 1e-4 ? 1.0 / 12.0 + th * th / 720.0
                             : 1.0 / (th * th) - (1.0 + std::cos(th)) / (2.0 * th * std::sin(th));
  return Mat3::Identity() + 0.5 * s + c * s * s;
}

}  // namespace kincal::so3
