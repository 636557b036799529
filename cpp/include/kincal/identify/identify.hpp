// kincal: parameter identification (step 3 of the Samak paper): its options, its result and
// identify(), Ceres Levenberg-Marquardt on the measurement model of point_model.hpp with its analytic
// Jacobian. First the base frame of every setup, the targets and an instrument drift are fitted on
// the nominal geometry (the "before"),
// then parameters the data cannot determine are found from the scaled Jacobian (identifiability.hpp:
// greedy column selection in a preferred order) and held at their start value, then everything
// else is identified together; standard deviations and correlations from the Ceres covariance.
#pragma once

#include "kincal/identify/point_model.hpp"
#include "kincal/io/measurements.hpp"
#include "kincal/model/model.hpp"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace kincal {

/// The default prior standard deviations: what a robot maker's tolerances justify for the joint
/// geometry (1 mm, 0.1 deg) and the tool (5 mm, 1 deg); none (wide) for the compliances (their size
/// per kN m differs by a factor of 100 between a 10 kg and a 500 kg robot: a prior tight enough to
/// matter on one is wrong on the other; on the UR10 data a 0.01 deg/kNm prior cost 6% held out), the
/// base frames, the targets and the extra effects.
std::vector<std::pair<std::string, double>> default_prior_sd();

struct IdentifyOptions {
  bool compliance = true;          ///< identify the joint compliances
  GravityTorques gravity = GravityTorques::automatic;  ///< their torques
  Loss loss = Loss::huber;         ///< the robust loss
  /// where the robust loss bends on a row's residual norm (mm); 0: from the data (after a
  /// least-squares start, from the residuals' robust spread, re-estimated once after the robust fit)
  double loss_scale_mm = 0.1;
  /// Priors (maximum a posteriori) by kind: every parameter of a kind named here gets a Gaussian
  /// prior centred on its start value with this standard deviation (core units) times prior_scale.
  /// Kinds: joint_mm and joint_rad (the joint lines' moves and tilts), compliance (deg/kNm),
  /// tool_mm, tool_rad, base_mm, base_rad, target_mm, and an effect's name (each of its
  /// parameters). Kinds not named have no prior. prior_scale 0: no priors.
  std::vector<std::pair<std::string, double>> prior_sd = default_prior_sd();
  double prior_scale = 0;
  int max_iterations = 100;
  double rank_tolerance = 1e-4;    ///< a unit column closer than this to the others' span: redundant
  double min_torque_share = 0.05;  ///< compliance of a joint with less gravity torque than this share is held
  double weak_tolerance = 2e-3;    ///< closer than this: so weakly seen that it is held too
  double correlation_threshold = 0.95;
  bool covariance = true;          ///< parameter standard deviations and correlations (Ceres covariance)
  std::vector<std::string> fix;    ///< parameter names to hold in any case
  std::vector<int> compliance_joints;  ///< with compliance: only these joints (0-based; empty: all)
  std::vector<Effect> effects;     ///< extra effects identified with the rest
  /// ridge penalties (parameter name, weight in mm per unit of the parameter): the residual
  /// weight * value pulls that parameter towards zero (e.g. a joint_map's smoothness penalty, order k
  /// weighted k, so that a map the data see only over part of a turn stays smooth); the
  /// identifiability analysis leaves penalised parameters out (free, the ridge determines them)
  std::vector<std::pair<std::string, double>> penalties;
  /// where each target's offset on the tool starts (mm, tool frame; empty: at the tool frame's
  /// origin, then fitted to the data on the nominal geometry): a probe's nominal ball offset, without
  /// which a ballbar's pivots may start on the wrong side of their balls
  std::vector<Vec3> target_start;
  /// the instrument's (or probe's) noise per coordinate (mm), when known: it weighs the priors and
  /// sets the robust loss's bend in place of the estimate from the residuals (0: estimated)
  double noise_mm = 0;
  /// the artifact's uncertainty (mm; an angle's on a 1 m lever): its known lengths and angles weigh
  /// noise / artifact_sd against the rows (0: each as one coordinate of a row, as a probe reading)
  double artifact_sd_mm = 0;
  std::function<void(int iteration, double cost)> progress;
  double orientation_weight = 100.0;  ///< mm per rad: how orientation residuals weigh against positions
};

