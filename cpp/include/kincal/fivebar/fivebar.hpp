// kincal: the Kiper paper's hidden robot (a planar 5-bar A0ACB with concurrent fixed joints), the
// over-constrained 6-bar it stands for (the truth simulator), link-length synthesis, and the
// error-correction matrix with its real-time corrector.
//
// Hidden robot: both actuated joints at the origin; crank a at theta1 to A, crank d at theta2 to B,
// couplers b (A to C) and c (B to C). Lengths in mm, angles in radians unless named _deg.
#pragma once

#include <Eigen/Core>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace kincal {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

struct FiveBar {
  double a = 150, b = 150, c = 150, d = 150;
  /// Assembly mode: the sign of (B - A) x (C - A); +1 puts C beyond the line AB, away from the
  /// fixed joints (the nominal mechanism of the paper).
  int assembly = +1;
  /// Working modes of the IK: +1 puts the crank's joint A left of the line from the origin to C
  /// (seen from the origin), -1 right of it; the paper's mechanism: A left (+1), B right (-1).
  int working1 = +1, working2 = -1;
};

/// End-effector C for actuator angles (rad); false when the couplers cannot close the loop.
bool fivebar_fk(const FiveBar& m, double t1, double t2, Vec2& c);
/// Actuator angles (rad) for C in the model's working modes (the paper's: A left of OC, B right of
/// it, seen from the origin); the angles are put next to ref (2 pi periodic) when ref is given.
/// false when C is out of reach.
bool fivebar_ik(const FiveBar& m, const Vec2& c, double& t1, double& t2, const double* ref = nullptr);
/// The Jacobian dC/d(theta1, theta2) (eq. 8 is its inverse); false at a singular pose.
bool fivebar_jacobian(const FiveBar& m, double t1, double t2, Mat2& j);

/// dC/d(a, b, c, d) at actuator angles (rad); false at a singular pose.
bool fivebar_length_jacobian(const FiveBar& m, double t1, double t2, Eigen::Matrix<double, 2, 4>& j);

/// One row of Table I (and of a grid measurement): the commanded angles, the desired position and
/// the measured one.
struct FiveBarPoint {
  int id = 0;
  double t1_deg = 0, t2_deg = 0;
  Vec2 desired = Vec2::Zero(), measured = Vec2::Zero();
  int line = 0;
};
/// Read a table with the columns of data/fivebar-table1.csv (errors name file:line and cause).
std::vector<FiveBarPoint> read_fivebar_table(const std::string& path);

/// Link lengths from a set of points (indices into pts) against the measured positions.
/// Polynomial approximation (exactly two points per dyad, eqs. 1-3) or linear least squares
/// (eqs. 4-6, two or more); each dyad separately. false when the equations are singular or give an
/// imaginary length.
bool fivebar_synthesis(const std::vector<FiveBarPoint>& pts, const std::vector<int>& use, bool least_squares,
                       FiveBar& out);

/// The largest distance over pts between the model at the commanded angles and the measured (or,
/// with desired = true, the desired) position; infinity when the model cannot reach one.
double fivebar_max_error(const FiveBar& m, const std::vector<FiveBarPoint>& pts, bool desired);

/// Every subset of n_min..n_max points (n = 2 for the polynomial method) fitted and scored; the one
/// with the smallest largest error wins (ties: the earlier subset).
struct SubsetResult {
  FiveBar model;
  std::vector<int> points;  ///< indices into pts
  double max_error = 0;
  long subsets_tried = 0;
};
SubsetResult fivebar_best_subset(const std::vector<FiveBarPoint>& pts, bool least_squares, bool desired_score,
                                 int n_min, int n_max);

// fivebar_fit_nonlinear (on Ceres) is in kincal/fivebar/fit.hpp: kincal::identify defines it.

