// kincal: the effects, the non-geometric effects a model can carry: joint_compliance,
// transmission_error, backlash, thermal_expansion, drift (the instrument's), joint_map and the five-bar's
// link_deflection. Each has a name of the contract, a domain (the serial robot or the five-bar hidden
// robot), what it concerns (one joint, one link, or the whole robot), the data it needs (dir1..dirN,
// temperature_c, time_s), its parameters (names, units) and its action on the model; each is defined
// in its own file, cpp/src/effects/<name>.cpp, which says what it does, and the registry
// (cpp/src/effects/effects.cpp) lists them. Adding an effect: its file, its id in EffectId and its
// line in the registry. The joint-angle effects act on the commanded angle q: the joint stands at
// q + dq(q, dir); compensation inverts them by a fixed point on q after solving the chain for the
// actual angles (compensation/pose.hpp), or by Newton on the whole model where they are steep. Inside
// the core, angles are radians; model files carry degrees (file_scale converts).
#pragma once

#include <string>
#include <vector>

namespace kincal {

/// The effects, one id each (the registry's order); each lives in its own file, cpp/src/effects/<name>.cpp.
enum class EffectId { joint_compliance, transmission_error, backlash, thermal_expansion, drift, joint_map, link_deflection };

struct Effect;

/// One kind of effect: the words users and the contract see, and what the effect does. Each effect
/// defines its kind in its own file (effects/<name>.cpp); the registry (effects.cpp) lists them, so
/// adding an effect touches its file and the registry line. Code elsewhere asks the kind (what the
/// effect acts on, which data column it reads, its basis), never its name.
struct EffectKind {
  EffectId id;
  std::string name;
  std::string domain;        ///< "serial" or "fivebar"
  std::string concerns;      ///< "joint", "link" or "robot"
  std::string needs;         ///< the data column the effect reads: "", "dir", "temperature_c", "time_s"
  std::string acts_on;       ///< "joint_angle", "length_scale", "link_length", "instrument"
  std::string description;
  bool gravity_loaded_only;  ///< per joint only where gravity loads the joint (joint_compliance)
  bool harmonic;             ///< its parameters: a sine and a cosine amplitude per harmonic order of the Effect
  int parameters;            ///< how many parameters it has (a harmonic one: 0, two per order)
  /// parameter names without the joint prefix (e.g. te_sin1, te_cos1) and their core units ("rad",
  /// "1/degC", "deg/kNm", "mm", "mm/h", "rad/h"), one per parameter
  std::vector<std::string> (*parameter_names)(const Effect&);
  std::vector<std::string> (*units)(const Effect&);
  /// the checks of this effect beyond the common ones (its joint, its domain); nullptr: none
  void (*check)(const Effect&, const std::string& who);
  /// a joint-angle effect's basis, dq = sum_k p_k b_k(q, dir) (its derivatives in db when not null);
  /// nullptr for the others
  void (*basis)(const Effect&, double q_rad, double dir, double* b, double* db);
  /// a harmonic effect that carries every order 1..K, named by its order K (joint_map)
  bool ordered = false;
  /// a five-bar link-length effect's basis, dl = sum_k p_k b_k(t1, t2) (the actuated angles, rad);
  /// nullptr for the others
  void (*link_basis)(const Effect&, double t1_rad, double t2_rad, double* b) = nullptr;
  /// needs == "dir", once: compensation asks it for every effect at every evaluation
  bool needs_dir = needs == "dir";
  /// a joint-angle effect whose basis does not depend on the joint angle (backlash: dir only)
  bool angle_free = false;
  bool reads_dir() const { return needs_dir; }                    ///< the direction of motion (dir1..dirN)
  bool scales_lengths() const { return acts_on == "length_scale"; }  ///< scales the robot's lengths
  bool of_instrument() const { return acts_on == "instrument"; }    ///< the measurement's, never the robot's
};

/// Every effect kind, in the order the diagnosis tries them.
const std::vector<EffectKind>& effect_kinds();
/// The kind of a name; InputError naming the known ones when unknown.
const EffectKind& effect_kind(const std::string& name);
/// The kind of an id.
const EffectKind& effect_kind(EffectId id);

/// One effect on one joint (or link), or on the whole robot (joint -1).
struct Effect {
  std::string name;
  int joint = -1;                   ///< 0-based joint (or link) index; -1 for robot-wide effects
  /// transmission_error: the harmonic orders (1 = once per turn); joint_map: 1..K (K its order)
  std::vector<int> harmonics{1, 2};

  Effect() = default;
  Effect(std::string name_, int joint_ = -1, std::vector<int> harmonics_ = {1, 2});
  /// its kind (InputError for an unknown name); id(): the kind's id
  const EffectKind& kind() const { return kind_ ? *kind_ : effect_kind(name); }
  EffectId id() const { return kind().id; }
  int size() const;                  ///< number of parameters
  int order() const;                 ///< joint_map: its order K (the highest harmonic); 0 for the others
  bool harmonic() const { return kind_ && kind_->harmonic; }
  std::string label() const;         ///< e.g. "transmission_error(joint 3)"
  std::vector<std::string> parameter_names() const { return kind().parameter_names(*this); }
  std::vector<std::string> units() const { return kind().units(*this); }
  std::vector<std::string> file_units() const;     ///< units in model files: "deg" for "rad", "deg/h" for "rad/h"
  std::vector<double> file_scale() const;          ///< file value = core value * scale
  bool operator==(const Effect& o) const {
    return name == o.name && joint == o.joint && (!harmonic() || harmonics == o.harmonics);
  }

 private:
  const EffectKind* kind_ = nullptr;  ///< the registry's entry of name (nullptr: unknown)
};

/// An effect with the values of its parameters (core units).
struct EffectValue {
  Effect effect;
  std::vector<double> p;
};

/// The joint_map of order K on a joint (0-based): harmonics 1..K.
Effect joint_map(int joint, int order);

/// Checks an effect for a robot of dof joints (known name, serial domain, joint in range, and the
/// effect's own checks); throws InputError with `who` in front of the cause.
void check_effect(const Effect& e, int dof, const std::string& who);

/// The basis of a joint-angle effect (transmission_error, joint_map, backlash): dq = sum_k p_k b_k(q, dir).
/// Writes size() values to b and, when db is not null, their derivatives with respect to q.
void joint_basis(const Effect& e, double q_rad, double dir, double* b, double* db = nullptr);
/// The basis of a five-bar link-length effect at the actuated angles t1, t2 (rad): its link's length
/// moves by sum_k p_k b[k] (mm). InputError for an effect that has none.
void link_basis(const Effect& e, double t1_rad, double t2_rad, double* b);

}  // namespace kincal
