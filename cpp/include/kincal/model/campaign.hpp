// kincal: what one measurement campaign adds to the robot's model (architecture: the robot model,
// the campaign and the workspace kept apart): where the instrument stood (one placement, or one per
// named setup), the instrument's drift about the campaign's mean time, and the joint angles the
// identification saw. Never applied by FK or compensation; carried beside the calibrated model (its
// file's "campaign" section) for predicting measured points, for programs written in the
// instrument's frame and for the warnings on angles outside what was fitted.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "kincal/core/types.hpp"
#include "kincal/effects/effects.hpp"

namespace kincal {

/// One instrument placement of a campaign measured from several (the `setup` column): its name
/// and the robot base frame seen from the instrument there.
struct SetupFrame {
  std::string name;
  Pose6 base_in_instrument;
};

/// A joint's fitted range of angles (deg): [lo, hi], lo in [-180, 180), hi - lo its arc (coverage.hpp)
using JointRange = std::array<double, 2>;

/// The campaign's side of a calibrated model; plain data, checked by check().
struct Campaign {
  Pose6 base_in_instrument;        ///< robot base frame seen from the instrument (the first setup's)
  /// every placement by name when the campaign has several setups (empty for one: base_in_instrument)
  std::vector<SetupFrame> setups;
  /// the instrument's drift (the registry's drift effect: translation mm/h and rotation rad/h about
  /// t_mean_s, instrument frame), none without one
  std::optional<EffectValue> drift;
  double t_mean_s = 0;             ///< the drift's reference time (s, the campaign's mean time)
  /// Per joint, the angles the identification saw (coverage.hpp); empty when unknown (a nominal
  /// model, a model written before they were recorded)
  std::vector<JointRange> fitted_deg;

  /// InputError (with `who` in front) for a value that is NaN or infinite, a setup without a name or
  /// named twice, a drift that is no drift or has the wrong number of values, fitted ranges that are
  /// not one valid [lo, hi] per joint of a robot of dof joints.
  void check(int dof, const std::string& who) const;
  Eigen::Isometry3d base() const;
};

}  // namespace kincal
