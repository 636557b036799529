// kincal: identify(): the steps of the identification and the Ceres solve. With fivebar/fit.cpp one
// of the two translation units that include Ceres (builds stay quick).
#include "kincal/identify/identify.hpp"

#include "ceres_rows.hpp"
#include "fit_setup.hpp"

#include "kincal/identify/identifiability.hpp"
#include "kincal/identify/priors.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace kincal {

using namespace fit_setup;   // the checks and starts before Ceres runs
using namespace ceres_rows;  // the rows as Ceres reads them

namespace {

/// The penalty terms of the free parameters (towards zero); InputError for a name the layout does
/// not have or a weight that is negative or not finite.
std::vector<PenaltyTerm> penalty_terms(const ParamLayout& L, const std::vector<int>& free_idx,
                                       const IdentifyOptions& opt) {
  std::vector<PenaltyTerm> out;
  for (const auto& [name, w] : opt.penalties) {
    const auto it = std::find(L.names.begin(), L.names.end(), name);
    if (it == L.names.end()) throw InputError("identify: a penalty on '" + name + "', which is no parameter of the model");
    if (!(w >= 0) || !std::isfinite(w)) throw InputError("identify: the penalty on '" + name + "' must be finite and >= 0");
    const int i = static_cast<int>(it - L.names.begin());
    const auto f = std::find(free_idx.begin(), free_idx.end(), i);
    if (f != free_idx.end() && w > 0) out.push_back({static_cast<int>(f - free_idx.begin()), w, 0.0});
  }
  return out;
}


class Progress : public ceres::IterationCallback {
 public:
  explicit Progress(const std::function<void(int, double)>& f) : f_(f) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (f_) f_(s.iteration, s.cost);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(int, double)>& f_;
};

/// The robust loss of the options at a scale (mm); none when the scale is not positive.
std::unique_ptr<ceres::LossFunction> make_loss(const IdentifyOptions& opt, double scale_mm) {
  if (!(scale_mm > 0)) return nullptr;
  switch (opt.loss) {
    case Loss::huber: return std::make_unique<ceres::HuberLoss>(scale_mm);
    case Loss::cauchy: return std::make_unique<ceres::CauchyLoss>(scale_mm);
    case Loss::none: break;
  }
  return nullptr;
}

ceres::Problem::Options problem_options(AllRows& all) {
  ceres::Problem::Options popt;
  popt.evaluation_callback = &all;
  popt.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popt.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  return popt;
}

/// Whether a solve reports its iterations to IdentifyOptions::progress.
enum class Report { silent, progress };

/// Levenberg-Marquardt on the free parameters of all (written back into its x by finish()).
void solve(ceres::Problem& problem, AllRows& all, ceres::LossFunction* loss, const IdentifyOptions& opt,
           ceres::Solver::Summary& summary, Report report, const std::vector<PenaltyTerm>& penalties = {},
           double artifact_weight = 1.0) {
  // without a loss the rows' blocks are sized for the cache (a block's Jacobian about 32 KB)
  const size_t per_block =
      loss ? 1 : std::max<size_t>(1, 4096 / static_cast<size_t>(std::max(1, all.row_size() * all.size())));
  for (size_t i = 0; i < all.rows(); i += per_block)
    problem.AddResidualBlock(new RowCost(all, i, std::min(per_block, all.rows() - i)), loss, all.z());
  for (size_t k = 0; k < all.artifact_terms(); ++k)
    problem.AddResidualBlock(new ArtifactCost(all, k, artifact_weight), nullptr, all.z());
  if (!penalties.empty()) problem.AddResidualBlock(new PenaltyCost(penalties, all.size()), nullptr, all.z());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-14;
  so.num_threads = 1;
  Progress prog(opt.progress);
  if (report == Report::progress && opt.progress) so.callbacks.push_back(&prog);
  ceres::Solve(so, &problem, &summary);
  all.finish();
}

/// Target t of the parameter vector x.
Vec3 target_of(const ParamLayout& L, const std::vector<double>& x, int t) {
  return Vec3(x[L.targets + 3 * t], x[L.targets + 3 * t + 1], x[L.targets + 3 * t + 2]);
}

/// Stage 1: the base frame of every setup, the targets and the drift fitted on the nominal geometry
/// (the "before" of the summary, and a start where the targets are where they are, so that the
/// identifiability analysis sees the real geometry). x: from the start to the fitted frames.
/// start: the frames-only evaluation at x (PointModel::at_frames_only).
void fit_frames(const PointModel& pm, const PointState& start, const Model& nominal, const MeasurementSet& data,
                const IdentifyOptions& opt, std::vector<double>& x, IdentifyResult& res) {
  const ParamLayout& L = res.layout;
  std::vector<int> frames = frame_columns(L, data, res);
  for (int i = L.stations; i < L.size; ++i)  // the probe stations are the campaign's frames too
    if (!res.fixed[i]) frames.push_back(i);
  if (L.drift >= 0)  // the instrument's own motion belongs to the frames
    for (int i = L.drift; i < L.drift + 6; ++i)
      if (!res.fixed[i]) frames.push_back(i);
  ceres::Solver::Summary summary;
  // only the base and target columns are needed here: every row's flange frame computed once
  AllRows all(start, data, x, frames, opt.orientation_weight);
  ceres::Problem problem(problem_options(all));
  std::unique_ptr<ceres::LossFunction> loss = make_loss(opt, opt.loss_scale_mm);  // a scale from the data: none yet
  solve(problem, all, loss.get(), opt, summary, Report::silent);
  res.nominal_x = x;
  const PointState fitted = pm.at(x);
  res.nominal_fitted = fitted.spec();
  res.nominal_fitted.name = nominal.spec().name;
  res.nominal_campaign = fitted.campaign();
  if (L.drift >= 0) {  // the "before" model sees the points from the same drifting instrument
    res.nominal_campaign.drift = EffectValue{Effect{effect_kind(EffectId::drift).name, -1, {}},
                                             std::vector<double>(x.begin() + L.drift, x.begin() + L.drift + 6)};
    res.nominal_campaign.t_mean_s = L.t_mean;
  }
  for (int t = 0; t < data.n_targets; ++t) res.nominal_targets.push_back(target_of(L, x, t));
  res.nominal_stations = fitted.stations();
  // every row's error at the fitted frames (row_errors' figure): the frames-only rows at that point,
  // whose flange frames are those of the fitted model unless the fit moved the tool (6-D rows: the
  // payload's centre of mass moves with it, and with it the gravity torque)
  std::vector<double> errors;
  if (data.orientation) {
    errors = row_errors(fitted, data);
  } else {
    all.refresh();
    for (size_t i = 0; i < data.rows.size(); ++i)
      errors.push_back(Eigen::Map<const Eigen::VectorXd>(all.residual(i), position_equations(data.rows[i])).norm());
  }
  double ss = 0;
  for (double e : errors) {
    ss += e * e;
    res.nominal_max_mm = std::max(res.nominal_max_mm, e);
  }
  res.nominal_rms_mm = std::sqrt(ss / data.rows.size());
}

/// The solution x into res: the calibrated model (carrying every identified effect), the targets,
/// the effects' values and the errors on the fitted rows.
void store_solution(const PointModel& pm, const Model& nominal, const MeasurementSet& data, const std::vector<double>& x,
                    IdentifyResult& res) {
  const ParamLayout& L = res.layout;
  res.x = x;
  const PointState solution = pm.at(x);
  res.calibrated = solution.spec();
  res.campaign = solution.campaign();
  res.calibrated.name = nominal.spec().name + "-calibrated";
  // 6-D rows measured the tool frame; reflectors alone leave it where it started (redundant with
  // their offsets): every pose then carries the tool's error
  res.calibrated.tcp = data.orientation ? "measured" : "nominal";
  for (int t = 0; t < data.n_targets; ++t) res.targets.push_back(target_of(L, x, t));
  res.stations = solution.stations();
  res.t_ref = L.t_ref;
  for (size_t e = 0; e < L.effect_list.size(); ++e) {
    const auto first = x.begin() + L.effect_offset[e];
    res.effects.push_back({L.effect_list[e], std::vector<double>(first, first + L.effect_list[e].size())});
  }
  // the model carries every identified effect of the robot, the campaign the instrument's drift
  res.calibrated.effects.clear();
  for (const EffectValue& ev : res.effects) {
    if (ev.effect.kind().of_instrument())
      res.campaign.drift = ev;
    else
      res.calibrated.effects.push_back(ev);
  }
  res.calibrated.t_ref_c = L.t_ref;
  res.campaign.t_mean_s = L.t_mean;
  // a probe row's error is along its constraint, with the campaign's stations (not in the model)
  const std::vector<double> e = point_errors(Model(res.calibrated), res.campaign, res.targets, data, res.stations);
  double ss = 0;
  for (double v : e) ss += v * v, res.max_mm = std::max(res.max_mm, v);
  res.rms_mm = std::sqrt(ss / e.size());
}

/// Standard deviations of the free parameters (the others NaN) and their correlations above
/// opt.correlation_threshold: (J^T J)^-1 from the SVD of the loss-weighted Jacobian (as Ceres's DENSE_SVD
/// covariance, left NaN when near rank deficient, without its error line on stderr) times the noise.
void covariance(ceres::Problem& problem, AllRows& all, const ceres::Solver::Summary& summary,
                const std::vector<int>& free_idx, const IdentifyOptions& opt, IdentifyResult& res) {
  res.stddev.assign(res.layout.size, std::nan(""));
  if (!opt.covariance) return;
  ceres::Problem::EvaluateOptions eo;  // the free parameters only
  eo.parameter_blocks = {all.z()};
  ceres::CRSMatrix crs;
  all.exact_only();  // the Jacobian at the solution itself, not one a chord step carried over
  if (!problem.Evaluate(eo, nullptr, nullptr, nullptr, &crs)) return;
  const int F = static_cast<int>(free_idx.size()), nres = all.row_size() * static_cast<int>(all.rows());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r)
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) J(r, crs.cols[k]) = crs.values[k];
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();  // reciprocal condition at least 1e-14
  if (sv.size() < F || !(sv(F - 1) * sv(F - 1) >= 1e-14 * sv(0) * sv(0))) return;
  Eigen::MatrixXd C = svd.matrixV() * sv.cwiseInverse().cwiseAbs2().asDiagonal() * svd.matrixV().transpose();
  // with priors the cost weighs them by the estimated noise: the posterior covariance is noise^2 (J^T J)^-1
  C *= res.noise_mm > 0 ? res.noise_mm * res.noise_mm : 2.0 * summary.final_cost / std::max(1, nres - F);
  for (int a = 0; a < F; ++a) res.stddev[free_idx[a]] = std::sqrt(std::max(0.0, C(a, a)));
  for (int a = 0; a < F; ++a)
    for (int b = a + 1; b < F; ++b) {
      const double r = C(a, b) / std::sqrt(C(a, a) * C(b, b));
      if (std::abs(r) >= opt.correlation_threshold)
        res.correlations.push_back({res.layout.names[free_idx[a]], res.layout.names[free_idx[b]], r});
    }
}

