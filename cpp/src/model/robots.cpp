#include "kincal/model/robots.hpp"

#include <cmath>
#include <random>

namespace kincal {

// ---------------------------------------------------------------------------------------------
// The built-in KR 500-class robot.
//
// Geometry: the public nominal dimensions of the KUKA KR 500 R2830 (KR 500 FORTEC) as drawn in
// KUKA's specification "KR 500 FORTEC" (working envelope drawing): A1-A2 offset 500 mm, A2 height
// 1045 mm above the mounting face, upper arm 1300 mm, A3-A4 offset 55 mm, forearm 1025 mm, wrist
// centre to flange 290 mm. Axis ranges and speeds from the same specification (A1 +-185 deg at
// 79 deg/s, A2 -130..+20 at 75, A3 -100..+144 at 70, A4 +-350 at 90, A5 +-120 at 90, A6 +-350 at
// 143). KUKA publishes no acceleration or jerk limits: ours are assumptions (full speed in 0.5 s,
// full acceleration in 0.1 s) and are marked so in the README; a limits file overrides them.
// Link masses and centres of mass are assumptions scaled to the robot's published 2.4 t; the
// payload is a tape-laying head of 300 kg (the Samak paper's KR 500 carries a Mikrosam ATL head),
// TCP 350 mm out from the flange. Zero configuration: arm stretched horizontally along +x, axes in
// KUKA's sense (A1 about -z, A2, A3, A5 about +y, A4, A6 about -x).
// ---------------------------------------------------------------------------------------------
ModelSpec kr500_spec() {
  ModelSpec s;
  s.name = "kr500";
  const double a1 = 500, d1 = 1045, a2 = 1300, a3 = 55, d4 = 1025, d6 = 290;
  const Vec3 wc(a1 + a2 + d4, 0, d1 + a3);
  struct Row {
    const char* name;
    Vec3 point, axis;
    double lo, hi, v, m;
    Vec3 com;
  };
  const Row rows[6] = {
      {"A1", Vec3(0, 0, 0), Vec3(0, 0, -1), -185, 185, 79, 700, Vec3(250, 0, 600)},
      {"A2", Vec3(a1, 0, d1), Vec3(0, 1, 0), -130, 20, 75, 350, Vec3(a1 + 650, 0, d1)},
      {"A3", Vec3(a1 + a2, 0, d1), Vec3(0, 1, 0), -100, 144, 70, 250, Vec3(a1 + a2 + 250, 0, d1 + a3)},
      {"A4", wc, Vec3(-1, 0, 0), -350, 350, 90, 60, Vec3(wc[0] - 300, 0, wc[2])},
      {"A5", wc, Vec3(0, 1, 0), -120, 120, 90, 30, wc},
      {"A6", wc, Vec3(-1, 0, 0), -350, 350, 143, 5, Vec3(wc[0] + d6 - 20, 0, wc[2])},
  };
  for (const Row& r : rows) {
    JointSpec j;
    j.name = r.name;
    j.point = r.point;
    j.axis = r.axis;
    j.lower_deg = r.lo;
    j.upper_deg = r.hi;
    j.max_velocity_deg_s = r.v;
    j.max_acceleration_deg_s2 = 2 * r.v;   // assumption: full speed in 0.5 s
    j.max_jerk_deg_s3 = 20 * r.v;          // assumption: full acceleration in 0.1 s
    j.mass_kg = r.m;
    j.com = r.com;
    s.joints.push_back(j);
  }
  // Tape-laying head: TCP 350 mm beyond the flange on the flange axis, tool z along the flange axis.
  s.tool.xyz = Vec3(wc[0] + d6 + 350, 0, wc[2]);
  s.tool.abc = Vec3(0, 90, 0);
  s.payload_kg = 300;
  s.payload_com = Vec3(0, 0, -150);  // between flange and TCP, in the tool frame
  s.home_deg = {0, -90, 90, 0, 90, 0};  // KUKA's upright home with the head pointing down
  return s;
}

// ---------------------------------------------------------------------------------------------
// Built-in UR10 (Universal Robots, CB3 generation): the standard Denavit-Hartenberg parameters
// Universal Robots publishes ("DH parameters for calculations of kinematics and dynamics": d1 =
// 127.3 mm, a2 = -612 mm, a3 = -572.3 mm, d4 = 163.941 mm, d5 = 115.7 mm, d6 = 92.2 mm, alpha =
// 90, 0, 0, 90, -90, 0 deg; link masses 7.1, 12.7, 4.27, 2.0, 2.0, 0.365 kg with the centres of mass
// of the same page), joint ranges +-360 deg, speeds 120 deg/s (base, shoulder) and 180 deg/s
// (elbow, wrists) from the UR10 data sheet. Zero configuration and joint senses are UR's, so the
// angles a UR controller reports apply unchanged. The tool is the flange (tool0). Not a spherical
// wrist: no closed-form IK; identification and compensation do not need one.
// ---------------------------------------------------------------------------------------------
ModelSpec ur10_spec() {
  ModelSpec s;
  s.name = "ur10";
  const double d[6] = {127.3, 0, 0, 163.941, 115.7, 92.2};
  const double a[6] = {0, -612.0, -572.3, 0, 0, 0};
  const double alpha[6] = {kPi / 2, 0, 0, kPi / 2, -kPi / 2, 0};
  const double mass[6] = {7.1, 12.7, 4.27, 2.0, 2.0, 0.365};
  const Vec3 com[6] = {Vec3(21, 0, 27), Vec3(380, 0, 158), Vec3(240, 0, 68),
                       Vec3(0, 7, 18), Vec3(0, 7, 18), Vec3(0, 0, -26)};
  const double vel[6] = {120, 120, 180, 180, 180, 180};
  const char* names[6] = {"shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"};
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 6; ++i) {
    JointSpec j;
    j.name = names[i];
    j.point = t.translation();
    j.axis = t.linear().col(2);
    // DH frame i: Rz(theta) Tz(d) Tx(a) Rx(alpha) at theta = 0
    t = t * Eigen::Translation3d(0, 0, d[i]) * Eigen::Translation3d(a[i], 0, 0) *
        Eigen::AngleAxisd(alpha[i], Vec3::UnitX());
    j.lower_deg = -360;
    j.upper_deg = 360;
    j.max_velocity_deg_s = vel[i];
    j.max_acceleration_deg_s2 = 2 * vel[i];  // assumption, as for kr500
    j.max_jerk_deg_s3 = 20 * vel[i];
    j.mass_kg = mass[i];
    j.com = t * com[i];
    s.joints.push_back(j);
  }
  s.tool = iso_to_pose(t);
  s.home_deg = {0, -90, 90, -90, -90, 0};
  return s;
}

