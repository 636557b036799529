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
//   drift 6), see effects.hpp (the registry);
//   per probe station 3 (instrument frame of the row's setup): a sphere's centre or a ballbar's
//        pivot (mm, absolute); a plane's normal tilted from its reference normal along two
//        directions normal to it (rad) and its offset, n . y = offset for the points y of the plane
//        (mm, absolute). The reference normal is the plane through the rows' ball centres on the
//        nominal model, turned towards the flange.
// A probe row's residual is along its constraint: a sphere row's ball centre minus the station's
// point (3), a plane row's distance of the ball centre from the plane minus the ball's radius (1), a
// ballbar row's distance from the pivot minus its length (1); the unused components of the row's
// residual block are zero.
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
#include "kincal/identify/stations.hpp"
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

/// What a layout is built from besides the model: the targets, the extra effects, the setups and
/// the references of the temperature and time effects.
struct LayoutOptions {
  LayoutOptions() = default;
  LayoutOptions(int targets, std::vector<Effect> extra = {}, double t_ref_c = 20.0, std::vector<std::string> setup_names = {},
                double t_mean_s = 0, bool fit_moments = false)
      : n_targets(targets), effects(std::move(extra)), t_ref(t_ref_c), setups(std::move(setup_names)), t_mean(t_mean_s),
        fit_gravity(fit_moments) {}
  int n_targets = 1;
  std::vector<Effect> effects;          ///< extra effects (not joint_compliance: IdentifyOptions::compliance)
  double t_ref = 20.0;                  ///< thermal reference temperature (deg C)
  std::vector<std::string> setups;      ///< the data's setup names by code; none or one: one placement "base.*"
  double t_mean = 0;                    ///< the drift's reference time (s)
  bool fit_gravity = false;             ///< the moments of every link from the first loaded joint's on are parameters
  std::vector<std::string> station_names;  ///< the data's probe stations by code (none without probe rows)
  std::vector<MeasureKind> station_kinds;  ///< and their kinds
  /// the planes' reference normals by station (empty: from the data the PointModel is given, else z)
  std::vector<Vec3> station_normals;
  /// where the targets start (mm, tool frame; empty: the origin): the balls the reference normals
  /// are fitted through (IdentifyOptions::target_start)
  std::vector<Vec3> target_start;
};

/// Layout of the identification parameter vector for a model and its options.
struct ParamLayout {
  int dof = 0, n_targets = 0, n_setups = 1;
  int joints = 0, compliance = 0, moments = 0, tool = 0, base = 0, targets = 0, effects = 0, stations = 0, size = 0;
  bool fit_gravity = false;           ///< the gravity's mass moments are parameters (no mass table)
  std::vector<int> moment_links;      ///< the link (joint index) of every pair of moment parameters
  int drift = -1;                     ///< offset of the drift's 6 parameters (-1: no drift)
  std::vector<int> loaded;            ///< joint of every compliance parameter
  std::vector<Effect> effect_list;    ///< extra effects, their parameters from `effects` on
  std::vector<int> effect_offset;
  double t_ref = 20.0;
  double t_mean = 0;                  ///< the drift's reference time (s)
  std::vector<std::string> setup_names;  ///< by setup code (empty: one setup, no setup column)
  std::vector<std::string> station_names;  ///< by station code; 3 parameters each from `stations` on
  std::vector<MeasureKind> station_kinds;
  std::vector<Vec3> station_normals;  ///< every station's reference normal (a plane's tilts turn it)
  std::vector<std::string> names;     ///< one per parameter, e.g. "joint3.tilt_u", "base.ry", "base[B].ry"
  std::vector<std::string> units;     ///< "rad", "mm", "deg/kNm", "t m"
  ParamLayout(const Model& nominal, const LayoutOptions& options);
};

namespace detail {
struct PointStructure;
class PointEval;
}  // namespace detail

class PointState;

/// The measurement model of one robot, layout and data: immutable after construction, so one
/// PointModel serves every thread. Its predictions are made by a PointState, the model at one
/// parameter vector (pinocchio's Model and Data: the model here, the state and the threads'
/// scratch apart).
class PointModel {
 public:
  /// nominal: must outlive the model and its states. data: the payloads named in its rows' payload_kg
  /// column get their model variants (a row with another payload is refused), its planes their
  /// reference normals (without it: the z axis). reference: the placements every setup's correction
  /// is relative to (the setup of that name, or its base_in_instrument; the identity by default).
  PointModel(const Model& nominal, const LayoutOptions& options, const MeasurementSet* data = nullptr,
             const Campaign& reference = Campaign{});
  const ParamLayout& layout() const;
  /// The model at parameters x (size layout().size).
  PointState at(const std::vector<double>& x) const;
  /// The model at x for fitting the frames alone: every row of data has its flange frame computed
  /// once; predictions of those rows give the Jacobian columns of the base frame, tool and targets
  /// only (the others left zero). Reuse it only while the robot's own parameters stay at x's.
  PointState at_frames_only(const std::vector<double>& x, const MeasurementSet& data) const;
  /// Starting parameters: nominal geometry, each setup's base frame from the best rigid fit (Horn)
  /// of the nominal prediction of the tool point to that setup's points, targets at the tool point
  /// (or at `targets`, mm in the tool frame: a probe's nominal ball), the stations through the
  /// nominal points of their rows (each row's target at its start).
  /// With the gravity fitted: every moment zero (no link torque), compliances nominal.
  std::vector<double> start(const MeasurementSet& data, const std::vector<Vec3>& targets = {}) const;
  /// With the gravity fitted: generic non-zero moments (and free zero compliances at the held one's
  /// value) in place of x's, for judging what the data determine: at zero moments a compliance has
  /// no effect, whatever the data (the bilinear form's saddle).
  std::vector<double> probe(std::vector<double> x, const std::vector<bool>& fixed) const;

