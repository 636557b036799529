// transmission_error (serial, per joint): dq_j = sum_k s_k sin(k q_j) + c_k cos(k q_j), the harmonic
// orders k an option (default 1 and 2); amplitudes in deg (rad in the core).
#include "harmonic.hpp"
#include "kincal/effects/effects.hpp"
#include "kincal/model/model.hpp"

#include <algorithm>

namespace kincal {

namespace {

void check(const Effect& e, const std::string& who) {
  if (e.harmonics.empty()) throw InputError(who + "transmission_error needs at least one harmonic order");
  for (size_t i = 0; i < e.harmonics.size(); ++i) {
    if (e.harmonics[i] < 1 || e.harmonics[i] > 64)
      throw InputError(who + "transmission_error: harmonic order " + std::to_string(e.harmonics[i]) +
                       " is not one of 1..64");
    if (std::count(e.harmonics.begin(), e.harmonics.end(), e.harmonics[i]) > 1)
      throw InputError(who + "transmission_error: harmonic order " + std::to_string(e.harmonics[i]) + " twice");
  }
}

}  // namespace

const EffectKind& transmission_error_kind() {
  static const EffectKind k{
      EffectId::transmission_error, "transmission_error", "serial", "joint", "", "joint_angle",
      "errors periodic in the joint angle: sine and cosine amplitudes of each harmonic order (deg)", false, true, 0,
      [](const Effect& e) { return harmonic::names("te_", e.harmonics); }, harmonic::units, check,
      [](const Effect& e, double q, double, double* b, double* db) { harmonic::basis(e.harmonics, q, b, db); }};
  return k;
}

}  // namespace kincal
