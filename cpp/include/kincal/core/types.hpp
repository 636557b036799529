// kincal: the types every part shares: fixed-size vectors, frames as position + KUKA ABC angles,
// degree/radian constants and the error raised for bad input.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "kincal/core/fastmath.hpp"

namespace kincal {

constexpr int kMaxJoints = 12;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using VecQ = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJoints, 1>;
using MatQ = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJoints, kMaxJoints>;
using Jac = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxJoints>;
/// A row-major dynamic matrix: the layout of numpy arrays and of row-per-sample tables.
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

/// A frame given as position (mm) and KUKA ABC angles (deg): R = Rz(a) Ry(b) Rx(c).
struct Pose6 {
  Vec3 xyz = Vec3::Zero();
  Vec3 abc = Vec3::Zero();
};

/// Rotation of KUKA ABC angles in degrees.
Mat3 abc_to_rotation(const Vec3& abc_deg);
/// ABC angles in degrees of a rotation (b in [-90, 90]).
Vec3 rotation_to_abc(const Mat3& r);
/// The same in radians, inlined for the hot paths (at gimbal lock everything goes into a).
/// cos b below which ABC angles are at their pole (b = +-90 deg): rotation_to_abc_rad takes c = 0
/// there, and an ABC residual's rates are singular (compensation says so).
constexpr double kAbcPoleCos = 3e-8;

inline Vec3 rotation_to_abc_rad(const Mat3& r) {
  // the entries of a rotation are at most 1: a plain square root is safe (and much faster than hypot)
  const double cb = std::sqrt(r(0, 0) * r(0, 0) + r(1, 0) * r(1, 0));
  const double b = fastmath::atan2(-r(2, 0), cb);
  // Near the pole (b = +-90 deg) a and c come from entries of size cos b that carry the rounding of
  // the matrix (~1e-15 after a kinematic chain): an error of 1e-15 / cos b each. Below cos b = 3e-8
  // c is set to 0 and a taken from the second column, which cos b does not scale: an error of about
  // cos b. Both stay below 3e-8 rad (2e-6 deg).
  if (cb < kAbcPoleCos) return Vec3(fastmath::atan2(-r(0, 1), r(1, 1)), b, 0.0);
  return Vec3(fastmath::atan2(r(1, 0), r(0, 0)), b, fastmath::atan2(r(2, 1), r(2, 2)));
}
Eigen::Isometry3d pose_to_iso(const Pose6& p);
Pose6 iso_to_pose(const Eigen::Isometry3d& t);

/// Error raised for bad input: the message names the source (file:line) and the cause.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace kincal
