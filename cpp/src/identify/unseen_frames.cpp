// kincal: the directions of the base placements and target offsets that tracker rows barely see
// (a reflector's depth along an axis every tool orientation shares), held before the frames' fit.
#include "kincal/identify/identifiability.hpp"

#include "linearization.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <string>

namespace kincal {

std::vector<int> frame_columns(const ParamLayout& L, const MeasurementSet& data, const IdentifyResult& res) {
  const auto unseen = [&](int i) { return held_unseen(res, i); };
  std::vector<int> frames;
  // with measured orientations the frame measured is the tool frame (its target held at zero): the
  // probe's mounting, position and rotation, is a frame too
  if (data.orientation)
    for (int i = L.tool; i < L.tool + 6; ++i)
      if (!unseen(i)) frames.push_back(i);
  for (int i = L.base; i < L.effects; ++i)  // the placements even when held, but those never measured
    if (!res.fixed[i] || (i < L.targets && res.fixed_reason[i] != kSetupNeverMeasured &&
                          res.fixed_reason[i] != kProbeOnlySetup && !unseen(i)))
      frames.push_back(i);
  return frames;
}

void hold_unseen_frames(const PointModel& pm, const PointState& frames_only, const MeasurementSet& data,
                        const IdentifyOptions& opt, IdentifyResult& res) {
  if (data.has_probe() || data.rows.empty()) return;
  const ParamLayout& L = res.layout;
  const auto on_tool = [&](int i) {  // a target's offset, or the tool frame a 6-D row measures
    return (i >= L.targets && i < L.effects) || (data.orientation && i >= L.tool && i < L.tool + 6);
  };
  // the frames' columns alone, from the frames-only evaluation (every row's flange frame once; the
  // same columns as the full linearization's at x, without the robot's own), but where 6-D rows move
  // the tool frame of a robot with compliance: the tool's columns then carry the payload's torque,
  // which the frames-only rows leave out
  const std::vector<int> frames = frame_columns(L, data, res);
  const Eigen::Index F = static_cast<Eigen::Index>(frames.size());
  Eigen::MatrixXd J(static_cast<Eigen::Index>(residual_size(residual_kind(data)) * data.rows.size()), F);
  if (data.orientation && !L.loaded.empty()) {
    const Eigen::MatrixXd full = detail::linearize(pm, data, frames_only.x(), opt.orientation_weight).jacobian;
    for (Eigen::Index c = 0; c < F; ++c) J.col(c) = full.col(frames[static_cast<size_t>(c)]).head(J.rows());
  } else {
    all_residuals(frames_only, data, opt.orientation_weight, frames, nullptr, J.data(), static_cast<size_t>(J.rows()));
  }
  std::vector<Eigen::Index> cols;  // J's columns the rows see at all (column c: parameter frames[c])
  for (Eigen::Index c = 0; c < F; ++c)
    if (J.col(c).norm() > 0) cols.push_back(c);
  const auto param = [&](Eigen::Index k) { return frames[static_cast<size_t>(cols[static_cast<size_t>(k)])]; };
  // the smallest singular value of the unit-scaled columns: below the weak tolerance its direction is
  // held by one parameter, the largest part of it on the tool when the tool takes a fair share (the
  // depth of a reflector along the axis every orientation shares), else the largest; again until none
  while (!cols.empty()) {
    Eigen::MatrixXd A(J.rows(), static_cast<Eigen::Index>(cols.size()));
    for (size_t c = 0; c < cols.size(); ++c) A.col(static_cast<Eigen::Index>(c)) = J.col(cols[c]).normalized();
    // the smallest singular value and its right vector from the (few columns') normal matrix: its
    // eigenvalues are the squares, exact to about 1e-15 beside the weak tolerance's square 4e-6 (with
    // fewer residuals than columns the smallest is 0, its vector in the null space)
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(detail::normal_matrix_lower(A));
    const double sigma = std::sqrt(std::max(0.0, eig.eigenvalues()[0]));
    if (sigma >= opt.weak_tolerance) break;
    const Eigen::VectorXd v = eig.eigenvectors().col(0);
    Eigen::Index pick = 0, pick_tool = -1;
    for (Eigen::Index c = 0; c < v.size(); ++c) {
      if (std::abs(v[c]) > std::abs(v[pick])) pick = c;
      if (on_tool(param(c)) && (pick_tool < 0 || std::abs(v[c]) > std::abs(v[pick_tool]))) pick_tool = c;
    }
    if (pick_tool >= 0 && std::abs(v[pick_tool]) >= 0.5 * std::abs(v[pick])) pick = pick_tool;
    std::string with;  // the direction in the parameters' units, per unit of the one held
    const auto unit_step = [&](Eigen::Index c) { return v[c] / J.col(cols[static_cast<size_t>(c)]).norm(); };
    for (Eigen::Index c = 0; c < v.size(); ++c)
      if (c != pick && std::abs(v[c]) >= 0.2) {
        char part[96];
        std::snprintf(part, sizeof part, "%s%+.3g %s", with.empty() ? "" : ", ", unit_step(c) / unit_step(pick),
                      L.names[param(c)].c_str());
        with += part;
      }
    char buf[320];
    std::snprintf(buf, sizeof buf, "%s: these rows see it only through %.1e of its effect, moving with %s (do all the tool's "
                  "orientations share an axis?)", kUnseenFrame, sigma, with.empty() ? "nothing else" : with.c_str());
    res.fix(param(pick), buf);
    cols.erase(cols.begin() + pick);
  }
}

}  // namespace kincal
