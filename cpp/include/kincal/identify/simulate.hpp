// kincal: measurement campaigns simulated on a true model (every effect it carries acting, noise,
// outliers, 6-D poses) and the errors of a model's predictions against measured rows. Every effect
// of the truth acts in one place, simulate_point().
#pragma once

#include "kincal/io/measurements.hpp"
#include "kincal/model/model.hpp"

#include <vector>

namespace kincal {

/// Simulator settings. Every effect of the truth is in simulate_point() (simulate.cpp's one place).
struct SimulationOptions {
  int poses = 150;
  unsigned seed = 1;
  double noise_mm = 0.02;          ///< isotropic Gaussian instrument noise, per coordinate
  double outlier_fraction = 0.0;   ///< share of rows with a gross error
  double outlier_mm = 5.0;         ///< size of a gross error
  std::vector<Vec3> targets = {Vec3::Zero()};  ///< target offsets in the tool frame (mm)
  double limit_margin = 0.9;       ///< poses drawn in this share of every joint's range
  std::vector<EffectValue> effects;  ///< effects hidden in the truth (besides its compliance)
  double t_ref = 20.0;             ///< reference temperature of thermal_expansion
  double t_min = 18.0, t_max = 30.0;  ///< the temperature drifts through this range over the campaign
  double orientation_noise_deg = -1;  ///< >= 0: the tool frame's orientation is measured too (6-D)
};

/// The point of target t (tool frame) in the instrument frame for the row's commanded joint angles
/// on a model, every effect it carries acting (the row's dir and temperature), without noise.
Vec3 simulate_point(const Model& truth, const Measurement& row, const Vec3& target);
/// A campaign on the truth: its own effects and opt.effects (hidden) act.
MeasurementSet simulate(const Model& truth, const SimulationOptions& opt);
/// The truth's spec with the hidden effects of opt added (t_ref from opt when the truth has none).
ModelSpec with_effects(const ModelSpec& truth, const std::vector<EffectValue>& effects, double t_ref);

/// Position errors (mm) of every row of data predicted by a model (every effect it carries acting)
/// with the given targets.
std::vector<double> point_errors(const Model& model, const std::vector<Vec3>& targets, const MeasurementSet& data);

}  // namespace kincal
