// kincal: the identification's residuals, of one row (its position and, for a 6-D row, its
// orientation, with their Jacobians from PointModel::predict) and of a whole measurement set, its rows
// spread over the cores.
#include "kincal/identify/point_model.hpp"

#include "kincal/identify/so3.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace kincal {

int row_residuals(const PointModel& pm, const Measurement& m, ResidualKind kind, double orientation_weight, double* r,
                  double* J) {
  const int P = pm.layout().size;
  // a reflector row among 6-D rows: its orientation rows are zero (no equation), the layout stays
  const bool orientation = kind == ResidualKind::pose && m.has_abc;
  Mat3 rot;
  thread_local std::vector<double> jw;
  if (J && orientation) jw.resize(3 * static_cast<size_t>(P));
  const Vec3 y = pm.predict(m, J, orientation ? &rot : nullptr, (J && orientation) ? jw.data() : nullptr);
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
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> W(jw.data(), 3, P);
    Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>> JJ(J, 6, P);
    JJ.bottomRows(3) = d * W;
  }
  return 6;
}

namespace {

/// Run f(i) for i in [0, n) on all cores (rows are independent; PointModel::predict is const). An
/// exception stops its chunk and is rethrown once every thread is joined: the one of the first row
/// that failed, as in a serial loop.
template <class F>
void parallel_rows(size_t n, F&& f) {
  const size_t threads = std::min<size_t>(std::max(1u, std::thread::hardware_concurrency()), n / 256 + 1);
  if (threads <= 1) {
    for (size_t i = 0; i < n; ++i) f(i);
    return;
  }
  const size_t chunk = (n + threads - 1) / threads;
  std::vector<std::exception_ptr> errors(threads);
  auto run = [&](size_t t) {
    try {
      for (size_t i = t * chunk; i < std::min(n, (t + 1) * chunk); ++i) f(i);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (size_t t = 1; t < threads; ++t) pool.emplace_back(run, t);
  run(0);
  for (auto& th : pool) th.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace

void all_residuals(const PointModel& pm, const MeasurementSet& data, double orientation_weight,
                   const std::vector<int>& columns, double* r, double* J) {
  const ResidualKind kind = residual_kind(data);
  const size_t RS = residual_size(kind), P = pm.layout().size, F = columns.size();
  parallel_rows(data.rows.size(), [&](size_t i) {
    thread_local std::vector<double> full;
    if (J) full.resize(6 * P);
    double row_r[6];
    row_residuals(pm, data.rows[i], kind, orientation_weight, r ? r + RS * i : row_r, J ? full.data() : nullptr);
    if (J)
      for (size_t k = 0; k < RS; ++k)
        for (size_t c = 0; c < F; ++c) J[(RS * i + k) * F + c] = full[k * P + columns[c]];
  });
}

}  // namespace kincal