/// The stage-2 solves: each a Levenberg-Marquardt run on a set of free parameters from the current
/// x, at a loss scale (0: least squares), with the options' penalties and the priors given. The
/// last problem stays for the covariance.
class Stage2 {
 public:
  Stage2(const PointModel& pm, const MeasurementSet& data, std::vector<double>& x, const IdentifyOptions& opt,
         const IdentifyResult& res)
      : pm_(pm), data_(data), x_(x), opt_(opt), res_(res) {}
  /// start: the linearization at x when x is the start (its first evaluation reused).
  void solve(const std::vector<int>& free_idx, const Linearization* start, double scale_mm,
             std::vector<PenaltyTerm> priors, double artifact_weight = 1.0) {
    problem_.reset();  // before the rows and the loss it refers to
    all_ = std::make_unique<AllRows>(pm_.at(x_), data_, x_, free_idx, opt_.orientation_weight, AllRows::Columns::every);
    if (start) all_->seed(*start);
    loss_ = make_loss(opt_, scale_mm);
    scale_ = loss_ ? scale_mm : 0.0;
    problem_ = std::make_unique<ceres::Problem>(problem_options(*all_));
    std::vector<PenaltyTerm> terms = penalty_terms(res_.layout, free_idx, opt_);
    terms.insert(terms.end(), priors.begin(), priors.end());
    free_ = free_idx;
    kincal::solve(*problem_, *all_, loss_.get(), opt_, summary, Report::progress, terms, artifact_weight);
    if (first_) initial_cost = summary.initial_cost, first_ = false;
    iterations += static_cast<int>(summary.iterations.size()) - 1;
    chord_steps += all_->chord_steps;
    ++passes_;
    // the first pass that did not converge is what the result reports (a later one converging from
    // a point it left unfinished does not make the whole fit converged)
    if (!unconverged_.empty()) return;
    if (summary.termination_type != ceres::CONVERGENCE) {
      unconverged_pass_ = passes_;
      unconverged_ = ceres::TerminationTypeToString(summary.termination_type);
      max_iterations_ = opt_.max_iterations;
      message_ = summary.message;
    }
  }
  /// Every pass converged; the reason of the final pass or of the first one that did not (n: the
  /// number of passes run).
  bool converged() const { return passes_ > 0 && unconverged_.empty(); }
  std::string stop_reason() const {
    if (converged()) return std::string(ceres::TerminationTypeToString(summary.termination_type)) + ": " + summary.message;
    if (passes_ == 0) return "NO_CONVERGENCE: no solve ran";
    std::string which = passes_ > 1 ? "pass " + std::to_string(unconverged_pass_) + " of " + std::to_string(passes_) : "the fit";
    const bool cap = unconverged_ == std::string("NO_CONVERGENCE") &&
                     message_.find("Maximum number of iterations") != std::string::npos;
    if (cap) return unconverged_ + ": " + which + " stopped at its cap of " + std::to_string(max_iterations_) +
                    " iterations (" + message_ + ")";
    return unconverged_ + ": " + which + " stopped: " + message_;
  }
  /// The robust noise of the residuals at the solution, p parameters determined by the data.
  double noise(size_t p) {
    all_->refresh();
    std::vector<double> position;
    position.reserve(3 * all_->rows());
    for (size_t i = 0; i < all_->rows(); ++i)
      position.insert(position.end(), all_->residual(i), all_->residual(i) + position_equations(data_.rows[i]));
    return robust_noise(position, p);
  }
  int row_size() const { return residual_size(residual_kind(data_)); }
  double scale() const { return scale_; }
  const std::vector<int>& free() const { return free_; }
  ceres::Problem& problem() { return *problem_; }
  AllRows& rows() { return *all_; }
  ceres::Solver::Summary summary;
  int iterations = 0, chord_steps = 0;
  double initial_cost = 0;

