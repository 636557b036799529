#include "kincal/core/types.hpp"

namespace kincal {

Mat3 abc_to_rotation(const Vec3& abc) {
  // Rz(a) Ry(b) Rx(c) written out
  double sa, ca, sb, cb, sc, cc;
  fastmath::sincos2(abc[0] * kDeg, abc[1] * kDeg, sa, ca, sb, cb);
  fastmath::sincos(abc[2] * kDeg, sc, cc);
  Mat3 r;
  r << ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc,  //
      sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc,    //
      -sb, cb * sc, cb * cc;
  return r;
}

Vec3 rotation_to_abc(const Mat3& r) { return rotation_to_abc_rad(r) / kDeg; }

Eigen::Isometry3d pose_to_iso(const Pose6& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = abc_to_rotation(p.abc);
  t.translation() = p.xyz;
  return t;
}

Pose6 iso_to_pose(const Eigen::Isometry3d& t) { return Pose6{t.translation(), rotation_to_abc(t.linear())}; }

}  // namespace kincal