std::vector<std::string> builtin_names() { return {"kr500", "ur10"}; }

ModelSpec builtin_spec(const std::string& name) {
  if (name == "kr500") return kr500_spec();
  if (name == "ur10") return ur10_spec();
  std::string known;
  for (const auto& n : builtin_names()) known += (known.empty() ? "" : ", ") + n;
  throw InputError("unknown robot '" + name + "': not a built-in name (" + known +
                   "), a .urdf file or a model .json file");
}

ModelSpec perturbed_spec(const ModelSpec& spec, unsigned seed, double sigma_mm, double sigma_deg, double compliance) {
  ModelSpec s = spec;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> ud(0.5, 1.5);
  const Model m(spec);
  for (int j = 0; j < m.dof(); ++j) {
    JointSpec& js = s.joints[j];
    const Vec3 w = m.axis(j);
    const Vec3 u = w.unitOrthogonal(), v = w.cross(u);
    const Vec3 tilt = (nd(rng) * u + nd(rng) * v) * sigma_deg * kDeg;
    js.axis = Eigen::AngleAxisd(tilt.norm(), tilt.norm() > 0 ? tilt.normalized() : u) * w;
    js.point += (nd(rng) * u + nd(rng) * v) * sigma_mm;
    // drawn with compliance 0 too (and dropped): one seed with and without compliance is one geometry
    if (m.gravity_loaded(j)) {
      const double draw = ud(rng);
      if (compliance > 0) js.compliance_deg_per_knm = compliance * draw;
    }
  }
  for (int k = 0; k < 3; ++k) s.tool.xyz[k] += nd(rng) * sigma_mm;
  for (int k = 0; k < 3; ++k) s.tool.abc[k] += nd(rng) * sigma_deg;
  s.name = spec.name + "-perturbed";
  return s;
}

}  // namespace kincal
