// kincal: the effect registry (the list of the effects, each defined in its own file of this folder)
// and what every effect shares: its label, units in files, the common checks and the basis dispatch.
#include "kincal/effects/effects.hpp"

#include "kincal/model/model.hpp"

#include <stdexcept>

namespace kincal {

// each effect's kind, defined in its own file of this folder
const EffectKind& joint_compliance_kind();
const EffectKind& transmission_error_kind();
const EffectKind& backlash_kind();
const EffectKind& thermal_expansion_kind();
const EffectKind& drift_kind();
const EffectKind& joint_map_kind();
const EffectKind& link_deflection_kind();

const std::vector<EffectKind>& effect_kinds() {
  // the registry: one line per effect, in the order the diagnosis tries them
  static const std::vector<EffectKind> kinds = {joint_compliance_kind(), transmission_error_kind(), backlash_kind(),
                                                thermal_expansion_kind(),  drift_kind(),
                                                joint_map_kind(),          link_deflection_kind()};
  return kinds;
}

const EffectKind& effect_kind(const std::string& name) {
  for (const EffectKind& k : effect_kinds())
    if (k.name == name) return k;
  std::string known;
  for (const EffectKind& k : effect_kinds()) known += (known.empty() ? "" : ", ") + k.name;
  throw InputError("unknown effect '" + name + "' (known: " + known + ")");
}

const EffectKind& effect_kind(EffectId id) {
  for (const EffectKind& k : effect_kinds())
    if (k.id == id) return k;
  throw std::logic_error("an effect id without a registry entry");
}

Effect::Effect(std::string name_, int joint_, std::vector<int> harmonics_)
    : name(std::move(name_)), joint(joint_), harmonics(std::move(harmonics_)) {
  for (const EffectKind& k : effect_kinds())
    if (k.name == name) kind_ = &k;
}

int Effect::size() const {
  if (harmonic()) return 2 * static_cast<int>(harmonics.size());
  return kind().parameters;
}

int Effect::order() const { return id() == EffectId::joint_map && !harmonics.empty() ? harmonics.back() : 0; }

std::string Effect::label() const {
  if (joint < 0) return name;
  return name + "(" + (effect_kind(name).concerns == "link" ? "link " : "joint ") + std::to_string(joint + 1) + ")";
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
  if (k.check) k.check(e, who);
}

void joint_basis(const Effect& e, double q, double dir, double* b, double* db) {
  const EffectKind& k = e.kind();
  if (!k.basis) throw InputError(e.name + " is no joint-angle effect (it has no basis)");
  k.basis(e, q, dir, b, db);
}

void link_basis(const Effect& e, double t1, double t2, double* b) {
  const EffectKind& k = e.kind();
  if (!k.link_basis) throw InputError(e.name + " is no link-length effect (it has no link basis)");
  k.link_basis(e, t1, t2, b);
}

}  // namespace kincal
