// kincal: closed-form inverse kinematics by Paden-Kahan subproblems, as a solver built from a Model.
//
// For 6R robots whose axes 2 and 3 are parallel and whose axes 4, 5, 6 meet in one point (KUKA,
// FANUC, ABB class), with any offsets. The wrist centre fixes q1 (subproblem 4: its component along
// the parallel axes), q3 (subproblem 3: its distance from axis 2) and q2 (subproblem 1); the wrist
// orientation gives q4, q5 (subproblem 2) and q6 (subproblem 1). Up to 2 x 2 x 2 = 8 solutions.
//
// The Model stays an immutable description; the IkSolver is built from it once (the structure check
// and the closed form's constants) and then solves any number of targets. It copies what it reads
// of the model, so it does not refer to the Model after construction; solve() is const and keeps
// its per-call state on the stack (one solver may serve several threads).
#pragma once

#include "kincal/model/model.hpp"

#include <array>
#include <string>

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

  /// The solution within limits nearest (Euclidean norm in joint space, deg) to ref_deg (6 angles;
  /// null: zero); -1 when none.
  int nearest(const double* ref_deg) const;
};

/// What IkSolver::solve does with a target out of reach.
enum class OutOfReach {
  NoSolution,  ///< status OutOfReach, no solution
  /// the configurations nearest to it (subproblems at tangency), flagged approximate: a start for
  /// Newton on a calibrated robot, which may reach a little beyond the nominal one
  Nearest,
};

/// Which solutions IkSolver::solve computes.
enum class Branches {
  All,  ///< every solution (up to 8)
  /// only the branch nearest the reference, choosing shoulder, elbow and wrist in turn: about a
  /// quarter of the work, for programs and compensation (All when there is no reference)
  NearestReference,
};

/// The options of one IkSolver::solve call.
struct IkOptions {
  /// 6 angles (deg) the solutions are shifted near by multiples of 360 deg; null: zero. Must stay
  /// valid for the call.
  const double* reference_deg = nullptr;
  Branches branches = Branches::All;
  OutOfReach out_of_reach = OutOfReach::NoSolution;

  IkOptions() = default;
  explicit IkOptions(const double* reference, Branches b = Branches::All, OutOfReach r = OutOfReach::NoSolution)
      : reference_deg(reference), branches(b), out_of_reach(r) {}
  explicit IkOptions(const Vec6& reference, Branches b = Branches::All, OutOfReach r = OutOfReach::NoSolution)
      : IkOptions(reference.data(), b, r) {}
};

/// Which closed-form inverse kinematics applies to a model.
struct IkStructure {
  bool spherical_wrist_parallel_23 = false;  ///< axes 4,5,6 meet, axes 2,3 parallel (KUKA class)
  std::string reason;                        ///< why not, when not
  Vec3 wrist_center = Vec3::Zero();
  /// axis 5 normal to axes 4 and 6, which are parallel at zero: the second wrist solution of every
  /// arm solution is (q4 + 180, -q5, q6 + 180) (KUKA, ABB, FANUC wrists)
  bool wrist_flip = false;
  /// the ortho-parallel robots among them (axis 1 normal to axis 2, axis 3 = +-axis 2, a wrist with
  /// the flip, any offsets and any base placement): solved by the same subproblems written as plane
  /// rotations of two numbers in a frame of axes 1 and 2 (no 3-D rotation), the same solutions in the
  /// same order
  bool ortho_parallel = false;
};

/// Which form of the closed form IkSolver uses.
enum class IkForm {
  Fastest,     ///< the plane-rotation form on ortho-parallel robots, the vector form on the others
  PadenKahan,  ///< the vector form on every robot of the class (a cross-check of the faster form)
};

