// kincal: measurement campaigns simulated on a true model (every effect it carries acting, noise,
// outliers, 6-D poses) and the errors of a model's predictions against measured rows. Every effect
// of the truth acts in one place, simulate_point().
#pragma once

#include "kincal/identify/stations.hpp"
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
  /// >= 0: the first target's rows are 6-D poses (the tool frame moved by that target's offset, its
  /// orientation measured too, with this noise per axis); the other targets' rows stay points
  /// (reflectors among the 6-D rows)
  double orientation_noise_deg = -1;
  /// > 0: every row gets time_s, the campaign running from 0 to duration_s in pose order (a hidden
  /// drift without it: 3 h). A drift hidden in a truth that has none is centred on the mean time.
  double duration_s = 0;
};

/// A probe campaign (measurements without a tracker, measurements.hpp's kinds) on a truth.
struct ProbeSimulationOptions {
  MeasureKind kind = MeasureKind::sphere;
  /// spheres or ballbar pivots placed in reach; planes: faces of one block in front of the robot (at
  /// most 5: top, the face towards the robot, the two sideways, the surface plate it stands on)
  int stations = 3;
  int touches = 25;            ///< rows per station
  double cone_deg = 35;        ///< the probe's axis within this angle of its station's mean direction
  Vec3 probe = Vec3::Zero();   ///< the ball centre in the tool frame (mm)
  double radius_mm = 3;        ///< plane: the ball's radius
  double length_mm = 150;      ///< distance: the ballbar's length
  double block_mm = 120;       ///< plane: the block's edge; touches spread over 70% of each face
  double noise_mm = 0.005;     ///< along the constraint (distance: of the ballbar's length)
  double limit_margin = 0.8;   ///< stations placed from poses in this share of every joint's range
  unsigned seed = 1;
  /// the artifact written with the rows: spheres and pivots, the distance of every station from the
  /// first; planes, the 90 deg angles between the top face and the others and the block's edge
  /// between opposite faces
  bool artifact = true;
};

/// A probe campaign on the truth (its effects acting at each row's context): each row's commanded
/// angles put the truth's ball centre on its constraint, with the noise along it; stations in the
/// instrument frame of the truth's base_in_instrument. InputError when a station cannot be reached.
MeasurementSet simulate_probe(const Model& truth, const ProbeSimulationOptions& opt);

/// The campaign's length a hidden drift gets when SimulationOptions::duration_s is not set (3 h).
constexpr double kDefaultDriftDuration_s = 3 * 3600.0;

/// The base frame seen from the instrument for each setup of a measurement set (by code): the
/// campaign's setup of the same name, or its base_in_instrument when it has no setups (then the
/// set may have at most one). InputError naming the setup the campaign does not know.
std::vector<Eigen::Isometry3d> setup_frames(const Campaign& campaign, const MeasurementSet& data);
/// A placement at the time a row was measured: frame moved by the campaign's drift (effects.hpp's
/// definition: rotation Exp(tau w) R, translation t + tau v, tau in hours from its t_mean_s); the
/// frame itself without a drift. InputError when the instrument drifts and the time is unknown (NaN).
Eigen::Isometry3d drifted(const Campaign& campaign, const Eigen::Isometry3d& frame, double time_s);

/// The point of target t (tool frame) in the instrument frame for the row's commanded joint angles
/// on a model, every effect it carries acting (the row's dir and temperature), seen from the
/// campaign's placement, without noise.
Vec3 simulate_point(const Model& truth, const Campaign& campaign, const Measurement& row, const Vec3& target);
/// The same seen from the placement `base` (a setup's frame), the campaign's drift acting.
Vec3 simulate_point(const Model& truth, const Campaign& campaign, const Measurement& row, const Vec3& target,
                    const Eigen::Isometry3d& base);
/// A campaign on the truth seen from `campaign`'s placement (by default the base frame itself): its
/// own effects and opt.effects (hidden; a hidden drift drifts the instrument) act.
MeasurementSet simulate(const Model& truth, const SimulationOptions& opt, const Campaign& campaign = Campaign{});
/// The truth's spec with the hidden robot effects of opt added (t_ref from opt when the truth has
/// none); a drift among them is left to the campaign.
ModelSpec with_effects(const ModelSpec& truth, const std::vector<EffectValue>& effects, double t_ref);

/// Position errors (mm) of every row of data predicted by a model (every effect it carries acting,
/// each row seen from its setup's placement, the campaign's drift at the row's time) with the given
/// targets.
std::vector<double> point_errors(const Model& model, const Campaign& campaign, const std::vector<Vec3>& targets,
                                 const MeasurementSet& data);
/// The same with probe rows: their error along the constraint against their station among `stations`
/// (stations.hpp; NaN for a station not among them).
std::vector<double> point_errors(const Model& model, const Campaign& campaign, const std::vector<Vec3>& targets,
                                 const MeasurementSet& data, const std::vector<StationValue>& stations);
/// Orientation errors (deg) of every 6-D row of a set, in order (rows without a measured orientation
/// are left out): the angle between the measured tool frame and the model's (every effect acting,
/// seen from the row's placement at its time).
std::vector<double> orientation_errors(const Model& model, const Campaign& campaign, const MeasurementSet& data);

}  // namespace kincal
