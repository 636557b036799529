// kincal: the priors of identification (maximum a posteriori) and the data's own noise scale: the
// prior standard deviation of every parameter from the options' kinds, the prior terms of a solve,
// the residuals' robust spread and the robust loss's scale from it.
#pragma once

#include "kincal/io/measurements.hpp"

#include "kincal/identify/identify.hpp"

#include <cstddef>
#include <vector>

namespace kincal {

/// A penalty on one free parameter: the residual weight * (z[index] - mean).
struct PenaltyTerm {
  int index;  ///< among the free parameters
  double weight, mean;
};

/// The prior standard deviation of every parameter of the layout (opt.prior_sd by kind times
/// opt.prior_scale; infinity for the kinds not named, or for all with prior_scale 0). InputError for
/// an unknown kind or a standard deviation or scale that is not a positive finite number.
std::vector<double> prior_sds(const ParamLayout& L, const IdentifyOptions& opt);

/// Whether any parameter has a prior (a finite standard deviation of prior_sds).
bool any_prior(const std::vector<double>& sd);

/// The prior terms of the free parameters that have one, centred on the start: weight noise / sd
/// (the data's residuals weigh 1 / noise, so the cost is the negative log posterior times noise^2).
std::vector<PenaltyTerm> prior_terms(const std::vector<double>& sd, const std::vector<double>& start,
                                     const std::vector<int>& free_idx, double noise_mm);

/// The residuals' robust spread per coordinate (mm): 1.4826 x the median absolute deviation of the
/// position components given, corrected for the p parameters the data determine (sqrt(n / (n - p))),
/// at least 0.1 um (no instrument measures better; noise-free data keep the priors and the loss finite).
double robust_noise(std::vector<double> position, std::size_t p);

/// Where the robust loss bends on a row's residual norm for a noise per coordinate: the 99.9% point
/// of the norm of Gaussian noise (the square root of the chi-square quantile: 3 components 4.03, 6
/// components 4.74). The loss is for gross errors (a broken beam, a wrong reflector), far beyond it;
/// a real robot's unmodelled error is heavy-tailed (UR10 series B, least-squares fit: 9.0% of the rows
/// beyond 2.80 x the noise, against 4.9% for Gaussian noise; 1.5% beyond 4.03 x, against 0.1%) and
/// belongs to the fit. Held out there (grouped 5-fold), the 95% point was 0.011% worse than no robust
/// loss, this one 0.003% better: differences at the resolution of that measure.
double loss_threshold(double noise_mm, int row_size);

struct Linearization;

/// The residuals' robust spread after a least-squares fit of the columns `determined`, from the
/// linearization at the start (one Gauss-Newton step: r - J (J^T J)^-1 J^T r) of data, row_size
/// residuals per row, of each the position components that carry an equation (position_equations).
double least_squares_noise(const Linearization& lin, const std::vector<int>& determined, const MeasurementSet& data,
                           int row_size);

}  // namespace kincal
