// Shared helpers of the identification tests: the kr500 truth with manufacturing errors seen from
// the instrument, and the three targets of its campaigns.
#pragma once

#include "kincal/model/robots.hpp"

#include "test_util.hpp"

#include <vector>

namespace kincal::test {

inline const std::vector<Vec3> kTargets = {Vec3(0, 0, 0), Vec3(120, 0, 30), Vec3(0, 150, -20)};

/// The truth of seed `seed` (KINCAL_TEST_SEED changes it: test_seed).
inline ModelSpec truth_spec(unsigned seed, double compliance) {
  ModelSpec s = perturbed_spec(kr500_spec(), test_seed(seed), 1.0, 0.05, compliance);
  s.base_in_instrument.xyz = Vec3(3500, -1500, -400);
  s.base_in_instrument.abc = Vec3(35, 1.5, -0.8);
  return s;
}

}  // namespace kincal::test
