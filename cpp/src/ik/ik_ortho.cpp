// kincal: the closed-form IK of ortho-parallel robots (IkStructure::ortho_parallel): the subproblems
// of the vector form written as plane rotations.
#include "kincal/ik/ik.hpp"

#include "subproblems.hpp"

namespace kincal {

using namespace ik_detail;

namespace {

// A shoulder branch (q1) of the ortho form: its elbow's cosine, sine and angle offset (sub3_elbow)
struct Shoulder {
  int n3;
  double ca, sa, a;
  bool clamped;
  Vec3 y, w6, v6;  // e^{-xi1 q1} p - p2, and C G w6, C G w5 turned back by -q1
};

// An arm branch (q1, q3) of the ortho form, in the order of solve_vector's loops
struct Arm {
  Angle a3, a2;
  bool clamped;
  int i1;  // its shoulder branch
};

// q3 of each shoulder branch the solve visits (the elbow's cosine, then the two branches'
// arctangents as a pair), with u (the wrist centre), gw and gv (C G w6, C G w5) turned back by -q1;
// the arm branches (q1, q3) into arm in solve_vector's order. Returns their count.
int elbow_arms(const IkSolver::Constants& kc, const Branch& br, const Angle* q1s, int n1, const Vec3& u, const Vec3& gw,
               const Vec3& gv, const Vec3& p21, bool clamped1, Tangency& tg, Shoulder* sh, Arm* arm) {
  int na = 0;
  const int b1 = br.pick(q1s, n1, 0);
  const int i1_begin = br.begin(b1), i1_end = br.end(b1, n1);
  for (int i1 = i1_begin; i1 < i1_end; ++i1) {
    const Angle& a1 = q1s[i1];
    Shoulder& h = sh[i1];
    // rotation about axis 1 by -q1 on components 2, 3
    auto r1 = [&](const Vec3& v) { return Vec3(v[0], v[1] * a1.c + v[2] * a1.s, -v[1] * a1.s + v[2] * a1.c); };
    h.y = r1(u) - p21;
    h.w6 = r1(gw);
    h.v6 = r1(gv);
    tg.clamped = clamped1;
    h.n3 = sub3_elbow_cos(kc, h.y.norm(), h.ca, tg);
    h.clamped = tg.clamped;
    h.sa = h.n3 > 0 ? sine_of(h.ca) : 0.0;
  }
  if (i1_end - i1_begin == 2 && sh[0].n3 > 0 && sh[1].n3 > 0) {
    fastmath::atan2x2(sh[0].sa, sh[0].ca, sh[1].sa, sh[1].ca, sh[0].a, sh[1].a);
  } else {
    for (int i1 = i1_begin; i1 < i1_end; ++i1)
      if (sh[i1].n3 > 0) sh[i1].a = fastmath::atan2(sh[i1].sa, sh[i1].ca);
  }
  for (int i1 = i1_begin; i1 < i1_end; ++i1) {
    const Shoulder& h = sh[i1];
    if (h.n3 == 0) continue;
    Angle t3[2];
    sub3_elbow_angles(kc, h.a, h.ca, h.sa, t3);
    const int b3 = br.pick(t3, h.n3, 2);
    for (int i3 = br.begin(b3); i3 < br.end(b3, h.n3); ++i3) arm[na++] = Arm{t3[i3], Angle{}, h.clamped, i1};
  }
  return na;
}

#if defined(__SSE2__)
// The ortho form's solutions in degrees within the limits (IkSolver::delivers: all branches, a plain
// reference), each angle converted once where solutions share it (q1 by up to four, q2 and q3 by
// two), two at a time: q1 of the two shoulder branches, (q2, q3) of an arm, q4, q5, q6 of its two
// wrists (to_limits2 lane by lane: the values IkSolver::deliver gives). polish(q) polishes a wrist
// near its singularity first.
template <class Polish>
void deliver_arms(IkSolutions& out, const Angle* q1s, int n1, const Arm* arm, int na, const Angle (*t4)[2],
                  const Angle (*t5)[2], const Angle* a6, const int* n45, const double* ref_deg,
                  const std::array<double, 6>& lo, const std::array<double, 6>& hi, Polish&& polish) {
  // each joint's reference and limits in both lanes
  __m128d r[6], l[6], h[6];
  for (int j = 0; j < 6; j += j == 0 ? 3 : 1) {
    r[j] = _mm_set1_pd(ref_deg ? ref_deg[j] : 0.0);
    l[j] = _mm_set1_pd(lo[j]);
    h[j] = _mm_set1_pd(hi[j]);
  }
  int in1;
  alignas(16) double d1[2];
  _mm_store_pd(d1, to_limits2(_mm_set_pd(q1s[n1 - 1].q, q1s[0].q), r[0], l[0], h[0], in1));  // (a lane repeated for one)
  const __m128d r23 = ref_deg ? _mm_loadu_pd(ref_deg + 1) : _mm_setzero_pd();
  const __m128d l23 = _mm_loadu_pd(lo.data() + 1), h23 = _mm_loadu_pd(hi.data() + 1);
  int count = 0;
  for (int k = 0; k < na; ++k) {
    const int n = n45[k];
    if (n == 0) continue;
    const Arm& a = arm[k];
    int in23;
    alignas(16) double d23[2], d4[2], d5[2], d6[2];
    _mm_store_pd(d23, to_limits2(_mm_set_pd(a.a3.q, a.a2.q), r23, l23, h23, in23));
    // the wrists (q4, q5, q6) and (q4 + pi, -q5, q6 + pi) (a lane repeated for one), radians, polished
    // near the singularity
    __m128d q4 = _mm_set_pd(t4[k][0].q + (n - 1) * kPi, t4[k][0].q);
    __m128d q5 = _mm_set_pd(n == 2 ? -t5[k][0].q : t5[k][0].q, t5[k][0].q);
    __m128d q6 = _mm_set_pd(a6[k].q + (n - 1) * kPi, a6[k].q);
    const double wrist = std::abs(t5[k][0].s);
    if (wrist < 1e-3) {
      alignas(16) double w[2][6], p4[2], p5[2], p6[2];
      _mm_store_pd(p4, q4);
      _mm_store_pd(p5, q5);
      _mm_store_pd(p6, q6);
      for (int i = 0; i < n; ++i) {
        w[i][0] = q1s[a.i1].q;
        w[i][1] = a.a2.q;
        w[i][2] = a.a3.q;
        w[i][3] = p4[i];
        w[i][4] = p5[i];
        w[i][5] = p6[i];
        polish(w[i]);
      }
      const int last = n - 1;
      q4 = _mm_set_pd(w[last][3], w[0][3]);
      q5 = _mm_set_pd(w[last][4], w[0][4]);
      q6 = _mm_set_pd(w[last][5], w[0][5]);
    }
    int in4, in5, in6;
    _mm_store_pd(d4, to_limits2(q4, r[3], l[3], h[3], in4));
    _mm_store_pd(d5, to_limits2(q5, r[4], l[4], h[4], in5));
    _mm_store_pd(d6, to_limits2(q6, r[5], l[5], h[5], in6));
    const int wrists_in = ((in1 >> a.i1) & 1) && in23 == 3 ? in4 & in5 & in6 : 0;
    for (int i = 0; i < n; ++i) {
      IkSolution& s = out.sol[count++];
      double* qd = s.q_deg.data();
      qd[0] = d1[a.i1];
      qd[1] = d23[0];
      qd[2] = d23[1];
      qd[3] = d4[i];
      qd[4] = d5[i];
      qd[5] = d6[i];
      s.within_limits = (wrists_in >> i) & 1;
      s.wrist_singular = wrist < 1e-7;
      s.shoulder_singular = false;
      s.approximate = a.clamped;
    }
  }
  out.count = count;
}
#endif

}  // namespace

void IkSolver::fill_ortho(IkForm form, const Vec3& c) {
  const Vec3 &w1 = w_[0], &w2 = w_[1], &w3 = w_[2];
  const double sigma = w3.dot(w2) > 0 ? 1.0 : -1.0;
  st_.ortho_parallel = form == IkForm::Fastest && st_.wrist_flip && std::abs(w1.dot(w2)) < 1e-12 &&
                       (w3 - sigma * w2).norm() < 1e-12;
  if (!st_.ortho_parallel) return;
  Ortho& o = o_;
  o.ct.row(0) = w1;
  o.ct.row(1) = w2;
  o.ct.row(2) = w1.cross(w2).normalized();
  o.d = w2.dot(c - p_[0]);
  o.p21 = o.ct * (p_[1] - p_[0]);
  const Vec3 pw3 = o.ct * (c - p_[2]), p32 = o.ct * (p_[2] - p_[1]);
  o.pw3_1 = pw3[0];
  o.pw3_3 = pw3[2];
  o.p32_1 = p32[0];
  o.p32_3 = p32[2];
  o.sigma = sigma;
  o.tau = w_[5].dot(w_[3]) > 0 ? 1.0 : -1.0;
  o.w4 = o.ct * w_[3];
  o.w5 = o.ct * w_[4];
  o.n = o.ct * k_.n;
}

// The ortho-parallel robots: the subproblems of solve_vector in the frame C of axes 1 and 2, where a
// rotation about axis 1 (axis 2, 3) turns components 2 and 3 (1 and 3) only: each rotation is a
// plane rotation of two numbers; the wrist's three angles come from its images of w6 and w5 in the
// frame (w4, w5, w4 x w5) directly. The arm branches (q1, q3) go through each stage together, so that
// their independent arctangents overlap.
// Same branches in the same order; a wrist centre on axis 1 (or out of reach) goes to solve_vector.
IkSolutions IkSolver::solve_ortho(const Mat3& gr, const Vec3& p, const IkOptions& opt, bool deliver_now) const {
  const double* ref_deg = opt.reference_deg;
  const Branch br{ref_deg, opt.branches == Branches::NearestReference && ref_deg != nullptr};
  Tangency tg;
  tg.clamp = opt.out_of_reach == OutOfReach::Nearest;
  const Ortho& o = o_;
  const Constants& kc = k_;
  const Vec3 u = o.ct * (p - p_[0]);
  const Vec3 gw = o.ct * (gr * w_[5]), gv = o.ct * (gr * w_[4]);  // C G w6, C G w5
  // q1 (sub4 with h = w2, k = w1: A = w2 . u, B = w2 . (w1 x u), C = d)
  Angle t1[2];
  const int n1 = sub4_abc(u[1], -u[2], o.d, t1, tg);
  IkSolutions out;
  if (n1 == 0) {
    out = solve_vector(gr, p, opt, deliver_now);
    return out;
  }
  const bool clamped1 = tg.clamped;
  Arm arm[4];
  Angle q1s[2];
  for (int i = 0; i < n1; ++i) q1s[i] = negated(t1[i]);
  Shoulder sh[2];
  const int na = elbow_arms(kc, br, q1s, n1, u, gw, gv, o.p21, clamped1, tg, sh, arm);
  // q2 (sub1 about w2 from x - p2 = rot(w2, sigma q3)(pw - p3) + p3 - p2 to y, components 1 and 3),
  // two arm branches at a time
  double x2[4], y2[4];
  for (int k = 0; k < na; ++k) {
    const Arm& a = arm[k];
    const double c3 = a.a3.c, s3 = o.sigma * a.a3.s;
    const double x1 = o.pw3_1 * c3 + o.pw3_3 * s3 + o.p32_1, x3 = -o.pw3_1 * s3 + o.pw3_3 * c3 + o.p32_3;
    const Vec3& y = sh[a.i1].y;
    x2[k] = x1 * y[0] + x3 * y[2];
    y2[k] = x3 * y[0] - x1 * y[2];
  }
  for (int k = 0; k < na; k += 2) {
    if (k + 1 < na) {
      from_xy2(x2[k], y2[k], x2[k + 1], y2[k + 1], arm[k].a2, arm[k + 1].a2);
    } else {
      arm[k].a2 = from_xy(x2[k], y2[k]);
    }
  }
  // q4, q5 and q6 of the first wrist solution of each arm branch (the one solve_vector's subproblem 2
  // gives first: sin q5 = -tau r), each from one arctangent of the wrist's images. The wrist is
  // orthonormal (w4 . w5 = 0, w6 = tau w4, n = w4 x w5), so in the frame (w4, w5, n)
  // e = R456 w6 = tau (c5, s5 s4, -s5 c4) (r = |(e2, e3)| = |s5|), and with f = R456 w5,
  // w4 . f = tau s5 s6 and w4 . (e x f) = e2 f3 - e3 f2 = tau s5 c6. No angle waits for another's
  // cosine and sine: q4 and q5 of an arm are one pair of arctangents, q6 of two arms another.
  Angle t4[4][2], t5[4][2], a6[4];
  int n45[4];
  double x6[4] = {1, 1, 1, 1}, y6[4] = {0, 0, 0, 0};
  for (int k = 0; k < na; ++k) {
    Arm& a = arm[k];
    // rotation about axis 2 by -(q2 + sigma q3) on components 1, 3
    const double c = a.a2.c * a.a3.c - o.sigma * a.a2.s * a.a3.s, s = a.a2.s * a.a3.c + o.sigma * a.a2.c * a.a3.s;
    const Vec3 &w1 = sh[a.i1].w6, &v1 = sh[a.i1].v6;
    const Vec3 w6(w1[0] * c - w1[2] * s, w1[1], w1[0] * s + w1[2] * c);
    const Vec3 v6(v1[0] * c - v1[2] * s, v1[1], v1[0] * s + v1[2] * c);
    const double e1 = o.w4.dot(w6), e2 = o.w5.dot(w6), e3 = o.n.dot(w6);
    const double f1 = o.w4.dot(v6), f2 = o.w5.dot(v6), f3 = o.n.dot(v6);
    const double r = std::sqrt(e2 * e2 + e3 * e3), s5 = -o.tau * r, c5 = o.tau * e1;
    const double x = e3 * f2 - e2 * f3, y = -f1;
    n45[k] = !std::isfinite(r + c5 + x + y) ? 0 : (r > 0 ? 2 : 1);
    if (n45[k] == 0) continue;  // (x6, y6 stay (1, 0) for the pair below)
    x6[k] = x;
    y6[k] = y;
    fastmath::atan2x2(-e2, e3, s5, c5, t4[k][0].q, t5[k][0].q);
    t5[k][0].c = c5;
    t5[k][0].s = s5;
  }
  for (int k = 0; k < na; k += 2) {
    if (k + 1 < na) {
      fastmath::atan2x2(y6[k], x6[k], y6[k + 1], x6[k + 1], a6[k].q, a6[k + 1].q);
    } else {
      a6[k].q = fastmath::atan2(y6[k], x6[k]);
    }
  }
#if defined(__SSE2__)
  if (deliver_now) {
    deliver_arms(out, q1s, n1, arm, na, t4, t5, a6, n45, ref_deg, lo_, hi_, [&](double* q) { polish(q, gr); });
    return out;
  }
#endif
  for (int k = 0; k < na; ++k) {
    if (n45[k] == 2) {  // the other wrist: (q4 + pi, -q5, q6 + pi)
      t4[k][1].q = t4[k][0].q + kPi;
      t5[k][1] = negated(t5[k][0]);
    }
    const int b45 = br.pick_wrist(t4[k], t5[k], n45[k]);
    for (int i45 = br.begin(b45); i45 < br.end(b45, n45[k]); ++i45) {
      double q[6] = {q1s[arm[k].i1].q, arm[k].a2.q, arm[k].a3.q, t4[k][i45].q, t5[k][i45].q, a6[k].q + i45 * kPi};
      record(out, q, std::abs(t5[k][i45].s), gr, false, arm[k].clamped, opt, deliver_now);
    }
  }
  return out;
}

}  // namespace kincal
