// kincal (private): the data's linearization at a parameter vector and the normal matrix of a
// Jacobian, shared by the identifiability analysis (identifiability.cpp) and the observability
// figures (observability.cpp).
#pragma once

#include "kincal/identify/identifiability.hpp"
#include "kincal/identify/point_model.hpp"

#include <vector>

namespace kincal::detail {

/// The lower triangle of J^T J (what the eigen-solvers read).
Eigen::MatrixXd normal_matrix_lower(const Eigen::MatrixXd& j);
/// The Jacobian of every parameter and the residuals of data at x (the artifact's terms after the rows).
Linearization linearize(const PointModel& pm, const MeasurementSet& data, const std::vector<double>& x, double weight);

}  // namespace kincal::detail
