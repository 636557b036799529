// kincal: the identification's residuals, of one row (its position and, for a 6-D row, its
// orientation, with their Jacobians from PointModel::predict) and of a whole measurement set, its rows
// spread over the process's thread pool.
#include "kincal/identify/point_model.hpp"

#include "../core/thread_pool.hpp"

#include "kincal/identify/so3.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <algorithm>
#include <vector>

namespace kincal {

int row_residuals(const PointState& pm, const Measurement& m, ResidualKind kind, double orientation_weight, double* r,
                  double* J, double* scratch) {
  const int P = pm.layout().size;
  if (is_probe(m.kind)) {  // along its constraint, the rest of its block zero
    pm.probe_residuals(m, residual_size(kind), r, J);
    return residual_size(kind);
  }
  // a reflector row among 6-D rows: its orientation rows are zero (no equation), the layout stays
  const bool orientation = kind == ResidualKind::pose && m.has_abc;
  Mat3 rot;
  std::vector<double> own;  // only when the caller gives no scratch
  if (J && orientation && !scratch) own.resize(3 * static_cast<size_t>(P)), scratch = own.data();
  const Vec3 y = pm.predict(m, J, orientation ? &rot : nullptr, (J && orientation) ? scratch : nullptr);
  for (int k = 0; k < 3; ++k) r[k] = y[k] - m.xyz[k];
  if (kind == ResidualKind::pose && !orientation) {
    for (int k = 3; k < 6; ++k) r[k] = 0;
    if (J) std::fill_n(J + 3 * static_cast<size_t>(P), 3 * static_cast<size_t>(P), 0.0);
    return 6;
  }
  if (!orientation) return 3;
  const Vec3 e = so3::log(abc_to_rotation(m.abc).transpose() * rot);
  for (int k = 0; k < 3; ++k) r[3 + k] = orientation_weight * e[k];
  if (J) {
    // e' = log(Rm^T Exp(w) R) ~ e + Jr^-1(e) R^T w. predict() wrote the 3 position rows at J, which
    // are already the top rows of the 6-row layout (row-major, P wide): only the bottom rows are new
    const Mat3 d = orientation_weight * so3::right_jacobian_inv(e) * rot.transpose();
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> W(scratch, 3, P);
    Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>> JJ(J, 6, P);
    JJ.bottomRows(3) = d * W;
  }
  return 6;
}

void all_residuals(const PointState& pm, const MeasurementSet& data, double orientation_weight,
                   const std::vector<int>& columns, double* r, double* J, size_t column_stride) {
  const ResidualKind kind = residual_kind(data);
  const size_t RS = residual_size(kind), P = pm.layout().size, F = columns.size(), n = data.rows.size();
  // every thread's scratch: a row's full Jacobian (6 x P) and its orientation part (3 x P)
  std::vector<double> scratch(J ? detail::pool_threads() * 9 * P : 0);
  detail::parallel_rows(n, detail::kRowsPerThread, [&](size_t begin, size_t end, size_t slot) {
    double* full = J ? &scratch[slot * 9 * P] : nullptr;
    double row_r[6];
    for (size_t i = begin; i < end; ++i) {
      row_residuals(pm, data.rows[i], kind, orientation_weight, r ? r + RS * i : row_r, full, full ? full + 6 * P : nullptr);
      if (J && column_stride == 0)
        for (size_t k = 0; k < RS; ++k)
          for (size_t c = 0; c < F; ++c) J[(RS * i + k) * F + c] = full[k * P + columns[c]];
      else if (J)
        for (size_t c = 0; c < F; ++c)
          for (size_t k = 0; k < RS; ++k) J[c * column_stride + RS * i + k] = full[k * P + columns[c]];
    }
  });
}

std::vector<double> row_errors(const PointState& pm, const MeasurementSet& data) {
  const size_t RS = residual_size(residual_kind(data));
  std::vector<double> r(RS * data.rows.size()), e(data.rows.size());
  all_residuals(pm, data, 0.0, {}, r.data(), nullptr);
  for (size_t i = 0; i < e.size(); ++i)
    e[i] = Eigen::Map<const Eigen::VectorXd>(&r[RS * i], position_equations(data.rows[i])).norm();
  return e;
}

}  // namespace kincal
