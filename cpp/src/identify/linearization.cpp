// kincal: the data's linearization at a parameter vector and the normal matrix of a Jacobian
// (linearization.hpp), for the identifiability analysis and the observability figures.
#include "linearization.hpp"

#include "../core/thread_pool.hpp"

#include <algorithm>
#include <numeric>
#include <vector>

namespace kincal {

namespace detail {

/// J^T J with only its lower triangle filled (half the work of the product; what a self-adjoint
/// solver reads). A tall J in pieces of kNormalPiece rows on the thread pool, their products summed in
/// order (the same sums whatever the number of cores).
Eigen::MatrixXd normal_matrix_lower(const Eigen::MatrixXd& j) {
  constexpr Eigen::Index kNormalPiece = 1024;
  const Eigen::Index rows = j.rows(), cols = j.cols(), pieces = (rows + kNormalPiece - 1) / kNormalPiece;
  if (pieces <= 1) {
    Eigen::MatrixXd n = Eigen::MatrixXd::Zero(cols, cols);
    n.selfadjointView<Eigen::Lower>().rankUpdate(j.transpose());
    return n;
  }
  std::vector<Eigen::MatrixXd> part(static_cast<size_t>(pieces), Eigen::MatrixXd::Zero(cols, cols));
  parallel_pieces(static_cast<size_t>(pieces), 1, 0, [&](size_t begin, size_t end, size_t) {
    for (size_t p = begin; p < end; ++p) {
      const Eigen::Index first = static_cast<Eigen::Index>(p) * kNormalPiece;
      part[p].selfadjointView<Eigen::Lower>().rankUpdate(j.middleRows(first, std::min(kNormalPiece, rows - first)).transpose());
    }
  });
  for (size_t p = 1; p < part.size(); ++p) part[0].triangularView<Eigen::Lower>() += part[p];
  return part[0];
}

/// The Jacobian of every parameter and the residuals of data at x.
Linearization linearize(const PointModel& pm, const MeasurementSet& data, const std::vector<double>& x, double weight) {
  const PointState at_x = pm.at(x);
  const int P = pm.layout().size;
  const size_t n = residual_size(residual_kind(data)) * data.rows.size();
  std::vector<int> every(P);
  std::iota(every.begin(), every.end(), 0);
  Linearization lin;
  lin.residuals.assign(n, 0.0);
  // the artifact's known lengths and angles follow the rows, one residual each
  const Eigen::Index rows = static_cast<Eigen::Index>(n);
  lin.jacobian.resize(rows + static_cast<Eigen::Index>(data.artifact.size()), P);
  all_residuals(at_x, data, weight, every, lin.residuals.data(), lin.jacobian.data(),
                static_cast<size_t>(lin.jacobian.rows()));
  std::vector<double> grad(static_cast<size_t>(P));
  for (size_t k = 0; k < data.artifact.size(); ++k) {
    lin.residuals.push_back(at_x.artifact_residual(data.artifact[k], grad.data()));
    for (int c = 0; c < P; ++c) lin.jacobian(rows + static_cast<Eigen::Index>(k), c) = grad[static_cast<size_t>(c)];
  }
  return lin;
}

}  // namespace detail

}  // namespace kincal
