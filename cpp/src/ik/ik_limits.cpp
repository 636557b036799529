// kincal: the IK's solutions to degrees, each angle shifted by whole turns into the joint limits
// nearest a reference.
#include "kincal/ik/ik.hpp"

#include "subproblems.hpp"

#include <algorithm>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kincal {

using namespace ik_detail;

// The solutions' angles, radians within a few turns, to degrees, each shifted by whole turns into the
// limits, nearest the reference. For a reference within the limits and less than a turn from zero
// (the usual case): the turn nearest the reference when it lands inside; else the next turn towards
// the limits (the candidates beyond are farther from both); else none (the angle in [-180, 180], out
// of limits): the choice into_limits makes, up to rounding, joint by joint over the solutions, two at
// a time in SSE2 registers without branches on the data (other targets: into_limits one by one).
void IkSolver::to_degrees(IkSolutions& out, const double* ref_deg) const {
  const int n = out.count;
  bool simple = true;
  for (int j = 0; j < 6; ++j) {
    const double r = ref_deg ? ref_deg[j] : 0.0;
    simple = simple && r >= lo_[j] && r <= hi_[j] && std::abs(r) < 360;
  }
#if defined(__SSE2__)
  if (simple && n > 2) {  // (one or two solutions, the nearest branch: the scalar loop is as quick)
    const __m128d magic = _mm_set1_pd(6755399441055744.0);  // fastmath::round_nearest
    auto round = [&](__m128d v) { return _mm_sub_pd(_mm_add_pd(v, magic), magic); };
    auto select = [](__m128d m, __m128d a, __m128d b) { return _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b)); };
    const __m128d turn = _mm_set1_pd(360), inv_turn = _mm_set1_pd(1.0 / 360), half = _mm_set1_pd(-180);
    const __m128d sign = _mm_set1_pd(-0.0), deg = _mm_set1_pd(180 / kPi);
    __m128d ok[4];
    for (auto& o : ok) o = _mm_castsi128_pd(_mm_set1_epi32(-1));
    for (int j = 0; j < 6; ++j) {
      const __m128d r = _mm_set1_pd(ref_deg ? ref_deg[j] : 0.0), lo = _mm_set1_pd(lo_[j]), hi = _mm_set1_pd(hi_[j]);
      for (int i = 0; i < n; i += 2) {
        const int i2 = i + 1 < n ? i + 1 : i;  // an odd count: the last lane repeats the last solution
        const __m128d d = _mm_mul_pd(_mm_set_pd(out.sol[i2].q_deg[j], out.sol[i].q_deg[j]), deg);
        // the turn nearest r, then the next turn towards the limits
        const __m128d y0 = _mm_add_pd(d, _mm_mul_pd(turn, round(_mm_mul_pd(_mm_sub_pd(r, d), inv_turn))));
        const __m128d above = _mm_cmpgt_pd(y0, hi);
        const __m128d in0 = _mm_andnot_pd(above, _mm_cmpge_pd(y0, lo));
        const __m128d y1 = _mm_add_pd(y0, _mm_xor_pd(turn, _mm_and_pd(above, sign)));
        const __m128d in1 = _mm_and_pd(_mm_cmpge_pd(y1, lo), _mm_cmple_pd(y1, hi));
        // none inside: the angle in (-180, 180]
        __m128d w = _mm_sub_pd(d, _mm_mul_pd(turn, round(_mm_mul_pd(d, inv_turn))));
        w = _mm_add_pd(w, _mm_and_pd(_mm_cmple_pd(w, half), turn));
        const __m128d y = select(in0, y0, select(in1, y1, w));
        ok[i / 2] = _mm_and_pd(ok[i / 2], _mm_or_pd(in0, in1));
        _mm_storel_pd(&out.sol[i].q_deg[j], y);
        _mm_storeh_pd(&out.sol[i2].q_deg[j], y);
      }
    }
    for (int i = 0; i < n; ++i) out.sol[i].within_limits = (_mm_movemask_pd(ok[i / 2]) >> (i % 2)) & 1;
    return;
  }
#endif
  for (int i = 0; i < n; ++i) {
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
