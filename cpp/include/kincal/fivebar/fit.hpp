// kincal: the hidden robot's four lengths fitted by nonlinear least squares. This is part of
// kincal::identify (it needs Ceres), so it is declared apart from fivebar.hpp, whose functions
// kincal::core defines: a user of kincal::core alone includes nothing it cannot link.
#pragma once

#include "kincal/fivebar/fivebar.hpp"

#include <vector>

namespace kincal {

/// Beyond the paper: the four lengths fitted to the measured positions by nonlinear least squares
/// (Ceres, analytic Jacobian), from `start`. rms: the fit's RMS distance (mm).
FiveBar fivebar_fit_nonlinear(const std::vector<FiveBarPoint>& pts, const FiveBar& start, double* rms = nullptr);

}  // namespace kincal
