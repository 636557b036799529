// thermal_expansion (serial, the whole robot): every length of the robot scales by 1 + alpha (T -
// t_ref), the tool point in the base frame about the base origin; alpha in 1/degC.
#include "kincal/effects/effects.hpp"

namespace kincal {

const EffectKind& thermal_expansion_kind() {
  static const EffectKind k{EffectId::thermal_expansion, "thermal_expansion", "serial", "robot", "temperature_c",
                            "length_scale", "the robot's lengths scale by 1 + alpha (T - t_ref) (alpha per deg C)",
                            false, false, 1, [](const Effect&) { return std::vector<std::string>{"thermal_expansion"}; },
                            [](const Effect&) { return std::vector<std::string>{"1/degC"}; }, nullptr, nullptr};
  return k;
}

}  // namespace kincal
