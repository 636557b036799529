#include "kincal/effects/effects.hpp"

#include <algorithm>
#include <cmath>

#include "kincal/core/fastmath.hpp"
#include "kincal/model/model.hpp"

namespace kincal {

const std::vector<EffectKind>& effect_kinds() {
  static const std::vector<EffectKind> kinds = {
      {"joint_compliance", "serial", "joint", "", "joint_angle",
       "joint deflection proportional to the gravity torque (deg per kN m)", true},
      {"transmission_error", "serial", "joint", "", "joint_angle",
       "errors periodic in the joint angle: sine and cosine amplitudes of each harmonic order (deg)", false},
      {"backlash", "serial", "joint", "dir", "joint_angle",
       "an offset of the joint angle that depends on the approach direction: b dir (deg)", false},
      {"thermal_expansion", "serial", "robot", "temperature_c", "length_scale",
       "the robot's lengths scale by 1 + alpha (T - t_ref) (alpha per deg C)", false},
      {"drift", "serial", "robot", "time_s", "instrument",
       "the instrument's placement moving linearly with time (a property of the measurement: removed from "
       "the fit, never compensated): translation mm/h and rotation deg/h about the campaign's mean time",
       false},
      {"joint_map", "serial", "joint", "", "joint_angle",
       "a smooth periodic error of the joint angle of any order K: sine and cosine amplitudes of orders 1..K (deg)",
       false},
      {"link_deflection", "fivebar", "link", "", "link_length",
       "a link length that varies with the pose: p1 cos t1 + p2 sin t1 + p3 cos t2 + p4 sin t2 (mm)", false},
  };
  return kinds;
}

const EffectKind& effect_kind(const std::string& name) {
  for (const EffectKind& k : effect_kinds())
    if (k.name == name) return k;
  std::string known;
  for (const EffectKind& k : effect_kinds()) known += (known.empty() ? "" : ", ") + k.name;
  throw InputError("unknown effect '" + name + "' (known: " + known + ")");
}

int Effect::size() const {
  if (harmonic()) return 2 * static_cast<int>(harmonics.size());
  if (name == "link_deflection") return 4;
  if (name == "drift") return 6;
  effect_kind(name);
  return 1;
}

int Effect::order() const { return name == "joint_map" && !harmonics.empty() ? harmonics.back() : 0; }

Effect joint_map(int joint, int order) {
  Effect e{"joint_map", joint, {}};
  for (int k = 1; k <= order; ++k) e.harmonics.push_back(k);
  return e;
}

std::string Effect::label() const {
  if (joint < 0) return name;
  return name + "(" + (effect_kind(name).concerns == "link" ? "link " : "joint ") + std::to_string(joint + 1) + ")";
}

std::vector<std::string> Effect::parameter_names() const {
  if (harmonic()) {
    const std::string p = name == "joint_map" ? "map_" : "te_";
    std::vector<std::string> n;
    for (int k : harmonics) n.push_back(p + "sin" + std::to_string(k)), n.push_back(p + "cos" + std::to_string(k));
    return n;
  }
  if (name == "link_deflection") return {"p1_cos_t1", "p2_sin_t1", "p3_cos_t2", "p4_sin_t2"};
  if (name == "joint_compliance") return {"compliance"};
  if (name == "backlash") return {"backlash"};
  if (name == "thermal_expansion") return {"thermal_expansion"};
  if (name == "drift") return {"drift_x", "drift_y", "drift_z", "drift_rx", "drift_ry", "drift_rz"};
  effect_kind(name);
  return {};
}

std::vector<std::string> Effect::units() const {
  if (name == "drift") return {"mm/h", "mm/h", "mm/h", "rad/h", "rad/h", "rad/h"};
  std::string u = "rad";
  if (name == "joint_compliance") u = "deg/kNm";
  if (name == "thermal_expansion") u = "1/degC";
  if (name == "link_deflection") u = "mm";
  return std::vector<std::string>(static_cast<size_t>(size()), u);
}

std::vector<std::string> Effect::file_units() const {
  std::vector<std::string> u = units();
  for (auto& s : u)
    if (s == "rad") s = "deg";
    else if (s == "rad/h") s = "deg/h";
  return u;
}

std::vector<double> Effect::file_scale() const {
  std::vector<double> s;
  for (const auto& u : units()) s.push_back(u == "rad" || u == "rad/h" ? 1 / kDeg : 1.0);
  return s;
}

void check_effect(const Effect& e, int dof, const std::string& who) {
  const EffectKind& k = effect_kind(e.name);
  if (k.domain != "serial")
    throw InputError(who + e.name + " belongs to the five-bar hidden robot, not to a serial robot");
  if (k.concerns == "robot") {
    if (e.joint != -1) throw InputError(who + e.name + " concerns the whole robot, not one joint");
  } else if (e.joint < 0 || e.joint >= dof) {
    throw InputError(who + e.name + ": joint " + std::to_string(e.joint + 1) + " is not one of 1.." +
                     std::to_string(dof));
  }
  if (e.name == "transmission_error") {
    if (e.harmonics.empty()) throw InputError(who + "transmission_error needs at least one harmonic order");
    for (size_t i = 0; i < e.harmonics.size(); ++i) {
      if (e.harmonics[i] < 1 || e.harmonics[i] > 64)
        throw InputError(who + "transmission_error: harmonic order " + std::to_string(e.harmonics[i]) +
                         " is not one of 1..64");
      if (std::count(e.harmonics.begin(), e.harmonics.end(), e.harmonics[i]) > 1)
        throw InputError(who + "transmission_error: harmonic order " + std::to_string(e.harmonics[i]) + " twice");
    }
  }
  if (e.name == "joint_map") {
    const int k = static_cast<int>(e.harmonics.size());
    if (k < 1 || k > 64) throw InputError(who + "joint_map: the order must be 1..64, not " + std::to_string(k));
    for (int i = 0; i < k; ++i)
      if (e.harmonics[i] != i + 1)
        throw InputError(who + "joint_map carries every harmonic order 1..K (its order K), not an order " +
                         std::to_string(e.harmonics[i]) + " at place " + std::to_string(i + 1));
  }
}

void joint_basis(const Effect& e, double q, double dir, double* b, double* db) {
  if (e.name == "backlash") {
    b[0] = dir;
    if (db) db[0] = 0;
    return;
  }
  // transmission_error, joint_map: sin(kq), cos(kq) of each order from sin q, cos q by the angle-addition rule
  double s1, c1;
  fastmath::sincos(q, s1, c1);
  int have = 1;
  double sk = s1, ck = c1;
  for (size_t i = 0; i < e.harmonics.size(); ++i) {
    const int k = e.harmonics[i];
    if (k < have) have = 1, sk = s1, ck = c1;  // orders out of ascending sequence: start again
    while (have < k) {
      const double s = sk * c1 + ck * s1;
      ck = ck * c1 - sk * s1;
      sk = s;
      ++have;
    }
    b[2 * i] = sk;
    b[2 * i + 1] = ck;
    if (db) db[2 * i] = k * ck, db[2 * i + 1] = -k * sk;
  }
}

}  // namespace kincal
