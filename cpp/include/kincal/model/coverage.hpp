// kincal: which joint angles a model was fitted on, and where it is asked to extrapolate.
//
// An effect periodic in a joint's angle (transmission_error, joint_map) is known only over the angles
// its fit saw: beyond them its series goes on, but nothing measured it. A joint's fitted range is the
// shortest arc of the circle that holds every fitted angle (angles modulo 360 deg, the effects being
// periodic), written [lo, hi] with lo in [-180, 180) and hi - lo the arc's length; fitted angles that
// leave no gap wider than kFullTurnGapDeg cover the whole turn, [-180, 180]. The calibrated model
// carries them (ModelSpec::fitted_deg, the model JSON's "fitted_joint_ranges_deg").
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "kincal/model/model.hpp"

namespace kincal {

/// fitted angles with no gap wider than this between neighbours (deg) cover the whole turn
constexpr double kFullTurnGapDeg = 10.0;
/// an angle this close to a fitted range (deg) is inside it
constexpr double kRangeMarginDeg = 1.0;

/// Per joint, the fitted range of rows of joint angles (deg; row-major, rows x dof); angles that are
/// not finite are left out (InputError when a joint has none); no rows: none (unknown). The angles
/// are the model's (ModelSpec), not a controller's numbers (joint_convention.hpp).
std::vector<JointRange> joint_ranges(const double* q_deg, size_t rows, int dof);

/// True when an angle (deg, any turn) lies outside a range by more than kRangeMarginDeg (never for an
/// angle that is not finite).
bool outside_range(double q_deg, const JointRange& range);

/// Checks ranges read from a file: one per joint, lo in [-180, 180), 0 <= hi - lo <= 360.
void check_joint_ranges(const std::vector<JointRange>& ranges, int dof, const std::string& who);

/// A joint whose periodic effects the rows ask for outside the angles they were fitted on.
struct Extrapolation {
  int joint = 0;            ///< counted from 1
  std::string effects;      ///< the joint's periodic effects, e.g. "joint_map(joint 1)"
  JointRange fitted{};      ///< the fitted range (deg)
  size_t rows = 0;          ///< rows outside it
  size_t first = 0;         ///< the first of them (0-based)
};

/// The joints of a calibrated model's periodic effects with a fitted range (its campaign's `fitted`,
/// one per joint; rows 0), in joint order; none without fitted ranges.
std::vector<Extrapolation> periodic_joints(const ModelSpec& calibrated, const std::vector<JointRange>& fitted);

/// The joints of a calibrated model's periodic effects that rows of joint angles (deg, row-major)
/// leave, in joint order; none without fitted ranges.
std::vector<Extrapolation> extrapolated(const ModelSpec& calibrated, const std::vector<JointRange>& fitted,
                                        const double* q_deg, size_t rows, int dof);

/// "joint 1 is outside the -180..-45 deg its joint_map(joint 1) was fitted on (angles modulo 360 deg)"
std::string leaving_message(const Extrapolation& e);

/// leaving_message() and " at 12 of 20 poses (60%): ..." (``noun``: "poses", "rows").
std::string extrapolation_message(const Extrapolation& e, size_t total, const std::string& noun);

}  // namespace kincal