 private:
  std::shared_ptr<const detail::PointStructure> s_;
};

/// The measurement model at one parameter vector: immutable, cheap to copy, safe to share between
/// threads.
class PointState {
 public:
  const ParamLayout& layout() const;
  const std::vector<double>& x() const;
  /// The geometry at these parameters as a model spec (tool included).
  const ModelSpec& spec() const;
  /// The instrument's placements at these parameters (base_in_instrument, one per named setup).
  const Campaign& campaign() const;
  /// The same model (frames-only mode and its cached flange frames included) at parameters x.
  PointState with_params(const std::vector<double>& x) const;
  /// Predicted point (instrument frame) of measurement m; jac (3 x size, row-major) when not null.
  /// rot: the tool frame's orientation (instrument frame); jac_rot (3 x size): its angular velocity
  /// (instrument frame) per parameter.
  Vec3 predict(const Measurement& m, double* jac, Mat3* rot = nullptr, double* jac_rot = nullptr) const;
  /// A probe row's residual (its components along the constraint, then zeros up to `size`) and, when
  /// J is not null, its Jacobian (size x layout().size, row-major). Returns the components used.
  int probe_residuals(const Measurement& m, int size, double* r, double* J) const;
  /// An artifact term's residual (mm: a length error; an angle error in rad times a 1 m lever) and,
  /// when J is not null, its gradient (layout().size).
  double artifact_residual(const ArtifactTerm& a, double* J) const;
  /// The probe stations at these parameters (layout order).
  std::vector<StationValue> stations() const;

 private:
  friend class PointModel;
  explicit PointState(std::shared_ptr<const detail::PointEval> e) : e_(std::move(e)) {}
  std::shared_ptr<const detail::PointEval> e_;
};

/// What the residual of a row holds: its point (3 position components, mm) or its full pose (the
/// same and 3 orientation components). The value is the number of residuals.
enum class ResidualKind { position = 3, pose = 6 };

/// The number of residuals of a row of that kind.
constexpr int residual_size(ResidualKind kind) { return static_cast<int>(kind); }

/// The position components of a row's residual that carry an equation: a point's or a sphere row's 3,
/// a plane or ballbar row's 1 (the first; the rest of its block is zero).
constexpr int position_equations(const Measurement& m) {
  return m.kind == MeasureKind::plane || m.kind == MeasureKind::distance ? 1 : 3;
}

/// The residual kind of every row of a set: pose when it carries measured orientations.
inline ResidualKind residual_kind(const MeasurementSet& data) {
  return data.orientation ? ResidualKind::pose : ResidualKind::position;
}

/// The residual of one row (3 position components in mm; for a pose 3 more: orientation_weight
/// times the rotation vector log(R_measured^T R_model), zero for a row without one) and, when J is
/// not null, its Jacobian
/// (row-major, rows x size; J must hold 6 x size). Returns the number of residuals.
/// scratch: 3 x size doubles for the orientation's Jacobian (null: allocated here).
int row_residuals(const PointState& pm, const Measurement& m, ResidualKind kind, double orientation_weight, double* r,
                  double* J, double* scratch = nullptr);

/// The residuals of every row of data at pm's parameters (residual_size(residual_kind(data)) per
/// row, in order, into r; r null: not kept) and, when J is not null, the Jacobian's columns
/// `columns` in that order (row-major: a row per residual, columns.size() wide; or, when column_stride
/// is not 0, column-major: residual k of column c at J[c * column_stride + k]). The rows are
/// evaluated on the process's thread pool, 256 rows or more per thread; nothing is allocated per row.
void all_residuals(const PointState& pm, const MeasurementSet& data, double orientation_weight,
                   const std::vector<int>& columns, double* r, double* J, size_t column_stride = 0);

/// Every row's error at pm's parameters (mm): a point's distance from its prediction, a probe row's
/// residual along its constraint (a sphere row's distance from the station's point, a plane or ballbar
/// row's error of distance). Orientations are not counted.
std::vector<double> row_errors(const PointState& pm, const MeasurementSet& data);

}  // namespace kincal
