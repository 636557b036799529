// kincal: measurement campaigns and parameter identification (step 3 of the Samak paper).
//
// Measurement model: a point measured in the instrument's frame is
//   y = B * P(q + K tau(q)) * M * t_k
// with B the robot base seen from the instrument, P the product of exponentials of the joint lines,
// K tau the joint deflection under gravity, M the tool frame at the zero configuration and t_k the
// offset of target (reflector) k in the tool frame.
//
// Parameters (all relative to the nominal model, so zero is the nominal):
//   per joint 4: axis tilt along u and v (rad; w' = normalise(w + a_u u + a_v v)) and the axis moved
//                along u and v (mm), with u, v unit vectors normal to the nominal axis;
//   per gravity-loaded joint 1: compliance (deg per kN m, absolute);
//   tool 6: translation (mm) and rotation vector (rad, R = R0 Exp(phi));
//   base 6: the same for the base frame in the instrument frame;
//   per target 3: offset in the tool frame (mm, absolute);
//   per extra effect (transmission_error 2 per harmonic order, backlash 1, thermal_expansion 1), see
//   effects.hpp (the registry).
// Rows with a measured orientation (a, b, c) add 3 residuals: the weighted rotation vector from the
// measured to the predicted tool frame.
// Identification is Ceres Levenberg-Marquardt with an analytic Jacobian. Parameters the data cannot
// determine are found from the scaled Jacobian (greedy column selection in a preferred order) and
// held at their start value.
#pragma once

#include "kincal/model/model.hpp"

#include <array>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace kincal {

struct Measurement {
  int pose = 0;
  VecQ q_deg;
  VecQ dir;                  ///< sign of the last motion of each joint (empty: unknown)
  double temperature_c = std::numeric_limits<double>::quiet_NaN();
  Vec3 xyz = Vec3::Zero();   ///< measured point, instrument frame (mm)
  bool has_abc = false;      ///< a full 6-D pose: the tool frame's orientation was measured too
  Vec3 abc = Vec3::Zero();   ///< measured orientation of the tool frame, instrument frame (KUKA ABC, deg)
  int target = 0;
  double payload_kg = std::numeric_limits<double>::quiet_NaN();  ///< NaN: the model's payload
  int line = 0;              ///< line in the source file (0: simulated)
};

struct MeasurementSet {
  std::string source;
  std::vector<Measurement> rows;
  int n_targets = 1;
  bool orientation = false;  ///< every row carries a measured orientation (a, b, c columns)
};

/// Read the measurement CSV of the contract (pose, q1..qN, x, y, z, optional target, payload_kg).
MeasurementSet read_measurements(const std::string& path, int dof);
MeasurementSet parse_measurements(const std::string& text, const std::string& source, int dof);
std::string format_measurements(const MeasurementSet& m, int dof);

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

/// Layout of the identification parameter vector for a model and a number of targets.
struct ParamLayout {
  int dof = 0, n_targets = 0;
  int joints = 0, compliance = 0, tool = 0, base = 0, targets = 0, effects = 0, size = 0;
  std::vector<int> loaded;            ///< joint of every compliance parameter
  std::vector<Effect> effect_list;    ///< extra effects, their parameters from `effects` on
  std::vector<int> effect_offset;
  double t_ref = 20.0;
  std::vector<std::string> names;     ///< one per parameter, e.g. "joint3.tilt_u", "base.ry"
  std::vector<std::string> units;     ///< "rad", "mm", "deg/kNm"
  ParamLayout(const Model& nominal, int n_targets, const std::vector<Effect>& effects = {}, double t_ref = 20.0);
};

/// Evaluates the measurement model and its analytic Jacobian for one parameter vector.
class PointModel {
 public:
  PointModel(const Model& nominal, int n_targets, const std::vector<Effect>& effects = {}, double t_ref = 20.0);
  const ParamLayout& layout() const { return layout_; }
  /// Set the parameters (size layout().size); builds the current model.
  void set_params(const std::vector<double>& x);
  /// Build the model variants for the payloads named in the data (payload_kg column).
  void prepare_payloads(const MeasurementSet& data);
  /// The current geometry as a model spec (base_in_instrument and tool included).
  ModelSpec spec() const;
  /// Jacobian columns of the base frame and targets only (the others left zero), for fitting the frames.
  /// With the data, every row's flange frame is computed here once and reused while only the frames
  /// move (set_params must not change the robot's own parameters until it is switched off).
  void set_frames_only(bool on, const MeasurementSet* data = nullptr);
  /// Predicted point (instrument frame) of measurement m; jac (3 x size, row-major) when not null.
  /// rot: the tool frame's orientation (instrument frame); jac_rot (3 x size): its angular velocity
  /// (instrument frame) per parameter.
  Vec3 predict(const Measurement& m, double* jac, Mat3* rot = nullptr, double* jac_rot = nullptr) const;
  /// Starting parameters: nominal geometry, base frame from the best rigid fit (Horn) of the
  /// nominal prediction of target 0 at the tool point, targets at the tool point.
  std::vector<double> start(const MeasurementSet& data) const;

