// kincal (private, identify.cpp only): what Ceres reads of the identification's rows. AllRows
// evaluates every row once per point Ceres asks for (on the thread pool) and keeps the residuals and
// the Jacobian; the cost functions copy their part of them.
#pragma once

#include "fit_setup.hpp"

#include "kincal/identify/identifiability.hpp"
#include "kincal/identify/point_model.hpp"
#include "kincal/identify/priors.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <vector>

namespace kincal::ceres_rows {

/// The Gauss-Newton tail, where a step's Jacobian serves the next point too (for one step): the
/// residuals moved by less than this fraction of their norm (the raw residuals, before a robust
/// loss's weights) since it was evaluated. Measured on kincal bench's kr500 campaign (1000 poses) and
/// the UR10's series B, least squares and the defaults: the steps before the last moved the residuals
/// by 0.016-2.4 of their norm, the last (after which the Jacobian of the step before is kept) by
/// 5.6e-5-3.6e-4. A chord step converges to where the carried-over Jacobian's gradient vanishes; the
/// fits still end where a Gauss-Newton step with a Jacobian computed afresh moves the points by under
/// 1e-6 mm (tests/python/test_identify.py, test_the_fit_stops_at_the_optimum).
constexpr double kChordTail = 1e-3;

/// Fills residuals and Jacobians of every row once per evaluation point (the cost functions read).
class AllRows : public ceres::EvaluationCallback {
 public:
  /// x: the full parameter vector (held values stay, free ones are written back by finish());
  /// Ceres sees only the free parameters (z), so no manifold is needed.
  /// base: the measurement model at some parameters (its mode: full, or the frames alone).
  /// Columns::every: the rows' Jacobian is kept for every parameter (RowCost hands Ceres the free
  /// columns), so that the one at the solution serves the observability figures too.
  enum class Columns { free, every };
  AllRows(PointState base, const MeasurementSet& d, std::vector<double>& x, std::vector<int> free_idx, double weight,
          Columns kept = Columns::free)
      : state_(std::move(base)), d_(d), x_(x), free_(std::move(free_idx)), F_(static_cast<int>(free_.size())),
        RS_(residual_size(residual_kind(d))), w_(weight), r_(RS_ * d.rows.size()), ar_(d.artifact.size()),
        aj_(d.artifact.size() * F_) {
    for (int i : free_) z_.push_back(x_[i]);
    if (kept == Columns::every) {
      for (int i = 0; i < static_cast<int>(x.size()); ++i) kept_.push_back(i);
      at_col_ = free_;
    } else {
      kept_ = free_;
      for (int k = 0; k < F_; ++k) at_col_.push_back(k);
    }
    K_ = static_cast<int>(kept_.size());
    j_.resize(RS_ * d.rows.size() * K_);
  }
  void PrepareForEvaluation(bool jacobians, bool /*new_point*/) override {
    // rows already evaluated at this very point (Ceres's repeated calls, or the seed) are kept (a
    // Jacobian carried over from the point before only while carrying over is allowed)
    if (valid_ && z_ == at_ && (!jacobians || (have_j_ && (j_exact_ || !exact_only_)))) return;
    // the Jacobian asked for at a point whose residuals are at hand (a step Ceres just accepted): in
    // the Gauss-Newton tail, where the residuals moved by less than kChordTail of their norm since the
    // point the Jacobian was computed at, that Jacobian serves here too, for one step (a chord step:
    // the next step is taken with it, and judged by residuals computed afresh; the Jacobian after it
    // is computed again)
    if (jacobians && valid_ && z_ == at_ && j_exact_ && !exact_only_ && in_tail()) {
      j_at_ = z_;
      have_j_ = true;
      j_exact_ = false;
      ++chord_steps;
      return;
    }
    for (int k = 0; k < F_; ++k) x_[free_[k]] = z_[k];
    state_ = state_.with_params(x_);
    all_residuals(state_, d_, w_, kept_, r_.data(), jacobians ? j_.data() : nullptr);
    if (jacobians) j_at_ = z_, r_of_j_ = r_, j_exact_ = true;
    std::vector<double> grad(jacobians ? x_.size() : 0);
    for (size_t k = 0; k < d_.artifact.size(); ++k) {
      ar_[k] = state_.artifact_residual(d_.artifact[k], jacobians ? grad.data() : nullptr);
      if (jacobians)
        for (int c = 0; c < F_; ++c) aj_[k * F_ + c] = grad[free_[c]];
    }
    valid_ = true;
    have_j_ = jacobians;
    at_ = z_;
  }
  /// Rows already evaluated at the start point (the residuals and the Jacobian of every parameter,
  /// at the same x): the first evaluation reuses them.
  void seed(const Linearization& start) {
    const size_t n = RS_ * d_.rows.size();
    for (size_t i = 0; i < n; ++i) {
      r_[i] = start.residuals[i];
      for (int k = 0; k < K_; ++k) j_[i * K_ + k] = start.jacobian(static_cast<Eigen::Index>(i), kept_[k]);
    }
    for (size_t a = 0; a < ar_.size(); ++a) {  // the artifact's terms follow the rows
      ar_[a] = start.residuals[n + a];
      for (int k = 0; k < F_; ++k) aj_[a * F_ + k] = start.jacobian(static_cast<Eigen::Index>(n + a), free_[k]);
    }
    valid_ = have_j_ = j_exact_ = true;
    at_ = j_at_ = z_;
    r_of_j_ = r_;
  }
  /// From now on every Jacobian is computed at the point it serves (the covariance's).
  void exact_only() { exact_only_ = true; }
  /// The steps Ceres took with the Jacobian of the point before (chord steps).
  int chord_steps = 0;
  void finish() {
    for (int k = 0; k < F_; ++k) x_[free_[k]] = z_[k];
  }
  /// The residuals at the current point (Ceres's last evaluation may have been a rejected step).
  void refresh() { PrepareForEvaluation(false, true); }
  double* z() { return z_.data(); }
  const double* residual(size_t i) const { return &r_[RS_ * i]; }
  /// The free columns of the Jacobian's residuals RS_ * first .. RS_ * first + count - 1, into out (row-major).
  void jacobian(size_t first, size_t count, double* out) const {
    const double* in = &j_[RS_ * first * K_];
    if (K_ == F_) {
      std::copy_n(in, count * F_, out);
      return;
    }
    for (size_t r = 0; r < count; ++r, in += K_, out += F_)
      for (int k = 0; k < F_; ++k) out[k] = in[at_col_[k]];
  }
  /// The rows' Jacobian of every parameter (row-major, a row per residual; Columns::every) that
  /// served at the current point (evaluated there, or after a chord step at the point before: its
  /// residuals within kChordTail of these), else null.
  const double* jacobian_here() const {
    return K_ == static_cast<int>(x_.size()) && j_at_ == z_ ? j_.data() : nullptr;
  }
  double artifact_residual(size_t k) const { return ar_[k]; }
  const double* artifact_jacobian(size_t k) const { return &aj_[k * F_]; }
  size_t artifact_terms() const { return ar_.size(); }
  int row_size() const { return RS_; }
  int size() const { return F_; }
  size_t rows() const { return d_.rows.size(); }

