// kincal: the D-optimal design's gains (design.hpp).
#include "kincal/identify/design.hpp"

#include "../core/thread_pool.hpp"
#include "kincal/core/types.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <string>
#include <vector>

namespace kincal {

namespace {

using RowF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// log det of the symmetric positive definite matrix G (its lower triangle), by Cholesky; NaN when
/// it is not positive definite.
double logdet_spd(Eigen::MatrixXd& G) {
  const Eigen::Index r = G.rows();
  double out = 0;
  for (Eigen::Index k = 0; k < r; ++k) {
    double d = G(k, k);
    for (Eigen::Index j = 0; j < k; ++j) d -= G(k, j) * G(k, j);
    if (!(d > 0)) return std::nan("");
    const double s = std::sqrt(d);
    G(k, k) = s;
    out += std::log(d);
    for (Eigen::Index i = k + 1; i < r; ++i) {
      double v = G(i, k);
      for (Eigen::Index j = 0; j < k; ++j) v -= G(i, j) * G(k, j);
      G(i, k) = v / s;
    }
  }
  return out;
}

}  // namespace

void d_optimal_gains(const float* J, std::size_t n, int rows, int cols, const std::int64_t* idx, std::size_t m,
                     const float* L, float* out) {
  if (rows < 1 || cols < 1) throw InputError("d_optimal_gains: a candidate needs rows and columns");
  for (std::size_t k = 0; k < m; ++k)
    if (idx[k] < 0 || static_cast<std::size_t>(idx[k]) >= n)
      throw InputError("d_optimal_gains: candidate " + std::to_string(idx[k]) + " of " + std::to_string(n));
  const Eigen::Map<const RowF> Lm(L, cols, cols);
  const RowF Lt = Lm.triangularView<Eigen::Lower>();  // the upper part as zeros
  const std::size_t block = static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols);
  std::vector<int> bad(m, 0);
  detail::parallel_pieces(m, 256, 0, [&](std::size_t begin, std::size_t end, std::size_t) {
    RowF A(rows, cols);
    Eigen::MatrixXf Gf(rows, rows);
    Eigen::MatrixXd G(rows, rows);
    for (std::size_t k = begin; k < end; ++k) {
      const Eigen::Map<const RowF> Ji(J + static_cast<std::size_t>(idx[k]) * block, rows, cols);
      A.noalias() = Ji * Lt;
      Gf.noalias() = A * A.transpose();
      G = Gf.cast<double>();
      G.diagonal().array() += 1.0;
      const double g = logdet_spd(G);
      bad[k] = std::isnan(g);
      out[k] = static_cast<float>(g);
    }
  });
  for (std::size_t k = 0; k < m; ++k)
    if (bad[k])
      throw InputError("d_optimal_gains: candidate " + std::to_string(idx[k]) +
                       ": its block is not positive definite (a NaN in the Jacobian or in L)");
}

}  // namespace kincal
