#include "kincal/compensation/branch.hpp"

#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <array>
#include <cmath>
#include <cstdio>

namespace kincal {

namespace {

double wrap180(double q) {  // to [-180, 180)
  return q - 360.0 * std::floor((q + 180.0) / 360.0);
}

// point x moved by joint j of model m turned by q (deg)
Vec3 turn(const Model& m, int j, double q_deg, const Vec3& x) {
  return axis_rotation(m.axis(j), q_deg * kDeg) * (x - m.point(j)) + m.point(j);
}

int quadrant(double q) { return static_cast<int>(std::floor(q / 90.0)); }
int fanuc_turn(double q) { return static_cast<int>(std::floor((q + 180.0) / 360.0)); }

// the value of a joint with the wanted 360-degree multiple in format f (joint j, branch data of t); a value
// within tol of a border may count on either side of it
double unwrap(ControllerFormat f, int j, double q, const ControllerTarget& t, double tol) {
  const double w = wrap180(q);
  if (f == ControllerFormat::Krl) {
    const bool neg = (t.kuka_t >> j) & 1;
    if (neg) return w < tol ? w : w - 360.0;
    return w > -tol ? w : w + 360.0;
  }
  const int idx = j == 0 ? 0 : j == 3 ? 1 : j == 5 ? 2 : -1;
  if (idx < 0) return w;
  if (f == ControllerFormat::Rapid) {
    const int cf = t.abb_conf[static_cast<size_t>(idx)];
    for (int k = -3; k <= 3; ++k) {
      const double v = w + 360.0 * k;
      if (quadrant(v) == cf || quadrant(v + tol) == cf || quadrant(v - tol) == cf) return v;
    }
    return std::nan("");
  }
  // FANUC: the turn number written after the three letters
  int turns[3] = {0, 0, 0};
  const size_t c = t.fanuc_config.find(',');
  if (c == std::string::npos || std::sscanf(t.fanuc_config.c_str() + c + 1, "%d , %d , %d", &turns[0], &turns[1], &turns[2]) != 3)
    return std::nan("");
  // turn n is [-180 + 360 n, 180 + 360 n): a joint within tol below its upper border (+180, which belongs
  // to turn n + 1) is taken as the lower border of turn n, which the turn includes (taught at exactly
  // J6 = 180 with turn 1, the inverse kinematics' 179.999998 is that joint, not 539.999998)
  return w + 360.0 * (w > 180.0 - tol ? turns[idx] - 1 : turns[idx]);
}

bool same_branch(ControllerFormat f, const ControllerTarget& a, const ControllerTarget& b) {
  return f == ControllerFormat::Krl     ? (a.kuka_s == b.kuka_s && a.kuka_t == b.kuka_t)
         : f == ControllerFormat::Rapid ? a.abb_conf == b.abb_conf
                                        : a.fanuc_config == b.fanuc_config;
}

// whether joints q have t's branch data, with each joint within tol of a border (a multiple of 90 deg) taken
// on either side of it
bool branch_matches(const Robot& robot, ControllerFormat f, const Vec6& q, const ControllerTarget& t, double tol) {
  ControllerTarget c = t;
  c.q_deg = q;
  set_branch_data(robot, c);
  if (same_branch(f, c, t)) return true;
  std::vector<int> near;
  for (int j = 0; j < 6 && tol > 0; ++j)
    if (std::abs(q[j] - 90.0 * std::round(q[j] / 90.0)) < tol) near.push_back(j);
  if (near.empty() || near.size() > 4) return false;
  for (unsigned mask = 1; mask < (1u << near.size()); ++mask) {
    c.q_deg = q;
    for (size_t k = 0; k < near.size(); ++k) {
      if (!((mask >> k) & 1)) continue;
      const int j = near[k];
      const double border = 90.0 * std::round(q[j] / 90.0);
      c.q_deg[j] = border + (q[j] < border ? 2.0 : -2.0) * tol;  // to the border's other side
    }
    set_branch_data(robot, c);
    if (same_branch(f, c, t)) return true;
  }
  return false;
}

}  // namespace

ArmClass arm_class(const Robot& robot, const Vec6& q) {
  const Model& m = *robot.nominal();
  const IkStructure& st = robot.ik().structure();
  if (!st.spherical_wrist_parallel_23)
    throw InputError("filtered targets with branch data need a robot whose axes 2 and 3 are parallel and whose wrist "
                     "axes meet (" + st.reason + ")");
  const Vec3 wc0 = st.wrist_center;
  const Vec3 w1 = m.axis(0), p1 = m.point(0);
  Vec3 u = (wc0 - p1) - (wc0 - p1).dot(w1) * w1;  // x of the A1 system
  if (u.norm() < 1e-9) u = Vec3::UnitX();
  u.normalize();
  const Vec3 y = Vec3::UnitZ().cross(u);
  // in the A1 system (axis 1 undone): shoulder, elbow, wrist centre
  const Vec3 s = m.point(1);
  const Vec3 e = turn(m, 1, q[1], m.point(2));
  const Vec3 wc = turn(m, 1, q[1], turn(m, 2, q[2], wc0));
  ArmClass a;
  a.x_a1 = (wc - p1).dot(u);
  a.behind = a.x_a1 < 0;
  const Vec3 ua = e - s, fa = wc - e;
  a.elbow_sin = ua.cross(fa).dot(y) / (ua.norm() * fa.norm());
  a.elbow_up = a.elbow_sin > 0;
  a.wrist_negative = wrap180(q[4]) < 0;
  return a;
}

void set_branch_data(const Robot& robot, ControllerTarget& t) {
  const Vec6& q = t.q_deg;
  const ArmClass a = arm_class(robot, q);
  t.kuka_s = (a.behind ? 1 : 0) | (a.elbow_up ? 2 : 0) | (a.wrist_negative ? 4 : 0);
  t.kuka_t = 0;
  for (int j = 0; j < 6; ++j)
    if (q[j] < 0) t.kuka_t |= 1 << j;
  t.abb_conf = {{quadrant(q[0]), quadrant(q[3]), quadrant(q[5]),
                 (a.behind ? 4 : 0) | (a.elbow_up ? 0 : 2) | (a.wrist_negative ? 1 : 0)}};
  t.fanuc_config = std::string(wrap180(q[4]) > 0 ? "F" : "N") + " " + (a.elbow_up ? "U" : "D") + " " +
                   (a.behind ? "B" : "T") + ", " + std::to_string(fanuc_turn(q[0])) + ", " +
                   std::to_string(fanuc_turn(q[3])) + ", " + std::to_string(fanuc_turn(q[5]));
}

std::optional<Vec6> select_branch(const Robot& robot, ControllerFormat f, const ControllerTarget& t, std::string* why,
                                  double border_tolerance) {
  const IkSolutions s = robot.ik().solve(pose_to_iso(t.pose), IkOptions());
  if (s.status != IkStatus::Ok) {
    if (why) *why = "the nominal inverse kinematics has no solution";
    return std::nullopt;
  }
  std::optional<Vec6> found;
  for (int i = 0; i < s.count; ++i) {
    Vec6 q;
    for (int j = 0; j < 6; ++j) q[j] = unwrap(f, j, s.sol[static_cast<size_t>(i)].q_deg[j], t, border_tolerance);
    if (!q.allFinite() || !branch_matches(robot, f, q, t, border_tolerance)) continue;
    if (found && (*found - q).cwiseAbs().maxCoeff() > 1e-6) {
      if (why) *why = "two solutions have the same branch data";
      return std::nullopt;
    }
    found = q;
  }
  if (!found && why) *why = "no solution has the target's branch data";
  return found;
}

std::string branch_text(ControllerFormat f, const ControllerTarget& t) {
  if (f == ControllerFormat::Krl) return "S " + std::to_string(t.kuka_s) + ", T " + std::to_string(t.kuka_t);
  if (f == ControllerFormat::Rapid)
    return "cfx " + std::to_string(t.abb_conf[3]) + ", cf1 " + std::to_string(t.abb_conf[0]) + ", cf4 " +
           std::to_string(t.abb_conf[1]) + ", cf6 " + std::to_string(t.abb_conf[2]);
  return t.fanuc_config;
}

BranchDifference branch_difference(const Robot& robot, ControllerFormat f, const ControllerTarget& taught,
                                   const Vec6& q_deg) {
  ControllerTarget c;
  c.q_deg = q_deg;
  set_branch_data(robot, c);
  BranchDifference d;
  if (f == ControllerFormat::Krl) {
    d.arm = c.kuka_s != taught.kuka_s;
    for (int j = 0; j < 6; ++j)
      if (((c.kuka_t ^ taught.kuka_t) >> j) & 1) d.turns.push_back(j);
  } else if (f == ControllerFormat::Rapid) {
    d.arm = c.abb_conf[3] != taught.abb_conf[3];
    const int joint[3] = {0, 3, 5};
    for (size_t k = 0; k < 3; ++k)
      if (c.abb_conf[k] != taught.abb_conf[k]) d.turns.push_back(joint[k]);
  } else {
    const auto letters = [](const std::string& s) {
      std::string out;
      for (char ch : s.substr(0, s.find(',')))
        if (ch != ' ') out += ch;
      return out;
    };
    const auto turns = [](const std::string& s) {
      int t[3] = {0, 0, 0};
      const size_t comma = s.find(',');
      if (comma != std::string::npos) std::sscanf(s.c_str() + comma + 1, "%d , %d , %d", &t[0], &t[1], &t[2]);
      return std::array<int, 3>{{t[0], t[1], t[2]}};
    };
    d.arm = letters(c.fanuc_config) != letters(taught.fanuc_config);
    const auto a = turns(c.fanuc_config), b = turns(taught.fanuc_config);
    const int joint[3] = {0, 3, 5};
    for (size_t k = 0; k < 3; ++k)
      if (a[k] != b[k]) d.turns.push_back(joint[k]);
  }
  return d;
}

}  // namespace kincal
