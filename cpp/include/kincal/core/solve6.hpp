// kincal: the 6 x 6 linear solves of Newton compensation (fixed sizes, inlined).
#pragma once

#include <cmath>

#include "kincal/model/model.hpp"

namespace kincal {

using Mat6r = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;  // row operations on contiguous memory

/// Solves a x = b in place (b becomes x) by Gaussian elimination with partial pivoting on the fixed
/// 6 x 6 system, its loops unrolled by the compiler (Eigen's general LU loops at run time); returns |det a|.
inline double solve6(Mat6r a, Vec6& b) {
  double det = 1;
#pragma GCC unroll 6
  for (int k = 0; k < 6; ++k) {
    int p = k;
    for (int i = k + 1; i < 6; ++i)
      if (std::abs(a(i, k)) > std::abs(a(p, k))) p = i;
    if (p != k) {
      a.row(k).swap(a.row(p));
      std::swap(b[k], b[p]);
    }
    const double piv = a(k, k);
    det *= piv;
    if (piv == 0) return 0;
    const double inv = 1 / piv;
#pragma GCC unroll 6
    for (int i = k + 1; i < 6; ++i) {
      const double l = a(i, k) * inv;
#pragma GCC unroll 6
      for (int j = k + 1; j < 6; ++j) a(i, j) -= l * a(k, j);
      b[i] -= l * b[k];
    }
  }
#pragma GCC unroll 6
  for (int k = 5; k >= 0; --k) {
    double v = b[k];
#pragma GCC unroll 6
    for (int j = k + 1; j < 6; ++j) v -= a(k, j) * b[j];
    b[k] = v / a(k, k);
  }
  return std::abs(det);
}

/// 3x3 inverse by cofactors (one division); returns the determinant.
inline double inverse3(const Mat3& a, Mat3& ai) {
  const double c00 = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1);
  const double c01 = a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2);
  const double c02 = a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0);
  const double det = a(0, 0) * c00 + a(0, 1) * c01 + a(0, 2) * c02;
  const double id = 1 / det;
  ai << c00 * id, (a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2)) * id, (a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)) * id,  //
      c01 * id, (a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0)) * id, (a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)) * id,     //
      c02 * id, (a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1)) * id, (a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)) * id;
  return det;
}

/// det(a)^2 against the product of its squared column norms (Hadamard's bound, 1 for orthogonal
/// columns): below 1e-8 the block is too near singular for elimination without pivoting. (At 1e-12 a
/// Schur complement computed with cancellation lost three digits against pivoting on a well
/// conditioned whole: 1.0e-9 relative at rcond 9e-4, seed 27 of BlockSolveMatchesPivotedLu; at 1e-8
/// the worst of seeds 1-60 is 4.7e-11. For a robot it moves the switch to pivoting from 1e-6 to
/// 1e-4 rad of the wrist's or the elbow's singularity.)
inline bool well_conditioned3(const Mat3& a, double det) {
  return det * det > 1e-8 * a.col(0).squaredNorm() * a.col(1).squaredNorm() * a.col(2).squaredNorm();
}

/// The factorisation of a Jacobian whose first three columns are the arm's and last three the
/// wrist's, by 3x3 blocks, kept for several right-hand sides: x_wrist from the Schur complement
/// S = D - C A^-1 B, then x_arm. Two divisions instead of six dependent eliminations (the solve is
/// latency-bound; BENCHMARKS.md has the figures). The rows should have the arm block A well
/// conditioned (the position of the wrist, see FactoredJacobian in compensation/pose.cpp); when A or
/// S is near singular, solve6's partial pivoting takes over (then each solve eliminates anew).
struct BlockSolver {
  Mat3 ai, g, c, si;  // A^-1, A^-1 B, C, S^-1
  Mat6r j;            // the matrix itself, when the blocks do not serve
  bool blocks = false;

  /// Returns |det j| (0 when singular).
  double factor(const Mat6r& jm) {
    const Mat3 a = jm.topLeftCorner<3, 3>();
    const double da = inverse3(a, ai);
    if (well_conditioned3(a, da)) {
      g = ai * jm.topRightCorner<3, 3>();
      c = jm.bottomLeftCorner<3, 3>();
      const Mat3 sc = jm.bottomRightCorner<3, 3>() - c * g;
      const double ds = inverse3(sc, si);
      if (well_conditioned3(sc, ds)) {
        blocks = true;
        return std::abs(da * ds);
      }
    }
    blocks = false;
    j = jm;
    Vec6 probe = Vec6::Zero();
    return solve6(j, probe);
  }

  /// b becomes x with j x = b.
  void solve(Vec6& b) const {
    if (!blocks) {
      solve6(j, b);
      return;
    }
    const Vec3 h = ai * b.head<3>();
    const Vec3 y = si * (b.tail<3>() - c * h);
    b.head<3>() = h - g * y;
    b.tail<3>() = y;
  }
};

/// Solves j x = b (b becomes x) by BlockSolver; returns |det j| (0 when singular, b then undefined).
inline double solve_blocks(const Mat6r& j, Vec6& b) {
  BlockSolver s;
  const double det = s.factor(j);
  if (det > 0) s.solve(b);
  return det;
}

}  // namespace kincal
