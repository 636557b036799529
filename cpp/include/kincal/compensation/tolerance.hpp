// kincal: between the targets (`--tolerance MM`). The compensation is exact at the targets; between
// two of them the controller interpolates, and the real robot (the calibrated model) may leave the
// desired straight segment. Here the path is followed at kPathSamples points per segment, and where it
// leaves the desired segment (position, mm) by more than the tolerance, a target is inserted halfway
// (the desired pose interpolated: position linearly, orientation by slerp) and compensated, until every
// segment keeps within the tolerance.
//
// The controller's path between two compensated targets qa, qb:
//   - Joint: joint targets (PTP / MoveAbsJ / J / movej / G-code A words): q(s) = qa + s (qb - qa);
//   - NominalLine: filtered Cartesian targets moved along a line (LIN / MoveL / L / movel): the nominal
//     model's straight line from FK_nom(qa) to FK_nom(qb) (position linear, orientation slerp), the
//     joints the controller's nominal IK gives on it (the branch followed from qa).
// The real robot stands at FK_cal(q(s)) with the model's effects (backlash: each joint's direction of
// motion in the segment; thermal expansion: the temperature interpolated).
#pragma once

#include "kincal/compensation/program.hpp"

#include <string>
#include <vector>

namespace kincal {

/// The controller's interpolation between two targets; Unchecked: a segment not followed (an arc, or
/// a start kincal does not know).
enum class PathKind { Joint, NominalLine, Unchecked };

/// Points per segment at which the path is followed (interior points s = k / kPathSamples).
constexpr int kPathSamples = 32;

/// The largest distance (mm) of the real robot's path from qa to qb (kPathSamples interior points)
/// from the desired segment between the positions of a and b (robot base frame).
double segment_deviation_mm(const Robot& robot, const Pose6& a, const Pose6& b, const Vec6& qa_deg,
                            const Vec6& qb_deg, PathKind kind, const EffectContext& ctx_a, const EffectContext& ctx_b);

/// A program compensated with targets inserted where the path would leave the tolerance.
struct ToleranceResult {
  std::vector<Pose6> poses;           ///< the program's poses with the inserted ones (program frame)
  std::vector<int> original;          ///< per pose: its index in the input program, or -1 when inserted
  std::vector<std::string> where;     ///< per pose: the input's "file:line" (inserted: of the target after it)
  ProgramResult result;               ///< the compensation of every pose
  double before_mm = 0;               ///< the largest deviation between the input's targets
  double after_mm = 0;                ///< the largest deviation between the targets written
  int inserted = 0;
};

/// compensate_poses, then segments bisected until each keeps within tolerance_mm (>0). InputError when a
/// segment still exceeds it after 2^20 subdivisions (a singularity between two targets?). kinds: per
/// segment i (from pose i to i + 1), the controller's interpolation; a segment's halves keep its kind.
ToleranceResult compensate_with_tolerance(const Robot& robot, const std::vector<Pose6>& poses,
                                          const std::vector<std::string>& where, const ProgramOptions& opt,
                                          const std::vector<double>& temperature_c, double tolerance_mm,
                                          const std::vector<PathKind>& kinds,
                                          const std::vector<std::optional<Vec6>>& references = {});
/// The same with one kind for every segment.
ToleranceResult compensate_with_tolerance(const Robot& robot, const std::vector<Pose6>& poses,
                                          const std::vector<std::string>& where, const ProgramOptions& opt,
                                          const std::vector<double>& temperature_c, double tolerance_mm,
                                          PathKind kind);

/// The pose at s in [0, 1] between a and b: position linear, orientation by slerp (shortest way).
Pose6 interpolate_pose(const Pose6& a, const Pose6& b, double s);

}  // namespace kincal
