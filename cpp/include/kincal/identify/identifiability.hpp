// kincal: which identification parameters the data can determine. Before the solve, parameters
// are held (fixed at their start value, with the reason) where nothing lets the data see them
// (targets never measured, compliances not asked for or of joints the poses barely load, those
// held by request) and where the unit-scaled Jacobian shows them redundant or too weakly seen
// (greedy selection of independent columns in a preferred order); data that leave redundant what a
// generic campaign determines are an input error. After the solve: the condition number and the
// observability index of the free parameters.
#pragma once

#include "kincal/identify/identify.hpp"

#include <vector>

namespace kincal {

/// Fix what the options and the measured poses rule out: targets never measured, the target of the
/// 6-D rows (at zero offset: the frame they measure is the tool frame; InputError when 6-D rows
/// measure several targets), compliances not
/// asked for (opt.compliance, opt.compliance_joints) or of a joint with less than
/// opt.min_torque_share of the largest gravity torque over the poses (with masses), and the
/// parameters named in opt.fix (InputError for an unknown name). With the gravity fitted, the first
/// free compliance is held as the moments' scale (its res.start set to kUnitCompliance if zero).
void fix_unobservable(const Model& nominal, const MeasurementSet& data, const IdentifyOptions& opt,
                      IdentifyResult& res);

/// The Jacobian of every parameter (a row per residual, as all_residuals) and the residuals of a
/// measurement set at one parameter vector.
/// The reasons a setup's placement is held when the data cannot see it.
inline constexpr const char* kSetupNeverMeasured = "setup never measured";
inline constexpr const char* kProbeOnlySetup = "probe rows only: the stations' unknowns absorb the base frame";
/// The start of the reason a frame's parameter is held before the frames' fit (hold_unseen_frames).
inline constexpr const char* kUnseenFrame = "held at its start before the frames' fit";
/// Whether parameter i was held by hold_unseen_frames.
inline bool held_unseen(const IdentifyResult& res, int i) {
  return res.fixed[i] && res.fixed_reason[i].rfind(kUnseenFrame, 0) == 0;
}

/// Before the frames' fit (the first stage, without priors): while the smallest singular value of the
/// unit-scaled columns of the base placements, target offsets and (6-D rows) tool frame on these
/// tracker rows is below opt.weak_tolerance, one parameter of its direction is held at its start
/// (res.fix, the reason kUnseenFrame, the singular value and what moves with it): the largest part of
/// the direction on the tool (a target's offset, the tool frame) when it is at least half the largest,
/// else the largest. The case: every row's tool shares one axis direction (a campaign of one or two
/// tool orientations about it, or a fold that holds out the only configurations of another), so a
/// reflector's depth along that axis and the base's translation along it move together, seen through
/// a lever of 1e-4; an unprioritised fit slides along it (1.9 m on a 15-configuration fold of the
/// UR10's series B) and the model then predicts any other tool orientation wrong by depth x angle.
/// Probe rows: nothing held (the stations' unknowns absorb the base frame exactly; the later analysis
/// decides).
/// The parameters the frames' fit (the first stage) moves: the tool frame with measured orientations,
/// every placement measured by points (held or not: the first stage places it) and the targets not
/// held; what hold_unseen_frames held excluded. (The probe stations and the drift come on top.)
std::vector<int> frame_columns(const ParamLayout& L, const MeasurementSet& data, const IdentifyResult& res);

/// frames: the frames-only evaluation at the start (PointModel::at_frames_only), which the frames'
/// fit then starts from.
void hold_unseen_frames(const PointModel& pm, const PointState& frames, const MeasurementSet& data,
                        const IdentifyOptions& opt, IdentifyResult& res);

/// The data's residuals (every row's block, then one per artifact term) and their Jacobian.
struct Linearization {
  Eigen::MatrixXd jacobian;
  std::vector<double> residuals;
};

/// Fix what the data cannot determine at x: the greedy selection of independent unit-scaled
/// Jacobian columns (opt.rank_tolerance: redundant, opt.weak_tolerance: too weakly seen), on the
/// data and on a generic campaign (100 random poses in the limits of the nominal model, the targets
/// measured, the same kind of rows). Throws InputError when the data leave redundant what the
/// generic campaign determines (too few or too similar poses). With the gravity fitted (no mass
/// table, point_model.hpp) the columns are judged at the moments the data show (one Gauss-Newton
/// step from x): a link's moments that do not stand out of their noise are held at zero, and the
/// compliance of a joint they barely load (opt.min_torque_share) is held, all of them when no moment
/// is seen; x is then moved there (those moments, the free compliances at the held one's value, what
/// was held at its value): the start of the solve. Returns the data's linearization at x. With priors
/// (prior_sd: one per parameter, finite where it has one) what only the data leave undetermined is
/// no error: it stays free, determined by its prior (res.at_prior), or is held when it has none.
/// Without priors and with the gravity's moments not fitted, a probe campaign whose known lengths
/// (its artifact's distances) alone see the arm's overall scale is judged on its `touches` (the rows
/// and the frames fitted without those lengths; none: as any campaign), the parameter held there for
/// the scale then freed: the same touches with and without a length hold the same parameters but
/// that one.
struct Touches {
  MeasurementSet rows;     ///< the campaign without its known lengths (without_lengths)
  std::vector<double> at;  ///< the frames these rows alone give (the nominal geometry's)
};
Linearization fix_unidentifiable(const PointModel& pm, const Model& nominal, const MeasurementSet& data,
                                 std::vector<double>& x, const IdentifyOptions& opt, IdentifyResult& res,
                                 const std::vector<double>& prior_sd = {}, const Touches* touches = nullptr);

/// The set without its artifact's known distances (its angles kept); whether it had any.
bool without_lengths(const MeasurementSet& data, MeasurementSet& out);

/// The one parameter a selection on a probe campaign's touches held for the overall scale, freed (the
/// known lengths set it): of those the selection held (not held before it, `before`, nor by the
/// generic campaign), the one the lengths see most beside the free ones, the largest distance of its
/// unit-scaled column of J (every row, the lengths' included) from their span, among those whose
/// distance there is more than ten times their distance in J_touches (the touches' rows alone: a
/// parameter held there for another reason is not one the lengths see); none when no such one.
/// (The touches see the scale barely or not at all: the parameter that carries it is held as barely
/// identifiable, or as a combination of the others.)
void release_scale(const Eigen::MatrixXd& J, const Eigen::MatrixXd& J_touches, const IdentifyResult& generic,
                   const std::vector<bool>& before, IdentifyResult& res);

/// The parameters' rates under a uniform scaling of every length (per unit of the scale's change).
Eigen::VectorXd scale_direction(const PointModel& pm, const std::vector<double>& x);

/// Whether the rows (their Jacobian J at x, the artifact's terms included) see a uniform scaling of
/// every length: what is left of it in the rows against what its parts alone would show (a probe
/// campaign without a known length leaves almost nothing: only the gravity torques' centres of
/// mass, given in mm, see it at all).
bool scale_seen(const PointModel& pm, const Eigen::MatrixXd& J, const std::vector<double>& x);
/// What the rows see of a uniform scaling (|J v| over the root sum of its parts |J_i v_i|): scale_seen
/// above 1e-3.
double scale_visibility(const PointModel& pm, const Eigen::MatrixXd& J, const std::vector<double>& x);
/// The condition number and the observability index of the free parameters (the unit-scaled
/// Jacobian at res.x), into res. jacobian: the rows' Jacobian at res.x when the caller has it
/// (row-major, a row per residual, a column per parameter, as all_residuals with every column;
/// used only when the data have no artifact terms), else null: evaluated here.
void observability(const PointModel& pm, const MeasurementSet& data, const IdentifyOptions& opt, IdentifyResult& res,
                   const double* jacobian = nullptr);

}  // namespace kincal
