// Shared helpers of the C++ tests: seeded random configurations, the test count CI can raise and the
// seed it can change.
#pragma once

#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/model.hpp"
#include "kincal/model/robots.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <random>
#include <stdexcept>
#include <string>

namespace kincal::test {

/// The InputError message f throws, or "(no error)".
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

/// Number of random cases: KINCAL_TEST_COUNT overrides the default.
inline int count(int dflt) {
  const char* e = std::getenv("KINCAL_TEST_COUNT");
  return e ? std::max(1, std::atoi(e)) : dflt;
}

/// KINCAL_TEST_SEED as an unsigned integer, or false when it is not set; a value that is not one (empty,
/// a sign, letters, beyond 2^64 - 1) throws std::invalid_argument naming the variable.
inline bool seed_override(std::uint64_t& value) {
  const char* e = std::getenv("KINCAL_TEST_SEED");
  if (!e) return false;
  const std::string s(e);
  const bool digits = !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
  errno = 0;
  value = digits ? std::strtoull(s.c_str(), nullptr, 10) : 0;
  if (!digits || errno == ERANGE)
    throw std::invalid_argument("KINCAL_TEST_SEED='" + s + "' is not an unsigned integer (0 .. 2^64 - 1)");
  return true;
}

/// The seed of a randomized test whose default seed is dflt: dflt itself, or with KINCAL_TEST_SEED=S set,
/// a seed drawn from S and dflt (splitmix64 of both), so that one variable changes every test's seed while
/// the different streams of one test (a fit and a held-out campaign, the truth and its poses) stay
/// different. Deterministic: the same S gives the same seeds.
inline unsigned test_seed(unsigned dflt) {
  std::uint64_t s;
  if (!seed_override(s)) return dflt;
  std::uint64_t z = s * 0x9E3779B97F4A7C15ull + dflt + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return static_cast<unsigned>((z ^ (z >> 31)) & 0xFFFFFFFFu);
}

/// What a failure prints of a test's seeds (SCOPED_TRACE): the seeds used, their defaults and the
/// KINCAL_TEST_SEED that reproduces them.
inline std::string seed_note(std::initializer_list<unsigned> defaults) {
  std::uint64_t s;
  const bool set = seed_override(s);
  std::string used, dflt;
  for (unsigned d : defaults) {
    used += (used.empty() ? "" : ", ") + std::to_string(test_seed(d));
    dflt += (dflt.empty() ? "" : ", ") + std::to_string(d);
  }
  return "seed(s) " + used + (set ? " from the default(s) " + dflt + " with KINCAL_TEST_SEED=" + std::to_string(s)
                                  : " (the defaults: KINCAL_TEST_SEED unset)");
}

// A kr500 with 1 mm / 0.05 deg geometric errors (seed), joint compliance (0.003 deg/kN m), and a
// transmission error (harmonics 1, 2) and a backlash on joints 1-3: the compensation benchmark's
// model with every effect.
inline ModelSpec every_effect_spec(unsigned seed) {
  ModelSpec spec = perturbed_spec(kr500_spec(), seed, 1.0, 0.05, 0.003);
  for (int j = 0; j < 3; ++j) {
    spec.effects.push_back({Effect{"transmission_error", j, {1, 2}}, {2e-4, -1e-4, 5e-5, 8e-5}});
    spec.effects.push_back({Effect{"backlash", j, {}}, {-2e-4}});
  }
  return spec;
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

/// A robot's joints from their axis points and directions (mm, any length), limits +-360 deg unless given.
inline void add_joints(ModelSpec& s, const Vec3* points, const Vec3* axes, const double* lower_deg = nullptr,
                       const double* upper_deg = nullptr) {
  for (int j = 0; j < 6; ++j) {
    JointSpec js;
    js.point = points[j];
    js.axis = axes[j];
    js.lower_deg = lower_deg ? lower_deg[j] : -360;
    js.upper_deg = upper_deg ? upper_deg[j] : 360;
    s.joints.push_back(js);
  }
}

/// Whether an IK's solutions lie within `deg` of a singularity: the wrist's (|sin q5| small, axes 4
/// and 6 aligned in a wrist with the flip), the shoulder's or the elbow's (two solutions of q1, or of
/// q3 for one q1, that close), where each closed form's rounding is magnified.
inline bool near_singular(const IkSolutions& s, double deg) {
  bool near = s.count == 0;
  for (int i = 0; i < s.count; ++i) {
    near = near || std::abs(std::sin(s.sol[i].q_deg[4] * kDeg)) < std::sin(deg * kDeg);
    for (int k = 0; k < i; ++k) {
      const double d1 = std::abs(std::remainder(s.sol[i].q_deg[0] - s.sol[k].q_deg[0], 360.0));
      const double d3 = std::abs(std::remainder(s.sol[i].q_deg[2] - s.sol[k].q_deg[2], 360.0));
      near = near || (d1 > 1e-6 && d1 < deg) || (d1 <= 1e-6 && d3 > 1e-6 && d3 < deg);
    }
  }
  return near;
}

}  // namespace kincal::test

/// Prints the test's seeds with a failure: KINCAL_SEED_TRACE(31) or KINCAL_SEED_TRACE(21, 3, 4).
#define KINCAL_SEED_TRACE(...) SCOPED_TRACE(::kincal::test::seed_note({__VA_ARGS__}))