/// The error-correction matrix: errors desired - measured on a regular grid, bilinear (eq. 7).
struct ErrorMatrix {
  double x0 = 0, y0 = 0, dx = 5, dy = 5;
  int nx = 0, ny = 0;
  std::vector<double> ex, ey;  ///< row-major [iy * nx + ix]
  /// Interpolated error at p (clamped to the grid's edges).
  Vec2 at(const Vec2& p) const;
  std::string to_json() const;
  static ErrorMatrix from_json(const std::string& text, const std::string& source);
  static ErrorMatrix from_points(const std::vector<FiveBarPoint>& grid, const std::string& source);
};

/// The real-time corrector: hidden-robot IK, bilinear lookup, Jacobian correction. No allocation.
class FiveBarCorrector {
 public:
  FiveBarCorrector(const FiveBar& m, const ErrorMatrix* matrix);
  /// Commanded angles (deg) for a desired point; false when out of reach or singular.
  bool command(const Vec2& p, double& t1_deg, double& t2_deg);

 private:
  FiveBar m_;
  ErrorMatrix e_;
  bool has_matrix_;
  double ref_[2];
  bool have_ref_ = false;
};

/// Joint commands (deg: theta1, theta2) for desired points, in order (the corrector's branch carried
/// from one to the next). A point out of reach or singular is an InputError "WHERE: (x, y) is out of
/// the hidden robot's reach", where(i) naming the i-th point (its row, or file:line).
std::vector<Vec2> fivebar_commands(const FiveBar& m, const ErrorMatrix* matrix, const std::vector<Vec2>& xy,
                                   const std::function<std::string(size_t)>& where);
/// fivebar_commands for the desired points of a CSV file (columns x, y in mm): errors name file:line.
std::vector<Vec2> fivebar_command_file(const FiveBar& m, const ErrorMatrix* matrix, const std::string& path);

std::string fivebar_to_json(const FiveBar& m);
FiveBar fivebar_from_json(const std::string& text, const std::string& source);

/// The over-constrained 6-bar A0ADCEB the hidden robot stands for (the truth of the simulations).
/// Fixed joints A0 = (-e/2, 0) and B0 = (e/2, 0); cranks a (A0A) and d (B0B); couplers b (AD) and
/// c (BE); the platform DE (length e) carries C at its middle. Each arm is doubled by a parallelogram
/// (companion links at distance h) that holds the platform's orientation; manufacturing errors of
/// the companions make the two sides want different platform angles, the over-constrained loop
/// settles between them and the links strain in proportion to the mismatch (pose-dependent link
/// lengths). Then joint clearance (a random offset of C up to `clearance`) and instrument noise.
struct SixBar {
  double a = 150, b = 150, c = 150, d = 150, e = 0;   ///< e = 0: the fixed joints are concurrent
  double h = 40;                                      ///< parallelogram companion distance
  double offset1_deg = 0, offset2_deg = 0;            ///< actuator zero errors
  std::array<double, 4> companion_error{};           ///< length errors of the 4 companion links (mm)
  double strain_b = 0, strain_c = 0;                  ///< coupler stretch per rad of angle mismatch (mm)
  double clearance = 0;                               ///< joint clearance at C (mm)
  /// Noise-free, clearance-free position of C for commanded angles (deg); false if it cannot close.
  bool position(double t1_deg, double t2_deg, Vec2& c, double* mismatch = nullptr) const;
  /// The coupler lengths at a pose (they change with the pose through the strain).
  void coupler_lengths(double t1_deg, double t2_deg, double& b_eff, double& c_eff) const;
};

/// Command every target through the hidden robot (and the error matrix when given), measure where
/// the truth goes: joint clearance (uniform in a disk) and Gaussian instrument noise per coordinate.
/// Targets the hidden robot cannot reach are skipped. Deterministic for a seed.
std::vector<FiveBarPoint> sixbar_campaign(const SixBar& truth, const FiveBar& model, const ErrorMatrix* matrix,
                                          const std::vector<Vec2>& targets, double noise_mm, unsigned seed);

/// The paper's-size truth: about 1.5 mm largest error of the nominal model over the Table I
/// workspace. Deterministic for a seed.
SixBar paper_sixbar(unsigned seed);

}  // namespace kincal
