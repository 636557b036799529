// kincal: the effect registry, the one list of the non-geometric effects a model can carry.
//
// Every effect has a name of the contract, a domain (the serial robot or the five-bar hidden robot),
// what it concerns (one joint, one link, or the whole robot), the data it needs (dir1..dirN,
// temperature_c), its parameters (names, units) and its action on the model:
//   joint_compliance   (serial, per gravity-loaded joint)  dq_j = c_j tau_j(q)       c in deg per kN m
//   transmission_error (serial, per joint)  dq_j = sum_k s_k sin(k q_j) + c_k cos(k q_j), harmonic
//                      orders k an option (default 1 and 2)                         amplitudes in deg
//   backlash           (serial, per joint)  dq_j = b_j dir_j, dir_j = +-1 the sign of the last motion
//                      into the pose; a gear's play makes the joint lag behind the command: b < 0 b in deg
//                      (with b > 0, a lead, a reversal smaller than 2|b| has no commanded angle that
//                      reaches the pose: the compensated program then misses it by up to 2|b|)
//   thermal_expansion  (serial, robot)      every length of the robot scales by 1 + alpha (T - t_ref):
//                      the tool point in the base frame scales about the base origin alpha in 1/degC
//   joint_map          (serial, per joint)  a smooth periodic error of the joint angle of any order K:
//                      dq_j = sum_{k=1..K} s_k sin(k q_j) + c_k cos(k q_j) (harmonics = 1..K)
//                                                                                amplitudes in deg
//   drift              (serial, robot, a property of the measurement) the instrument's placement
//                      moves linearly with time: a point x of the robot base frame is seen at
//                      Exp(tau w) R x + t + tau v instead of R x + t (R, t the placement: the
//                      rotation turns about the robot base's origin, v and w in the instrument's
//                      axes), tau = (t_s - t_mean) / 3600 s in hours, t_mean the campaign's mean time
//                      (ModelSpec::t_mean_s). Removed from the fit and reported; a Model carries it
//                      inert: FK and compensation never apply it.   v in mm/h, w in rad/h (deg/h in files)
//   link_deflection    (five-bar, per link) the link's length varies as p1 cos t1 + p2 sin t1 +
//                      p3 cos t2 + p4 sin t2                                          p in mm
// The joint-angle effects act on the commanded angle q: the joint stands at q + dq(q, dir). Their
// inverse in compensation is Newton on the whole model (the commanded q such that q + dq(q) is the
// angle needed); thermal expansion scales the position. Inside the core, angles are radians; model
// files carry degrees (file_scale converts).
#pragma once

#include <string>
#include <vector>

namespace kincal {

struct EffectKind {
  std::string name;
  std::string domain;        ///< "serial" or "fivebar"
  std::string concerns;      ///< "joint", "link" or "robot"
  std::string needs;         ///< the data column the effect reads: "", "dir", "temperature_c", "time_s"
  std::string acts_on;       ///< "joint_angle", "length_scale", "link_length", "instrument"
  std::string description;
  bool gravity_loaded_only;  ///< per joint only where gravity loads the joint (joint_compliance)
};

/// Every effect kind, in the order the diagnosis tries them.
const std::vector<EffectKind>& effect_kinds();
/// The kind of a name; InputError naming the known ones when unknown.
const EffectKind& effect_kind(const std::string& name);

/// One effect on one joint (or link), or on the whole robot (joint -1).
struct Effect {
  std::string name;
  int joint = -1;                   ///< 0-based joint (or link) index; -1 for robot-wide effects
  /// transmission_error: the harmonic orders (1 = once per turn); joint_map: 1..K (K its order)
  std::vector<int> harmonics{1, 2};
  int size() const;                  ///< number of parameters
  int order() const;                 ///< joint_map: its order K (the highest harmonic); 0 for the others
  bool harmonic() const { return name == "transmission_error" || name == "joint_map"; }
  std::string label() const;         ///< e.g. "transmission_error(joint 3)"
  /// parameter names without the joint prefix, e.g. te_sin1, te_cos1; and their core units
  std::vector<std::string> parameter_names() const;
  std::vector<std::string> units() const;          ///< "rad", "1/degC", "deg/kNm", "mm", "mm/h", "rad/h"
  std::vector<std::string> file_units() const;     ///< units in model files: "deg" for "rad", "deg/h" for "rad/h"
  std::vector<double> file_scale() const;          ///< file value = core value * scale
  bool operator==(const Effect& o) const {
    return name == o.name && joint == o.joint && (!harmonic() || harmonics == o.harmonics);
  }
};

/// An effect with the values of its parameters (core units).
struct EffectValue {
  Effect effect;
  std::vector<double> p;
};

/// The joint_map of order K on a joint (0-based): harmonics 1..K.
Effect joint_map(int joint, int order);

/// Checks an effect for a robot of dof joints (known name, serial domain, joint in range, harmonic
/// orders positive and distinct, joint_map's 1..K); throws InputError with `who` in front of the cause.
void check_effect(const Effect& e, int dof, const std::string& who);

/// The basis of a joint-angle effect (transmission_error, joint_map, backlash): dq = sum_k p_k b_k(q, dir).
/// Writes size() values to b and, when db is not null, their derivatives with respect to q.
void joint_basis(const Effect& e, double q_rad, double dir, double* b, double* db = nullptr);

}  // namespace kincal
