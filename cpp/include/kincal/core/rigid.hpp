// kincal: the rigid transform that best maps one point set onto another (Horn / Kabsch).
#pragma once

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace kincal {

/// The rotation R and translation t minimising sum |R a_k + t - b_k|^2 over the columns of a and b
/// (the same count), a proper rotation (det +1). Points that do not span a plane (fewer than three,
/// or all on a line) leave the rotation undetermined: then R = I and t = mean(b) - mean(a). The one
/// home of this fit: the identification's start of each instrument placement and the TCP placed
/// from known target offsets (bound as kincal._core.rigid_fit).
inline Eigen::Isometry3d rigid_fit(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  if (a.cols() == 0 || a.cols() != b.cols()) return out;
  const Eigen::Vector3d ca = a.rowwise().mean(), cb = b.rowwise().mean();
  const Eigen::Matrix3Xd da = a.colwise() - ca;
  Eigen::JacobiSVD<Eigen::Matrix3Xd> spread(da);
  const auto s = spread.singularValues();
  if (a.cols() < 3 || !(s[1] > 1e-6 * std::max(1.0, s[0]))) {  // on a line: a translation only
    out.translation() = cb - ca;
    return out;
  }
  const Eigen::Matrix3d h = da * (b.colwise() - cb).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  out.linear() = svd.matrixV() * d * svd.matrixU().transpose();
  out.translation() = cb - out.linear() * ca;
  return out;
}

}  // namespace kincal
