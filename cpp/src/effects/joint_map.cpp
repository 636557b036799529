// joint_map (serial, per joint): a smooth periodic error of the joint angle of any order K,
// dq_j = sum_{k=1..K} s_k sin(k q_j) + c_k cos(k q_j) (harmonics = 1..K); amplitudes in deg.
#include "harmonic.hpp"
#include "kincal/effects/effects.hpp"
#include "kincal/model/model.hpp"

namespace kincal {

namespace {

void check(const Effect& e, const std::string& who) {
  const int k = static_cast<int>(e.harmonics.size());
  if (k < 1 || k > 64) throw InputError(who + "joint_map: the order must be 1..64, not " + std::to_string(k));
  for (int i = 0; i < k; ++i)
    if (e.harmonics[i] != i + 1)
      throw InputError(who + "joint_map carries every harmonic order 1..K (its order K), not an order " +
                       std::to_string(e.harmonics[i]) + " at place " + std::to_string(i + 1));
}

}  // namespace

const EffectKind& joint_map_kind() {
  static const EffectKind k{
      EffectId::joint_map, "joint_map", "serial", "joint", "", "joint_angle",
      "a smooth periodic error of the joint angle of any order K: sine and cosine amplitudes of orders 1..K (deg)",
      false, true, 0, [](const Effect& e) { return harmonic::names("map_", e.harmonics); }, harmonic::units, check,
      [](const Effect& e, double q, double, double* b, double* db) { harmonic::basis(e.harmonics, q, b, db); },
      true};
  return k;
}

Effect joint_map(int joint, int order) {
  Effect e{"joint_map", joint, {}};
  for (int k = 1; k <= order; ++k) e.harmonics.push_back(k);
  return e;
}

}  // namespace kincal
