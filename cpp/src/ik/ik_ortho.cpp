// kincal: the closed-form IK of ortho-parallel robots (IkStructure::ortho_parallel): the subproblems
// of the vector form written as plane rotations.
#include "kincal/ik/ik.hpp"

#include "subproblems.hpp"

namespace kincal {

using namespace ik_detail;

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
  o.m = o.ct * k_.m;
}

// The ortho-parallel robots: the subproblems of solve_vector in the frame C of axes 1 and 2, where a
// rotation about axis 1 (axis 2, 3) turns components 2 and 3 (1 and 3) only, and the wrist's in the
// frame (w4, w5, w4 x w5), with v6 = w5: each rotation is a plane rotation of two numbers. The arm
// branches (q1, q3) go through each stage together, so that their independent arctangents overlap.
// Same branches in the same order; a wrist centre on axis 1 (or out of reach) goes to solve_vector.
IkSolutions IkSolver::solve_ortho(const Mat3& gr, const Vec3& p, const IkOptions& opt) const {
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
  if (n1 == 0) return solve_vector(gr, p, opt);
  const bool clamped1 = tg.clamped;
  // the arm branches (q1, q3), in the order of solve_vector's loops
  struct Arm {
    Angle a1, a3, a2;
    Vec3 y, w6, v6;  // e^{-xi1 q1} p - p2, and C G w6, C G w5 turned back by -q1
    bool clamped;
  };
  Arm arm[4];
  int na = 0;
  Angle q1s[2];
  for (int i = 0; i < n1; ++i) q1s[i] = negated(t1[i]);
  const int b1 = br.pick(q1s, n1, 0);
  for (int i1 = br.begin(b1); i1 < br.end(b1, n1); ++i1) {
    const Angle& a1 = q1s[i1];
    // rotation about axis 1 by -q1 on components 2, 3
    auto r1 = [&](const Vec3& v) { return Vec3(v[0], v[1] * a1.c + v[2] * a1.s, -v[1] * a1.s + v[2] * a1.c); };
    const Vec3 y = r1(u) - o.p21;
    Angle t3[2];
    tg.clamped = clamped1;
    const int n3 = sub3_elbow(kc, y.norm(), t3, tg);
    const int b3 = br.pick(t3, n3, 2);
    for (int i3 = br.begin(b3); i3 < br.end(b3, n3); ++i3) arm[na++] = Arm{a1, t3[i3], Angle{}, y, r1(gw), r1(gv), tg.clamped};
  }
  // q2 (sub1 about w2 from x - p2 = rot(w2, sigma q3)(pw - p3) + p3 - p2 to y, components 1 and 3)
  for (int k = 0; k < na; ++k) {
    Arm& a = arm[k];
    const double c3 = a.a3.c, s3 = o.sigma * a.a3.s;
    const double x1 = o.pw3_1 * c3 + o.pw3_3 * s3 + o.p32_1, x3 = -o.pw3_1 * s3 + o.pw3_3 * c3 + o.p32_3;
    a.a2 = from_xy(x1 * a.y[0] + x3 * a.y[2], x3 * a.y[0] - x1 * a.y[2]);
  }
  // q4, q5 (sub2 of the wrist) and q6 of the first wrist solution of each arm branch
  Angle t4[4][2], t5[4][2], a6[4];
  int n45[4];
  for (int k = 0; k < na; ++k) {
    Arm& a = arm[k];
    // rotation about axis 2 by -(q2 + sigma q3) on components 1, 3
    const double c = a.a2.c * a.a3.c - o.sigma * a.a2.s * a.a3.s, s = a.a2.s * a.a3.c + o.sigma * a.a2.c * a.a3.s;
    const Vec3 w6(a.w6[0] * c - a.w6[2] * s, a.w6[1], a.w6[0] * s + a.w6[2] * c);
    a.v6 = Vec3(a.v6[0] * c - a.v6[2] * s, a.v6[1], a.v6[0] * s + a.v6[2] * c);
    tg.clamped = a.clamped;
    n45[k] = sub2_dots(kc, o.w4.dot(w6), o.w5.dot(w6), o.n.dot(w6), o.m.dot(w6), t4[k], t5[k], true, tg);
    a.clamped = tg.clamped;
  }
  for (int k = 0; k < na; ++k) {
    if (n45[k] == 0) continue;
    // q6 takes w5 to rot(w5, -q5) rot(w4, -q4) R456 w5; in the frame (w4, w5, n) a turn about w4
    // moves components 2, 3 and one about w5 components 1, 3; sub1 about tau w4 from (0, 1, 0)
    const Vec3& v = arm[k].v6;
    const double e1 = o.w4.dot(v), e2 = o.w5.dot(v), e3 = o.n.dot(v);
    const Angle &a4 = t4[k][0], &a5 = t5[k][0];
    const double f2 = e2 * a4.c + e3 * a4.s, f3 = -e2 * a4.s + e3 * a4.c;
    a6[k].q = fastmath::atan2(o.tau * (e1 * a5.s + f3 * a5.c), f2);
  }
  IkSolutions out;
  for (int k = 0; k < na; ++k) {
    if (n45[k] == 2) {  // the other wrist: (q4 + pi, -q5, q6 + pi)
      t4[k][1].q = t4[k][0].q + kPi;
      t5[k][1] = negated(t5[k][0]);
    }
    const int b45 = br.pick_wrist(t4[k], t5[k], n45[k]);
    for (int i45 = br.begin(b45); i45 < br.end(b45, n45[k]); ++i45) {
      double q[6] = {arm[k].a1.q, arm[k].a2.q, arm[k].a3.q, t4[k][i45].q, t5[k][i45].q, a6[k].q + i45 * kPi};
      record(out, q, std::abs(t5[k][i45].s), gr, false, arm[k].clamped);
    }
  }
  return out;
}

}  // namespace kincal
