// kincal: the IK's solutions to degrees, each angle shifted by whole turns into the joint limits
// nearest a reference.
#include "kincal/ik/ik.hpp"

#include "subproblems.hpp"

#include <algorithm>
#include <cmath>

namespace kincal {

using namespace ik_detail;

// Whether the solutions can go to degrees and into the limits as record() writes them (deliver): a
// reference within the limits and less than a turn from zero (the usual case; null is zero), all
// solutions asked for (the nearest branch, one solution, keeps to_degrees' scalar loop), SSE2.
bool IkSolver::delivers(const IkOptions& opt) const {
#if defined(__SSE2__)
  if (opt.branches == Branches::NearestReference && opt.reference_deg != nullptr) return false;
  for (int j = 0; j < 6; ++j) {
    const double r = opt.reference_deg ? opt.reference_deg[j] : 0.0;
    if (!(r >= lo_[j] && r <= hi_[j] && std::abs(r) < 360)) return false;
  }
  return true;
#else
  (void)opt;
  return false;
#endif
}

// The solutions' angles, radians within a few turns, to degrees, each shifted by whole turns into the
// limits nearest the reference (or 0), flagged, one by one (the targets deliver() does not take).
void IkSolver::to_degrees(IkSolutions& out, const double* ref_deg) const {
  for (int i = 0; i < out.count; ++i) {
    Vec6& q = out.sol[i].q_deg;
    for (int j = 0; j < 6; ++j) q[j] = wrap(q[j]) * (180 / kPi);
    out.sol[i].within_limits = into_limits(q, ref_deg);
  }
}

// The angles (deg, in [-180, 180]) shifted by whole turns into the limits, nearest the reference
// (or 0): the whole turn nearest the reference (|k| <= 2); when it falls outside the limits, the
// nearest of the five that lie inside; none: q kept, out of limits (false). to_degrees' general case.
bool IkSolver::into_limits(Vec6& qd, const double* ref_deg) const {
  bool ok = true;
  for (int j = 0; j < 6; ++j) {
    const double q = qd[j], ref = ref_deg ? ref_deg[j] : 0.0;
    const double kn = std::min(2.0, std::max(-2.0, fastmath::round_nearest((ref - q) * (1.0 / 360))));
    const double c = q + 360.0 * kn;
    if (c >= lo_[j] && c <= hi_[j]) {
      qd[j] = c;
      continue;
    }
    double best = q;
    bool found = false;
    for (int k = -2; k <= 2; ++k) {
      const double ck = q + 360.0 * k;
      if (ck < lo_[j] || ck > hi_[j]) continue;
      if (!found || std::abs(ck - ref) < std::abs(best - ref)) best = ck;
      found = true;
    }
    qd[j] = best;
    ok = ok && found;
  }
  return ok;
}

}  // namespace kincal