 private:
  const Model& nominal_;
  ParamLayout layout_;
  std::vector<Vec3> u_, v_;
  std::vector<double> x_;
  bool frames_only_ = false;
  struct Flange {
    Mat3 r;
    Vec3 t;
    double scale;
  };
  std::vector<Flange> flange_;          ///< per row of flange_rows_, while frames_only_
  const Measurement* flange_rows_ = nullptr;
  const Flange* cached_flange(const Measurement& m) const;
  ModelSpec spec_;
  std::shared_ptr<const Model> current_;
  std::vector<std::pair<double, std::shared_ptr<const Model>>> payload_models_;
  Mat3 rb_, rm_, jrb_, jrm_;
  Vec3 tb_, tm_;
  std::vector<Vec3> w_, p_;
  const Model& model_for(double payload) const;
  void chain_frames(const VecQ& q, std::array<Mat3, kMaxJoints + 1>& gr, std::array<Vec3, kMaxJoints + 1>& gt) const;
  /// Gravity at the commanded angles: frames, centres of mass, moment arms and joint torques.
  struct GravityState {
    std::array<Mat3, kMaxJoints + 1> gr;
    std::array<Vec3, kMaxJoints + 1> gt, S;
    std::array<double, kMaxJoints + 1> M;
    std::array<Vec3, kMaxJoints> wc, oc, arm;
    std::array<double, kMaxJoints> tau{};
    Vec3 cp;
    double mp = 0;
  };
  void gravity_state(const Model& model, const Measurement& m, GravityState& gs) const;
  /// The joint frames G_0..G_n of row m with compliance and effects acting, and the thermal scale.
  void row_frames(const Model& model, const Measurement& m, GravityState& gs, std::array<Mat3, kMaxJoints + 1>& gr,
                  std::array<Vec3, kMaxJoints + 1>& gt, double& scale) const;
  void add_torque_terms(const Model& model, const GravityState& gs, const std::array<Vec3, kMaxJoints>& jp,
                        const std::array<Vec3, kMaxJoints>& jw, double* jac, double* jac_rot) const;
};

struct IdentifyOptions {
  bool compliance = true;          ///< identify the joint compliances
  std::string loss = "huber";      ///< "none", "huber", "cauchy"
  double loss_scale_mm = 0.1;      ///< where the robust loss bends
  int max_iterations = 100;
  double rank_tolerance = 1e-4;    ///< a unit column closer than this to the others' span: redundant
  double min_torque_share = 0.05;  ///< compliance of a joint with less gravity torque than this share is held
  double weak_tolerance = 2e-3;    ///< closer than this: so weakly seen that it is held too
  double correlation_threshold = 0.95;
  bool covariance = true;          ///< parameter standard deviations and correlations (Ceres covariance)
  std::vector<std::string> fix;    ///< parameter names to hold in any case
  std::vector<int> compliance_joints;  ///< with compliance: only these joints (0-based; empty: all)
  std::vector<Effect> effects;     ///< extra effects identified with the rest
  std::function<void(int iteration, double cost)> progress;
  double orientation_weight = 100.0;  ///< mm per rad: how orientation residuals weigh against positions
};

struct IdentifyResult {
  explicit IdentifyResult(ParamLayout l) : layout(std::move(l)) {}
  ParamLayout layout;
  std::vector<double> start, x, stddev;   ///< stddev NaN for fixed parameters
  std::vector<double> nominal_x;          ///< nominal geometry with the fitted base frame and targets
  double nominal_rms_mm = 0, nominal_max_mm = 0;  ///< on the fitted rows, nominal geometry
  ModelSpec nominal_fitted;               ///< nominal geometry, fitted base frame
  std::vector<Vec3> nominal_targets;      ///< targets fitted with the nominal geometry
  std::vector<bool> fixed;
  std::vector<std::string> fixed_reason;
  ModelSpec calibrated;
  std::vector<Vec3> targets;
  std::vector<EffectValue> effects;       ///< identified values of the extra effects
  double t_ref = 20.0;                    ///< reference temperature of thermal_expansion
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  double rms_mm = 0, max_mm = 0;          ///< on the fitted rows
  double condition_number = 0, observability_index = 0;
  struct Correlation {
    std::string a, b;
    double r;
  };
  std::vector<Correlation> correlations;
  std::string termination;
};

/// The residual of one row (3 position components in mm; with orientation 3 more: weight times the
/// rotation vector log(R_measured^T R_model)) and, when J is not null, its Jacobian (row-major,
/// rows x size; J must hold 6 x size). Returns the number of residuals.
int row_residuals(const PointModel& pm, const Measurement& m, double weight, bool orientation, double* r, double* J);

/// Identify the parameters from measurements (rows of the set). Throws InputError when the data
/// are too few for the free parameters.
IdentifyResult identify(const Model& nominal, const MeasurementSet& data, const IdentifyOptions& opt);

/// Position errors (mm) of every row of data predicted by a model (every effect it carries acting)
/// with the given targets.
std::vector<double> point_errors(const Model& model, const std::vector<Vec3>& targets, const MeasurementSet& data);

}  // namespace kincal
