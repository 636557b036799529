// kincal: identification's priors and the data's noise scale (priors.hpp).
#include "kincal/identify/priors.hpp"

#include "kincal/identify/point_model.hpp"

#include "kincal/effects/effects.hpp"
#include "kincal/identify/identifiability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

namespace kincal {

Loss parse_loss(const std::string& word) {
  if (word == "none") return Loss::none;
  if (word == "huber") return Loss::huber;
  if (word == "cauchy") return Loss::cauchy;
  throw InputError("identify: unknown loss '" + word + "' (none, huber, cauchy)");
}

std::string loss_word(Loss loss) {
  switch (loss) {
    case Loss::none: return "none";
    case Loss::huber: return "huber";
    case Loss::cauchy: return "cauchy";
  }
  return "";
}

GravityTorques parse_gravity(const std::string& word) {
  if (word == "auto") return GravityTorques::automatic;
  if (word == "masses") return GravityTorques::masses;
  if (word == "fit") return GravityTorques::fit;
  throw InputError("identify: unknown gravity mode '" + word + "' (auto, masses, fit)");
}

std::string gravity_word(GravityTorques gravity) {
  switch (gravity) {
    case GravityTorques::automatic: return "auto";
    case GravityTorques::masses: return "masses";
    case GravityTorques::fit: return "fit";
  }
  return "";
}

std::vector<std::pair<std::string, double>> default_prior_sd() {
  const double deg = M_PI / 180.0;
  return {{"joint_mm", 1.0}, {"joint_rad", 0.1 * deg}, {"tool_mm", 5.0}, {"tool_rad", 1.0 * deg}};
}

bool any_prior(const std::vector<double>& sd) {
  return std::any_of(sd.begin(), sd.end(), [](double s) { return std::isfinite(s); });
}

std::vector<double> prior_sds(const ParamLayout& L, const IdentifyOptions& opt) {
  std::vector<double> sd(L.size, std::numeric_limits<double>::infinity());
  if (opt.prior_scale == 0) return sd;
  if (!(opt.prior_scale > 0) || !std::isfinite(opt.prior_scale))
    throw InputError("identify: the prior scale must be a positive number (0: no priors)");
  for (const auto& [kind, v] : opt.prior_sd) {
    if (!(v > 0) || !std::isfinite(v))
      throw InputError("identify: the prior standard deviation of '" + kind + "' must be a positive number");
    // the ranges of the kind: [first, last) and the unit its parameters have there ("": any)
    std::vector<std::tuple<int, int, std::string>> ranges;
    if (kind == "joint_mm" || kind == "joint_rad") ranges.emplace_back(L.joints, L.compliance, kind.substr(6));
    else if (kind == "compliance") ranges.emplace_back(L.compliance, L.moments, "");
    else if (kind == "tool_mm" || kind == "tool_rad") ranges.emplace_back(L.tool, L.base, kind.substr(5));
    else if (kind == "base_mm" || kind == "base_rad") ranges.emplace_back(L.base, L.targets, kind.substr(5));
    else if (kind == "target_mm") ranges.emplace_back(L.targets, L.effects, "");
    else {
      const auto& kinds = effect_kinds();
      if (std::none_of(kinds.begin(), kinds.end(), [&](const EffectKind& k) { return k.name == kind; }))
        throw InputError("identify: no prior kind '" + kind + "' (joint_mm, joint_rad, compliance, tool_mm, tool_rad, "
                         "base_mm, base_rad, target_mm or an effect's name)");
      for (size_t e = 0; e < L.effect_list.size(); ++e)
        if (L.effect_list[e].name == kind)
          ranges.emplace_back(L.effect_offset[e], L.effect_offset[e] + L.effect_list[e].size(), "");
    }
    for (const auto& [first, last, unit] : ranges)
      for (int i = first; i < last; ++i)
        if (unit.empty() || L.units[i] == unit) sd[i] = v * opt.prior_scale;
  }
  return sd;
}

std::vector<PenaltyTerm> prior_terms(const std::vector<double>& sd, const std::vector<double>& start,
                                     const std::vector<int>& free_idx, double noise_mm) {
  std::vector<PenaltyTerm> out;
  for (size_t k = 0; k < free_idx.size(); ++k)
    if (std::isfinite(sd[free_idx[k]]))
      out.push_back({static_cast<int>(k), noise_mm / sd[free_idx[k]], start[free_idx[k]]});
  return out;
}

double robust_noise(std::vector<double> v, std::size_t p) {
  if (v.empty()) return 1e-4;
  auto median = [](std::vector<double>& a) {
    std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
    return a[a.size() / 2];
  };
  const double m = median(v);
  for (double& e : v) e = std::abs(e - m);
  const double n = static_cast<double>(v.size());
  const double dof = std::max(1.0, n - static_cast<double>(p));
  return std::max(1e-4, 1.4826 * median(v) * std::sqrt(n / dof));
}

double loss_threshold(double noise_mm, int row_size) { return noise_mm * std::sqrt(row_size == 6 ? 22.458 : 16.266); }

/// The residuals' robust spread after a least-squares fit of the columns `determined`, from the
/// linearization at the start (one Gauss-Newton step: r - J (J^T J)^-1 J^T r).
double least_squares_noise(const Linearization& lin, const std::vector<int>& determined, const MeasurementSet& data,
                           int row_size) {
  const Eigen::Index n = static_cast<Eigen::Index>(lin.residuals.size());
  Eigen::MatrixXd J(n, static_cast<Eigen::Index>(determined.size()));
  for (size_t k = 0; k < determined.size(); ++k) J.col(static_cast<Eigen::Index>(k)) = lin.jacobian.col(determined[k]);
  const Eigen::Map<const Eigen::VectorXd> r(lin.residuals.data(), n);
  const Eigen::VectorXd step = (J.transpose() * J).ldlt().solve(J.transpose() * r);
  const Eigen::VectorXd after = r - J * step;
  std::vector<double> position;  // the data's rows (an artifact's terms follow them)
  for (size_t i = 0; i < data.rows.size(); ++i)
    for (int c = 0; c < position_equations(data.rows[i]); ++c)
      position.push_back(after[static_cast<Eigen::Index>(i) * row_size + c]);
  return robust_noise(position, determined.size());
}

}  // namespace kincal