/// The closed-form IK of one model: its structure, its constants, and the solve.
class IkSolver {
 public:
  /// Constants of the closed form, fixed by the geometry: the elbow's subproblem 3 about axis 3
  /// (u = wrist centre - p3, v = p2 - p3: only the distance d changes) and the wrist's subproblem 2
  /// (k1 = axis 4, k2 = axis 5, u = axis 6: only v changes).
  struct Constants {
    Vec3 v6 = Vec3::UnitX();  ///< a unit vector normal to axis 6
    double sigma23 = 0;       ///< +-1 when axis 3 is exactly (to the bit) +-axis 2, else 0
    double elbow_q = 0, elbow_c = 1, elbow_s = 0;  ///< angle from u to v about axis 3 (projections)
    double elbow_nu = 0, elbow_nv = 0, elbow_dz = 0;  ///< |u|, |v| normal to axis 3; (u - v) along it
    double elbow_inv_2nunv = 0;                         ///< 1 / (2 |u| |v|)
    Vec3 n = Vec3::Zero(), m = Vec3::Zero();  ///< k1 x k2, k1 x n
    double k12 = 0, inv_den = -1, k2u = 0, u2 = 1, inv_n2 = 1;  ///< k1.k2, 1/(k12^2 - 1), k2.u, |u|^2, 1/|n|^2
    double a1 = 0, a2 = 0, b1 = 0, x21 = 0, y21 = 0;  ///< up.k1, up.k2, k2.(up x k1), up.n, k2.(up x n)
  };

  /// Checks the model's structure and, for a model of the class, computes the constants. A model
  /// outside the class gives a solver whose solve() answers Unsupported (structure().reason says why).
  explicit IkSolver(const Model& m, IkForm form = IkForm::Fastest);

  const IkStructure& structure() const { return st_; }
  const Constants& constants() const { return k_; }

  /// All closed-form solutions (or the nearest branch, see IkOptions) for the tool pose target (base
  /// frame, mm). Each angle is shifted by multiples of 360 deg to the value nearest the reference (or
  /// 0) that lies within the joint limits, when one does. Never NaN.
  IkSolutions solve(const Eigen::Isometry3d& target, const IkOptions& opt = IkOptions()) const;

 private:
  /// The ortho-parallel form's constants: the frame C of axes 1 and 2 (rows w1, w2, w1 x w2) and
  /// the model's vectors in it.
  struct Ortho {
    Mat3 ct = Mat3::Identity();
    double d = 0;             ///< w2 . (pw - p1): the wrist centre's offset along axis 2
    Vec3 p21 = Vec3::Zero();  ///< C (p2 - p1)
    double pw3_1 = 0, pw3_3 = 0, p32_1 = 0, p32_3 = 0;  ///< C (pw - p3) and C (p3 - p2), components 1 and 3
    double sigma = 1;         ///< w3 = sigma w2
    double tau = 1;           ///< w6 = tau w4
    Vec3 w4 = Vec3::Zero(), w5 = Vec3::Zero(), n = Vec3::Zero();  ///< C w4, C w5, C n
  };
  IkSolutions solve_vector(const Mat3& gr, const Vec3& p, const IkOptions& opt, bool deliver_now) const;
  IkSolutions solve_ortho(const Mat3& gr, const Vec3& p, const IkOptions& opt, bool deliver_now) const;
  bool into_limits(Vec6& q_deg, const double* ref_deg) const;
  void to_degrees(IkSolutions& out, const double* ref_deg) const;
  bool delivers(const IkOptions& opt) const;
  bool deliver(const double* q, const double* ref_deg, double* q_deg) const;
  void fill_ortho(IkForm form, const Vec3& wrist_center);
  void record(IkSolutions& out, double* q, double wrist, const Mat3& gr, bool shoulder, bool clamped,
              const IkOptions& opt, bool deliver_now) const;
  void polish(double* q, const Mat3& gr) const;

  IkStructure st_;
  Constants k_;
  Ortho o_;
  std::array<Vec3, 6> w_, p_;          ///< unit axes and axis points of the model
  Eigen::Isometry3d tool_;             ///< tool frame at the zero configuration
  std::array<double, 6> lo_{}, hi_{};  ///< joint limits (deg) widened by 1e-9
};

}  // namespace kincal
