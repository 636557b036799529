// kincal: the campaign's checks (model/campaign.hpp).
#include "kincal/model/campaign.hpp"

#include <cmath>

#include "kincal/model/coverage.hpp"

namespace kincal {

namespace {

bool finite(const Vec3& v) { return v.allFinite(); }

}  // namespace

void Campaign::check(int dof, const std::string& who) const {
  if (!finite(base_in_instrument.xyz) || !finite(base_in_instrument.abc))
    throw InputError(who + "the instrument's placement (base_in_instrument) has a NaN or infinite value");
  for (size_t i = 0; i < setups.size(); ++i) {
    const SetupFrame& f = setups[i];
    if (f.name.empty()) throw InputError(who + "setup " + std::to_string(i + 1) + " has no name");
    if (!finite(f.base_in_instrument.xyz) || !finite(f.base_in_instrument.abc))
      throw InputError(who + "setup '" + f.name + "': a value is NaN or infinite");
    for (size_t k = 0; k < i; ++k)
      if (setups[k].name == f.name) throw InputError(who + "setup '" + f.name + "' is given twice");
  }
  if (!std::isfinite(t_mean_s)) throw InputError(who + "the drift's reference time is NaN or infinite");
  if (drift) {
    if (!drift->effect.kind().of_instrument())
      throw InputError(who + drift->effect.label() + " is the robot's, not the instrument's drift");
    check_effect(drift->effect, dof, who);
    if (static_cast<int>(drift->p.size()) != drift->effect.size())
      throw InputError(who + drift->effect.label() + ": " + std::to_string(drift->p.size()) + " values for " +
                       std::to_string(drift->effect.size()) + " parameters");
    for (double v : drift->p)
      if (!std::isfinite(v)) throw InputError(who + drift->effect.label() + ": a value is NaN or infinite");
  }
  if (!fitted_deg.empty()) check_joint_ranges(fitted_deg, dof, who + "fitted joint ranges");
}

Eigen::Isometry3d Campaign::base() const { return pose_to_iso(base_in_instrument); }

}  // namespace kincal
