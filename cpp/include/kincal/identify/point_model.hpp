// kincal: the measurement model of identification and its analytic Jacobian (step 3 of the Samak
// paper): the layout of the parameter vector, PointModel (one row's predicted point and tool frame
// for a parameter vector) and the residuals of a row and of a whole measurement set.
//
// Measurement model: a point measured in the instrument's frame is
//   y = B_s * P(q + K tau(q)) * M * t_k
// with B_s the robot base seen from the instrument in the row's setup s (one placement per value of
// the setup column; one without it), P the product of exponentials of the joint lines, K tau the
// joint deflection under gravity, M the tool frame at the zero configuration and t_k the offset of
// target (reflector) k in the tool frame, shared by every setup. With the drift effect the
// placement moves with the row's time: B_s(t) y = Exp(tau w) (R_s y) + t_s + tau v, tau = (t -
// t_mean) / 3600 s (effects.hpp).
//
// Parameters (all relative to the nominal model, so zero is the nominal):
//   per joint 4: axis tilt along u and v (rad; w' = normalise(w + a_u u + a_v v)) and the axis moved
//                along u and v (mm), with u, v unit vectors normal to the nominal axis;
//   per gravity-loaded joint 1: compliance (deg per kN m, absolute);
//   with the gravity fitted (no mass table, see below) per link from the first loaded joint's on 2:
//        its first moment across its joint's axis, along u and v (t m = 1e6 kg mm: columns of the
//        order of the others', so that the covariance's conditioning is not lost to units);
//   tool 6: translation (mm) and rotation vector (rad, R = R0 Exp(phi));
//   base 6 per setup: the same for the base frame in the instrument frame ("base.x" for one setup,
//        "base[NAME].x" for several), relative to the model's frame of that setup name (its setups)
//        or to its base_in_instrument;
//   per target 3: offset in the tool frame (mm, absolute);
//   per extra effect (transmission_error 2 per harmonic order, backlash 1, thermal_expansion 1,
//   drift 6), see effects.hpp (the registry).
// Gravity without a mass table ("fit"): the torque about joint j is tau_j = w_j . (A_j x g) with
// A_j = sum_{k>=j} G_{k+1} a_k (+ the payload's known part), a_k a constant vector of link k (its mass
// times its centre of mass from p_k, plus the mass beyond it times p_{k+1} - p_k): linear in the
// a_k. Along w_k, a_k only moves a constant vector of link k-1 (G_{k+1} w_k = G_k w_k), so only its
// 2 components across w_k count: every gravity torque is reached with those. Compliance times these
// moments is what the points see: K_j a_k, unchanged by K -> K / s, a -> s a. That scale is held:
// the compliance of the first loaded joint asked for stays at its start value (its nominal one, or
// kUnitCompliance), and the fitted moments are "effective" ones at that compliance; every other
// compliance is free, its ratio to the held one identified. This bilinear form (not one product
// K_j a_k per pair, which the points would also see) keeps one moment per link, so that the result
// is a mass table: every fitted link gets kUnitMass kg at its centre of mass p_k + (a_k - M_{k+1}
// (p_{k+1} - p_k)) / kUnitMass, which fk, compensate and kincal-compensate apply as they apply any
// masses. The payload's mass stays the model's (a constant payload is absorbed by the moments; only
// several payloads in the data fix the absolute scale, and then the scale is not held).
// Rows with a measured orientation (a, b, c) add 3 residuals: the weighted rotation vector from the
// measured to the predicted tool frame. Such a row measures the tool frame itself (its target's offset
// is held at zero: identify() then identifies the tool frame); a reflector row among them keeps its
// 3 orientation residuals at zero.
#pragma once

