// kincal: URScript programs (UR CB3 / e-Series): def NAME(): ... end, with movej([q1..q6]) in radians
// for joint targets, and for filtered targets movej(p[...]) to the first pose then movel(p[...])
// (x, y, z in m, the rotation vector in rad). A UR controller takes no branch data: it reaches a pose
// by the inverse kinematics solution nearest its current joints. Speeds: movej's v is the joint speed
// in rad/s (the percentage of 180 deg/s), movel's the tool speed in m/s; r the blend radius in m.
#include "controller_writers.hpp"

namespace kincal::ctl {

namespace {

constexpr int kMDecimals = 8;     // 1e-8 m: 1e-5 mm

}  // namespace

std::vector<OutputFile> write_urscript(const std::string& out, const std::vector<ControllerTarget>& t,
                                       const WriterOptions& o, const std::string& name) {
  const bool filtered = o.targets == TargetKind::Filtered;
  const double r = zone_of(o) / 1000.0;
  const std::string vj = fixed(joint_speed_pct(o) / 100.0 * kPi, 4);
  std::string s = "def " + name + "():\n";
  s += "  # kincal compensate: " + std::to_string(t.size()) + (filtered ? " filtered Cartesian" : " joint") + " targets\n";
  for (size_t i = 0; i < t.size(); ++i) {
    const std::string blend = fixed(i + 1 < t.size() ? r : 0.0, 4);
    if (!filtered) {
      s += "  movej([";
      for (int j = 0; j < 6; ++j) s += (j ? ", " : "") + fixed(t[i].q_deg[j] * kDeg, kRadDecimals);
      s += "], a=1.4, v=" + vj + ", r=" + blend + ")\n";
    } else {
      const Vec3 rv = rotation_vector_of(t[i].pose.abc);
      std::string p = "p[";
      for (int k = 0; k < 3; ++k) p += (k ? ", " : "") + fixed(t[i].pose.xyz[k] / 1000.0, kMDecimals);
      for (int k = 0; k < 3; ++k) p += ", " + fixed(rv[k], kRadDecimals);
      p += "]";
      if (i == 0)
        s += "  movej(" + p + ", a=1.4, v=" + vj + ", r=" + blend + ")\n";
      else
        s += "  movel(" + p + ", a=1.2, v=" + fixed(linear_speed_mm_s(o) / 1000.0, 4) + ", r=" + blend + ")\n";
    }
  }
  s += "end\n";
  return {{out, s}};
}

}  // namespace kincal::ctl
