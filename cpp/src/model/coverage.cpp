#include "kincal/model/coverage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kincal {

namespace {

/// an angle (deg) in [-180, 180)
double wrap180(double a) {
  double r = std::fmod(a + 180.0, 360.0);
  if (r < 0) r += 360.0;
  if (r >= 360.0) r -= 360.0;  // -180 less an ulp: fmod gives -tiny, and -tiny + 360 rounds to 360
  return r - 180.0;
}

}  // namespace

std::vector<JointRange> joint_ranges(const double* q_deg, size_t rows, int dof) {
  std::vector<JointRange> out;
  if (rows == 0) return out;  // nothing fitted: unknown
  for (int j = 0; j < dof; ++j) {
    std::vector<double> a;  // the finite angles (a measurement reader refuses others; a caller may not)
    a.reserve(rows);
    for (size_t i = 0; i < rows; ++i) {
      const double q = q_deg[i * static_cast<size_t>(dof) + static_cast<size_t>(j)];
      if (std::isfinite(q)) a.push_back(wrap180(q));
    }
    if (a.empty()) throw InputError("joint ranges: joint " + std::to_string(j + 1) + " has no finite angle");
    std::sort(a.begin(), a.end());
    // the widest gap between neighbours on the circle (the last one wraps to the first)
    size_t widest = a.size() - 1;
    double gap = a.front() + 360.0 - a.back();
    for (size_t i = 0; i + 1 < a.size(); ++i)
      if (a[i + 1] - a[i] > gap) gap = a[i + 1] - a[i], widest = i;
    if (gap <= kFullTurnGapDeg) {
      out.push_back({-180.0, 180.0});
      continue;
    }
    const double lo = a[(widest + 1) % a.size()];
    out.push_back({lo, lo + 360.0 - gap});
  }
  return out;
}

bool outside_range(double q_deg, const JointRange& range) {
  const double lo = range[0] - kRangeMarginDeg, len = range[1] - range[0] + 2 * kRangeMarginDeg;
  if (len >= 360.0) return false;
  double past = std::fmod(q_deg - lo, 360.0);  // 0 at the range's (widened) start
  if (past < 0) past += 360.0;
  return past > len;
}

void check_joint_ranges(const std::vector<JointRange>& ranges, int dof, const std::string& who) {
  if (static_cast<int>(ranges.size()) != dof)
    throw InputError(who + ": " + std::to_string(ranges.size()) + " ranges for " + std::to_string(dof) + " joints");
  for (size_t j = 0; j < ranges.size(); ++j) {
    const JointRange& r = ranges[j];
    if (!(r[0] >= -180.0 && r[0] < 180.0) || !(r[1] >= r[0] && r[1] - r[0] <= 360.0))
      throw InputError(who + ": joint " + std::to_string(j + 1) +
                       ": a range needs [lo, hi] with lo in [-180, 180) and 0 <= hi - lo <= 360 (deg)");
  }
}

std::vector<Extrapolation> periodic_joints(const ModelSpec& calibrated, const std::vector<JointRange>& fitted) {
  std::vector<Extrapolation> out;
  for (size_t j = 0; j < fitted.size(); ++j) {
    Extrapolation e;
    for (const EffectValue& ev : calibrated.effects)
      if (ev.effect.harmonic() && ev.effect.joint == static_cast<int>(j))
        e.effects += (e.effects.empty() ? "" : ", ") + ev.effect.label();
    if (e.effects.empty()) continue;
    e.joint = static_cast<int>(j) + 1;
    e.fitted = fitted[j];
    out.push_back(e);
  }
  return out;
}

std::vector<Extrapolation> extrapolated(const ModelSpec& calibrated, const std::vector<JointRange>& fitted,
                                        const double* q_deg, size_t rows, int dof) {
  std::vector<Extrapolation> out;
  for (Extrapolation e : periodic_joints(calibrated, fitted)) {
    if (e.joint > dof) continue;
    for (size_t i = 0; i < rows; ++i)
      if (outside_range(q_deg[i * static_cast<size_t>(dof) + static_cast<size_t>(e.joint - 1)], e.fitted)) {
        if (e.rows == 0) e.first = i;
        ++e.rows;
      }
    if (e.rows > 0) out.push_back(e);
  }
  return out;
}

std::string leaving_message(const Extrapolation& e) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "joint %d is outside the %.0f..%.0f deg its ", e.joint, e.fitted[0], e.fitted[1]);
  return buf + e.effects + " was fitted on (angles modulo 360 deg)";
}

std::string extrapolation_message(const Extrapolation& e, size_t total, const std::string& noun) {
  const double share = total ? 100.0 * static_cast<double>(e.rows) / static_cast<double>(total) : 0.0;
  char tail[160];
  // a share that would round to 0% or 100% without being it keeps a decimal
  // (rounded away from it: 99.95% is 99.9%, 0.05% is 0.1%)
  const bool low = share < 0.5 && e.rows > 0, high = share >= 99.5 && e.rows < total;
  const double shown = low ? std::ceil(share * 10) / 10 : high ? std::floor(share * 10) / 10 : share;
  std::snprintf(tail, sizeof tail, " at %zu of %zu %s (%.*f%%)", e.rows, total, noun.c_str(), low || high ? 1 : 0,
                shown);
  return leaving_message(e) + tail + ": the effect is extrapolated there, not measured";
}

}  // namespace kincal