#include "kincal/identify/fit_modes.hpp"
#include "kincal/io/measurements.hpp"
#include "kincal/model/model.hpp"

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace kincal {

/// The fitted gravity's mass of every fitted link (kg) and the held compliance's start value
/// (deg/kNm) when the model has none: only their products with the moments are determined.
constexpr double kUnitMass = 1.0, kUnitCompliance = 0.01;
/// kg mm per unit of a fitted moment parameter (t m)
constexpr double kMomentUnit = 1e6;

/// Whether identification fits the gravity's mass moments: mode "fit", or "auto" and no link of the
/// model has a mass; "masses" uses the model's (InputError when it has none, or for another mode).
bool gravity_fitted(const Model& nominal, GravityTorques mode);

/// Layout of the identification parameter vector for a model, a number of targets and the setups.
struct ParamLayout {
  int dof = 0, n_targets = 0, n_setups = 1;
  int joints = 0, compliance = 0, moments = 0, tool = 0, base = 0, targets = 0, effects = 0, size = 0;
  bool fit_gravity = false;           ///< the gravity's mass moments are parameters (no mass table)
  std::vector<int> moment_links;      ///< the link (joint index) of every pair of moment parameters
  int drift = -1;                     ///< offset of the drift's 6 parameters (-1: no drift)
  std::vector<int> loaded;            ///< joint of every compliance parameter
  std::vector<Effect> effect_list;    ///< extra effects, their parameters from `effects` on
  std::vector<int> effect_offset;
  double t_ref = 20.0;
  double t_mean = 0;                  ///< the drift's reference time (s)
  std::vector<std::string> setup_names;  ///< by setup code (empty: one setup, no setup column)
  std::vector<std::string> names;     ///< one per parameter, e.g. "joint3.tilt_u", "base.ry", "base[B].ry"
  std::vector<std::string> units;     ///< "rad", "mm", "deg/kNm", "t m"
  /// setups: the names of the data's setups (by code); none or one: a single placement "base.*".
  /// fit_gravity: the moments of every link from the first loaded joint's on are parameters.
  ParamLayout(const Model& nominal, int n_targets, const std::vector<Effect>& effects = {}, double t_ref = 20.0,
              const std::vector<std::string>& setups = {}, double t_mean = 0, bool fit_gravity = false);
};

/// Evaluates the measurement model and its analytic Jacobian for one parameter vector.
class PointModel {
 public:
  PointModel(const Model& nominal, int n_targets, const std::vector<Effect>& effects = {}, double t_ref = 20.0,
             const std::vector<std::string>& setups = {}, double t_mean = 0, bool fit_gravity = false);
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
  /// Starting parameters: nominal geometry, each setup's base frame from the best rigid fit (Horn)
  /// of the nominal prediction of the tool point to that setup's rows, targets at the tool point.
  /// With the gravity fitted: every moment zero (no link torque), compliances nominal.
  std::vector<double> start(const MeasurementSet& data) const;
  /// With the gravity fitted: generic non-zero moments (and free zero compliances at the held one's
  /// value) in place of x's, for judging what the data determine: at zero moments a compliance has
  /// no effect, whatever the data (the bilinear form's saddle).
  std::vector<double> probe(std::vector<double> x, const std::vector<bool>& fixed) const;

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
  /// One instrument placement: its reference frame (r0, t0) and, at the current parameters, its
  /// frame (r, t) and the right Jacobian of its rotation vector.
  struct Placement {
    Mat3 r0, r, jr;
    Vec3 t0, t;
  };
  std::vector<Placement> place_;
  /// The row's placement (InputError for a setup code out of the layout); kept out of line with the
  /// drift's parts, so that predict()'s common path stays as compact as with one placement.
  [[gnu::noinline]] const Placement& placement(const Measurement& m) const;
  /// The placement at the row's time (rb, tb), tau in hours and the drift's rotation vector dw.
  [[gnu::noinline]] void drifted(const Measurement& m, const Placement& pl, Mat3& rb, Vec3& tb, double& tau,
                                 Vec3& dw) const;
  /// The drift's Jacobian columns at a row (rx: the rotated point R x).
  [[gnu::noinline]] void drift_columns(double tau, const Vec3& dw, const Vec3& rx, double* jac, double* jac_rot) const;
  Mat3 rm_, jrm_;
  Vec3 tm_;
  std::vector<Vec3> w_, p_;
  std::vector<Vec3> com0_;  ///< with the gravity fitted: each link's centre of mass at zero moments
  void init_fitted_gravity();                       ///< com0_ from the nominal geometry
  void fitted_masses(const std::vector<double>& x);  ///< the moments of x as spec_'s mass table
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
  /// rb: the row's instrument placement (rotation).
  void add_torque_terms(const Model& model, const GravityState& gs, const std::array<Vec3, kMaxJoints>& jp,
                        const std::array<Vec3, kMaxJoints>& jw, const Mat3& rb, double* jac,
                        double* jac_rot) const;
};

/// What the residual of a row holds: its point (3 position components, mm) or its full pose (the
/// same and 3 orientation components). The value is the number of residuals.
enum class ResidualKind { position = 3, pose = 6 };

/// The number of residuals of a row of that kind.
constexpr int residual_size(ResidualKind kind) { return static_cast<int>(kind); }

/// The residual kind of every row of a set: pose when it carries measured orientations.
inline ResidualKind residual_kind(const MeasurementSet& data) {
  return data.orientation ? ResidualKind::pose : ResidualKind::position;
}

/// The residual of one row (3 position components in mm; for a pose 3 more: orientation_weight
/// times the rotation vector log(R_measured^T R_model), zero for a row without one) and, when J is
/// not null, its Jacobian
/// (row-major, rows x size; J must hold 6 x size). Returns the number of residuals.
int row_residuals(const PointModel& pm, const Measurement& m, ResidualKind kind, double orientation_weight, double* r,
                  double* J);

/// The residuals of every row of data at pm's parameters (residual_size(residual_kind(data)) per
/// row, in order, into r; r null: not kept) and, when J is not null, the Jacobian's columns
/// `columns` in that order (row-major: a row per residual, columns.size() wide). The rows are
/// evaluated on all cores; nothing is allocated per row.
void all_residuals(const PointModel& pm, const MeasurementSet& data, double orientation_weight,
                   const std::vector<int>& columns, double* r, double* J);

}  // namespace kincal
