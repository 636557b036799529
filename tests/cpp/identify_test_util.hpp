// Shared helpers of the identification tests: the kr500 truth with manufacturing errors, where the
// instrument sees it from, and the three targets of its campaigns.
#pragma once

#include "kincal/model/robots.hpp"

#include "test_util.hpp"

#include <vector>

namespace kincal::test {

inline const std::vector<Vec3> kTargets = {Vec3(0, 0, 0), Vec3(120, 0, 30), Vec3(0, 150, -20)};

/// The truth of seed `seed` (KINCAL_TEST_SEED changes it: test_seed).
inline ModelSpec truth_spec(unsigned seed, double compliance) {
  return perturbed_spec(kr500_spec(), test_seed(seed), 1.0, 0.05, compliance);
}

/// Where the instrument stands in the truth's campaigns.
inline Campaign truth_campaign() {
  Campaign c;
  c.base_in_instrument.xyz = Vec3(3500, -1500, -400);
  c.base_in_instrument.abc = Vec3(35, 1.5, -0.8);
  return c;
}

}  // namespace kincal::test