 private:
  PointState state_;  ///< the model at the last evaluation's point
  const MeasurementSet& d_;
  std::vector<double>& x_;
  std::vector<int> free_;
  int F_, RS_, K_ = 0;
  double w_;
  std::vector<double> z_, r_, j_, at_;  // at_: the point r_ (and j_ if have_j_) were evaluated at
  std::vector<int> kept_;               // the parameters of j_'s K_ columns
  std::vector<int> at_col_;             // the free parameter k's column in j_
  std::vector<double> j_at_;            // the point j_ serves (evaluated there, or a tail step away)
  std::vector<double> r_of_j_;          // the residuals where j_ was evaluated
  bool j_exact_ = false;                // j_ was evaluated at j_at_ (not carried over by a chord step)
  bool exact_only_ = false;             // no chord steps any more (exact_only())

  /// Whether the residuals at hand moved by less than kChordTail of their norm from those where the
  /// Jacobian was evaluated.
  bool in_tail() const {
    if (r_of_j_.size() != r_.size() || ar_.size() > 0) return false;  // (an artifact's terms: always afresh)
    double moved = 0, norm = 0;
    for (size_t i = 0; i < r_.size(); ++i) {
      moved += (r_[i] - r_of_j_[i]) * (r_[i] - r_of_j_[i]);
      norm += r_[i] * r_[i];
    }
    return moved <= kChordTail * kChordTail * norm;
  }
  std::vector<double> ar_, aj_;         // the artifact's terms and their Jacobian rows
  bool valid_ = false, have_j_ = false;
};

/// Rows first .. first + count - 1 as one residual block (one row each under a robust loss, which
/// bends a row's distance; without one, blocks of rows sized for the cache).
class RowCost : public ceres::CostFunction {
 public:
  RowCost(const AllRows& all, size_t first, size_t count) : all_(all), i_(first) {
    set_num_residuals(all.row_size() * static_cast<int>(count));
    mutable_parameter_block_sizes()->push_back(all.size());
  }
  bool Evaluate(double const* const*, double* residuals, double** jacobians) const override {
    std::copy_n(all_.residual(i_), num_residuals(), residuals);
    if (jacobians && jacobians[0]) all_.jacobian(i_, static_cast<size_t>(num_residuals()), jacobians[0]);
    return true;
  }

 private:
  const AllRows& all_;
  size_t i_;
};

/// A known length or angle of the artifact (the --artifact file): one residual, no robust loss.
class ArtifactCost : public ceres::CostFunction {
 public:
  ArtifactCost(const AllRows& all, size_t k, double weight) : all_(all), k_(k), w_(weight) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(all.size());
  }
  bool Evaluate(double const* const*, double* residuals, double** jacobians) const override {
    residuals[0] = w_ * all_.artifact_residual(k_);
    if (jacobians && jacobians[0]) {
      const double* g = all_.artifact_jacobian(k_);
      for (int i = 0; i < all_.size(); ++i) jacobians[0][i] = w_ * g[i];
    }
    return true;
  }

 private:
  const AllRows& all_;
  size_t k_;
  double w_;
};

/// Ridge penalties and Gaussian priors: residual w_k (z_k - m_k) for the free parameters that carry one.
class PenaltyCost : public ceres::CostFunction {
 public:
  PenaltyCost(std::vector<PenaltyTerm> terms, int size) : terms_(std::move(terms)), size_(size) {
    set_num_residuals(static_cast<int>(terms_.size()));
    mutable_parameter_block_sizes()->push_back(size);
  }
  bool Evaluate(double const* const* z, double* residuals, double** jacobians) const override {
    for (size_t i = 0; i < terms_.size(); ++i) residuals[i] = terms_[i].weight * (z[0][terms_[i].index] - terms_[i].mean);
    if (jacobians && jacobians[0]) {
      std::fill_n(jacobians[0], terms_.size() * size_, 0.0);
      for (size_t i = 0; i < terms_.size(); ++i) jacobians[0][i * size_ + terms_[i].index] = terms_[i].weight;
    }
    return true;
  }

 private:
  std::vector<PenaltyTerm> terms_;
  int size_;
};

}  // namespace kincal::ceres_rows
