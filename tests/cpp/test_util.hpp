// Shared helpers of the C++ tests: seeded random configurations, the test count CI can raise.
#pragma once

#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/model.hpp"
#include "kincal/model/robots.hpp"

#include <cstdlib>
#include <random>

namespace kincal::test {

/// Number of random cases: KINCAL_TEST_COUNT overrides the default.
inline int count(int dflt) {
  const char* e = std::getenv("KINCAL_TEST_COUNT");
  return e ? std::max(1, std::atoi(e)) : dflt;
}

inline Vec6 random_q(const Model& m, std::mt19937_64& rng, double margin_deg = 0) {
  Vec6 q;
  for (int j = 0; j < 6; ++j) {
    const auto& js = m.spec().joints[j];
    q[j] = std::uniform_real_distribution<double>(js.lower_deg + margin_deg, js.upper_deg - margin_deg)(rng);
  }
  return q;
}

/// Angle of the rotation between two rotation matrices (rad).
inline double rot_dist(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

/// The kr500's distance (deg) from its singularities: wrist (q5 = 0), elbow (arm stretched),
/// shoulder (wrist centre on axis 1, measured as the angle it subtends at 1300 mm).
inline double singularity_distance_deg(const Model& m, const Vec6& q) {
  const double elbow = std::atan2(55.0, 1025.0) / kDeg;  // q3 where axes 2, 3 and the wrist centre line up
  VecQ qq = q * kDeg;
  qq[3] = qq[4] = qq[5] = 0;
  const Vec3 wc = fk(m, qq) * (m.tool().inverse() * IkSolver(m).structure().wrist_center);
  const double shoulder = std::asin(std::min(1.0, std::hypot(wc[0], wc[1]) / 1300.0)) / kDeg;
  return std::min({std::abs(q[4]), std::abs(q[2] - elbow), shoulder});
}

}  // namespace kincal::test