struct IdentifyResult {
  explicit IdentifyResult(ParamLayout l) : layout(std::move(l)) {}
  ParamLayout layout;
  std::vector<double> start, x, stddev;   ///< stddev NaN for fixed parameters
  std::vector<double> nominal_x;          ///< nominal geometry with the fitted base frame and targets
  double nominal_rms_mm = 0, nominal_max_mm = 0;  ///< on the fitted rows, nominal geometry
  ModelSpec nominal_fitted;               ///< nominal geometry (fitted with the frames alone)
  Campaign nominal_campaign;              ///< its fitted placements (and drift)
  std::vector<Vec3> nominal_targets;      ///< targets fitted with the nominal geometry
  std::vector<StationValue> nominal_stations;  ///< the probe stations fitted with the nominal geometry
  std::vector<bool> fixed;                ///< held at its start value
  /// free, but determined by its prior rather than by the data (these poses leave it redundant or
  /// barely seen where a generic campaign would determine it)
  std::vector<bool> at_prior;
  std::vector<double> prior_sd;           ///< the prior's standard deviation (scaled; inf: none)
  double noise_mm = 0;
  /// the artifact's uncertainty (mm; an angle's on a 1 m lever): its known lengths and angles weigh
  /// noise / artifact_sd against the rows (0: each as one coordinate of a row, as a probe reading)
  double artifact_sd_mm = 0;                    ///< the residuals' robust spread per coordinate (0: not estimated)
  double loss_scale_mm = 0;               ///< the robust loss's scale used in the final fit (0: no robust loss)
  std::vector<std::string> fixed_reason;  ///< why it is held ("" when free)
  ModelSpec calibrated;
  Campaign campaign;                      ///< the calibrated model's campaign: placements, drift, fitted ranges
  std::vector<Vec3> targets;
  std::vector<StationValue> stations;     ///< the probe stations (the campaign's, not the robot's)
  std::vector<EffectValue> effects;       ///< identified values of the extra effects
  double t_ref = 20.0;                    ///< reference temperature of thermal_expansion
  int iterations = 0;
  int chord_steps = 0;  ///< of the iterations, the steps taken with the Jacobian of the point before
  double initial_cost = 0, final_cost = 0;
  double rms_mm = 0, max_mm = 0;          ///< on the fitted rows
  double condition_number = 0, observability_index = 0;
  /// whether the data see the overall scale of the arm (not without a known length in a probe
  /// campaign: then the priors, or a held parameter, fix it)
  bool scale_determined = true;
  struct Correlation {
    std::string a, b;
    double r;
  };
  std::vector<Correlation> correlations;
  std::string termination;                ///< Ceres's brief report of the final stage-2 pass
  /// whether the fit converged: every stage-2 pass stopped on a Ceres tolerance (CONVERGENCE), none
  /// at its iteration cap (NO_CONVERGENCE) or on a failure
  bool converged = false;
  /// why it stopped: the Ceres termination type and message of the final pass, or of the first pass
  /// that did not converge (which pass of how many, e.g. "NO_CONVERGENCE: robust pass 1 of 2 stopped
  /// at its cap of 100 iterations (Maximum number of iterations reached. ...)")
  std::string stop_reason;
  /// Hold parameter i at its start value, for that reason.
  void fix(int i, std::string reason) {
    fixed[i] = true;
    fixed_reason[i] = std::move(reason);
  }
};

/// Identify the parameters from measurements (rows of the set). Throws InputError when the data
/// are too few for the free parameters.
/// `reference`: the placements the fitted ones are relative to (a calibrated robot's campaign when
/// refitting it; the identity by default).
IdentifyResult identify(const Model& nominal, const MeasurementSet& data, const IdentifyOptions& opt,
                        const Campaign& reference = Campaign{});

/// InputError unless the effects are valid for the robot and the data carry the columns they read
/// (the registry's needs: temperature_c, time_s, dir1..dirN), naming the file and line of the first
/// row without it: the one check identify() and Python's effect choice make.
void check_effect_columns(const Model& nominal, const MeasurementSet& data, const std::vector<Effect>& effects);

}  // namespace kincal