 private:
  const PointModel& pm_;
  const MeasurementSet& data_;
  std::vector<double>& x_;
  const IdentifyOptions& opt_;
  const IdentifyResult& res_;
  std::unique_ptr<AllRows> all_;
  std::unique_ptr<ceres::LossFunction> loss_;
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<int> free_;
  double scale_ = 0;
  bool first_ = true;
  int passes_ = 0, unconverged_pass_ = 0, max_iterations_ = 0;
  std::string unconverged_, message_;  // the first pass that did not converge: its termination, message
};

}  // namespace

IdentifyResult identify(const Model& nominal, const MeasurementSet& all_data, const IdentifyOptions& opt,
                        const Campaign& reference) {
  check_rows(nominal, all_data);
  MeasurementSet copy;
  const MeasurementSet& data = measured_artifact(all_data, copy);
  const std::vector<Effect> effects = effects_to_identify(nominal, opt);
  check_effect_columns(nominal, data, effects);
  const double t_ref = reference_temperature(nominal, data, effects);
  const double t_mean = reference_time(data, effects);
  const bool fit_gravity = opt.compliance && gravity_fitted(nominal, opt.gravity);
  LayoutOptions lo(data.n_targets, effects, t_ref, data.setup_names, t_mean, fit_gravity);
  lo.station_names = data.station_names;
  lo.station_kinds = data.station_kinds;
  lo.target_start = opt.target_start;
  const PointModel pm(nominal, lo, &data, reference);
  IdentifyResult res(pm.layout());
  res.start = pm.start(data, opt.target_start);
  res.fixed.assign(res.layout.size, false);
  res.fixed_reason.assign(res.layout.size, "");
  start_carried_effects(nominal, opt, res);
  fix_unobservable(nominal, data, opt, res);
  std::vector<double> x = res.start;
  // stage 1: the frames on the nominal geometry; then what the data cannot determine is held (or,
  // with priors, left to them)
  const PointState frames_only = pm.at_frames_only(x, data);  // every row's flange frame once
  hold_unseen_frames(pm, frames_only, data, opt, res);
  res.prior_sd = prior_sds(res.layout, opt);
  // without priors (and the gravity's moments not fitted) a probe campaign with known lengths is
  // judged where its touches alone put the frames (fix_unidentifiable)
  Touches touches;
  const bool priors = any_prior(res.prior_sd);
  const bool by_touches = !priors && !res.layout.fit_gravity && data.has_probe() && without_lengths(data, touches.rows);
  if (by_touches) {
    IdentifyResult scratch = res;
    touches.at = x;
    fit_frames(pm, frames_only, nominal, touches.rows, opt, touches.at, scratch);
  }
  fit_frames(pm, frames_only, nominal, data, opt, x, res);
  const Linearization at_start =
      fix_unidentifiable(pm, nominal, data, x, opt, res, res.prior_sd, by_touches ? &touches : nullptr);
  const std::vector<int> free_idx = free_parameters(data, res, res.prior_sd);
  // stage 2: everything identifiable, its first evaluation the linearization at the start
  Stage2 s2(pm, data, x, opt, res);
  if (!(opt.artifact_sd_mm >= 0) || !std::isfinite(opt.artifact_sd_mm))
    throw InputError("identify: the artifact's uncertainty must be a finite number of mm >= 0 (0: as a row's)");
  const bool weighed_artifact = opt.artifact_sd_mm > 0 && !data.artifact.empty();  // needs the noise
  if (!priors && !weighed_artifact && (opt.loss_scale_mm > 0 || opt.loss == Loss::none)) {
    s2.solve(free_idx, &at_start, opt.loss_scale_mm, {});
  } else {
    // the noise from a least-squares start on what the data determine (one Gauss-Newton step from the
    // linearization at the start: the model is nearly linear over the errors of a real robot); then
    // the robust (maximum a posteriori) fit at the data's scale; the noise re-estimated once from it
    std::vector<int> determined;
    for (int i : free_idx)
      if (!res.at_prior[i]) determined.push_back(i);
    if (!(opt.noise_mm >= 0) || !std::isfinite(opt.noise_mm))
      throw InputError("identify: the noise must be a finite number of mm >= 0 (0: estimated from the residuals)");
    res.noise_mm = opt.noise_mm > 0 ? opt.noise_mm : least_squares_noise(at_start, determined, data, s2.row_size());
    for (int pass = 0; pass < 2; ++pass) {
      const double scale = opt.loss_scale_mm > 0 ? opt.loss_scale_mm : loss_threshold(res.noise_mm, s2.row_size());
      s2.solve(free_idx, pass == 0 ? &at_start : nullptr, opt.loss == Loss::none ? 0.0 : scale,
               prior_terms(res.prior_sd, res.start, free_idx, res.noise_mm),
               weighed_artifact ? res.noise_mm / opt.artifact_sd_mm : 1.0);
      if (pass == 1 || opt.noise_mm > 0) break;  // a noise given is not re-estimated
      // res.noise_mm stays the one the final solve weighed the priors and set the loss with
      const double again = s2.noise(determined.size());
      if (std::abs(again / res.noise_mm - 1) < 0.02) break;
      res.noise_mm = again;
    }
  }
  res.loss_scale_mm = s2.scale();
  res.iterations = s2.iterations;
  res.chord_steps = s2.chord_steps;
  res.initial_cost = s2.initial_cost;
  res.final_cost = s2.summary.final_cost;
  res.termination = s2.summary.BriefReport();
  res.converged = s2.converged();
  res.stop_reason = s2.stop_reason();
  store_solution(pm, nominal, data, x, res);
  // the joint ranges the starting campaign recorded stay with the refitted one (its caller records new ones)
  res.campaign.fitted_deg = res.nominal_campaign.fitted_deg = reference.fitted_deg;
  // the observability figures at the solution: the stage-2 rows' Jacobian there when it is at hand
  observability(pm, data, opt, res, s2.free() == free_idx ? s2.rows().jacobian_here() : nullptr);
  if (s2.free() == free_idx) covariance(s2.problem(), s2.rows(), s2.summary, free_idx, opt, res);
  else res.stddev.assign(res.layout.size, std::nan(""));
  return res;
}

}  // namespace kincal
