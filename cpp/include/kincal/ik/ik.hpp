// kincal: closed-form inverse kinematics by Paden-Kahan subproblems.
//
// For 6R robots whose axes 2 and 3 are parallel and whose axes 4, 5, 6 meet in one point (KUKA,
// FANUC, ABB class), with any offsets. The wrist centre fixes q1 (subproblem 4: its component along
// the parallel axes), q3 (subproblem 3: its distance from axis 2) and q2 (subproblem 1); the wrist
// orientation gives q4, q5 (subproblem 2) and q6 (subproblem 1). Up to 2 x 2 x 2 = 8 solutions.
#pragma once

#include "kincal/model/model.hpp"

namespace kincal {

enum class IkStatus { Ok, OutOfReach, Unsupported };

struct IkSolution {
  Vec6 q_deg;  ///< joint angles in degrees (within limits when possible)
  bool within_limits = false;
  bool wrist_singular = false;        ///< axes 4 and 6 aligned: q4 + q6 is fixed, q4 is arbitrary
  bool shoulder_singular = false;     ///< wrist centre on axis 1: q1 is arbitrary
  bool approximate = false;           ///< out of reach: the nearest stretched configuration
};

struct IkSolutions {
  IkStatus status = IkStatus::OutOfReach;
  int count = 0;
  std::array<IkSolution, 8> sol;
};

/// Fills the closed form's geometry constants of st (wrist_flip, Constants) for a 6R model of the
/// class (st.wrist_center set), from its unit axes w and axis points p (the Model does this).
void fill_ik_constants(IkStructure& st, const Vec3* w, const Vec3* p);

/// All closed-form solutions of the nominal model for the tool pose T (base frame, mm).
/// Each angle is shifted by multiples of 360 deg to the value nearest ref_deg (or 0) that lies
/// within the joint limits, when one does. Never NaN.
/// With nearest_if_unreachable, a pose just out of reach (as a calibrated robot may reach) gives the
/// configurations nearest to it (subproblems at tangency), flagged approximate: a start for Newton.
/// With nearest_branch (and ref_deg), only the branch nearest the reference is computed, choosing
/// shoulder, elbow and wrist in turn: about a quarter of the work, for programs and compensation.
IkSolutions ik_all(const Model& m, const Eigen::Isometry3d& target, const double* ref_deg = nullptr,
                   bool nearest_if_unreachable = false, bool nearest_branch = false);

/// The solution within limits nearest (max-norm in joint space) to ref_deg; -1 when none.
int ik_nearest(const Model& m, const IkSolutions& s, const double* ref_deg);

}  // namespace kincal
