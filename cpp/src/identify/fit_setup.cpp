// kincal: what a fit asks of the data and the effects before Ceres runs (fit_setup.hpp).
#include "fit_setup.hpp"
#include "kincal/identify/identifiability.hpp"

#include "kincal/kinematics/kinematics.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

namespace kincal::fit_setup {

namespace {

bool same_effect(const Effect& a, const Effect& b) { return a.name == b.name && a.joint == b.joint; }

bool has_thermal(const std::vector<Effect>& effects) {
  return std::any_of(effects.begin(), effects.end(), [](const Effect& e) { return e.kind().scales_lengths(); });
}

}  // namespace

/// "source:line: cause" of a measured row.
std::string where(const MeasurementSet& data, const Measurement& r) {
  return data.source + ":" + std::to_string(r.line);
}

/// InputError unless every row has the robot's number of joint angles and every probe station enough
/// rows (a plane's ball centres not on one line).
void check_rows(const Model& nominal, const MeasurementSet& data) {
  for (const auto& r : data.rows)
    if (r.q_deg.size() != nominal.dof())
      throw InputError(where(data, r) + ": " + std::to_string(r.q_deg.size()) + " joint angles but the robot has " +
                       std::to_string(nominal.dof()));
  for (size_t k = 0; k < data.station_names.size(); ++k) {
    std::vector<const Measurement*> rows;
    for (const auto& r : data.rows)
      if (r.station == static_cast<int>(k)) rows.push_back(&r);
    if (rows.empty()) continue;  // a station of the campaign none of these rows touch (a fold)
    const MeasureKind kind = data.station_kinds[k];
    // a station's own unknowns take 3 equations: a sphere's 2 rows, a plane's or a ballbar's 3 rows
    // leave nothing for the robot; one row more at the least
    const size_t need = kind == MeasureKind::sphere ? 3 : 4;
    const std::string name = "station '" + data.station_names[k] + "'";
    if (rows.size() < need)
      throw InputError(where(data, *rows.front()) + ": " + name + " has " + std::to_string(rows.size()) + " row(s); a " +
                       to_string(kind) + " station needs " + std::to_string(need) + " at least");
    if (kind != MeasureKind::plane) continue;
    // the ball centres on the nominal model: spread over the plane, not along one line
    Eigen::Matrix3Xd y(3, rows.size());
    for (size_t j = 0; j < rows.size(); ++j)
      y.col(static_cast<Eigen::Index>(j)) = fk_compliant(nominal, rows[j]->q_deg * kDeg).translation();
    const Eigen::Matrix3Xd c = y.colwise() - y.rowwise().mean();
    const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(c);
    const Vec3 sv = svd.singularValues() / std::sqrt(static_cast<double>(rows.size()));
    if (sv[1] < std::max(0.5, 1e-3 * sv[0]))  // mm RMS across the line
      throw InputError(where(data, *rows.front()) + ": " + name + ": its touches lie on a line (" +
                       std::to_string(sv[1]).substr(0, 5) + " mm across it); a plane needs touches spread over it");
  }
}

const MeasurementSet& measured_artifact(const MeasurementSet& data, MeasurementSet& copy) {
  std::vector<bool> touched(data.station_names.size(), false);
  for (const auto& r : data.rows)
    if (r.station >= 0) touched[static_cast<size_t>(r.station)] = true;
  auto kept = [&](const ArtifactTerm& a) { return touched[static_cast<size_t>(a.a)] && touched[static_cast<size_t>(a.b)]; };
  if (std::all_of(data.artifact.begin(), data.artifact.end(), kept)) return data;
  copy = data;
  copy.artifact.clear();
  for (const ArtifactTerm& a : data.artifact)
    if (kept(a)) copy.artifact.push_back(a);
  return copy;
}

/// The extra effects: those asked for, then those the starting model carries (held at their values;
/// a model carries no drift: that is its campaign's, which a refit does not carry over).
std::vector<Effect> effects_to_identify(const Model& nominal, const IdentifyOptions& opt) {
  std::vector<Effect> effects = opt.effects;
  for (const EffectValue& ev : nominal.spec().effects) {
    bool asked = false;
    for (const Effect& e : effects) asked = asked || same_effect(e, ev.effect);
    if (!asked) effects.push_back(ev.effect);
  }
  return effects;
}


/// The reference temperature of thermal_expansion: the starting model's, or the mean of the data's
/// when the effect is new to the model.
double reference_temperature(const Model& nominal, const MeasurementSet& data, const std::vector<Effect>& effects) {
  if (!has_thermal(effects) || nominal.thermal_alpha() != 0) return nominal.spec().t_ref_c;
  double sum = 0;
  for (const auto& r : data.rows) sum += r.temperature_c;
  return sum / data.rows.size();
}

/// The drift's reference time: the data's mean time (the placements are those of that moment).
double reference_time(const MeasurementSet& data, const std::vector<Effect>& effects) {
  if (std::none_of(effects.begin(), effects.end(), [](const Effect& e) { return e.kind().of_instrument(); })) return 0;
  double sum = 0;
  for (const auto& r : data.rows) sum += r.time_s;
  return sum / data.rows.size();
}

/// Effects the starting model carries start from its values; those not asked for are held there.
void start_carried_effects(const Model& nominal, const IdentifyOptions& opt, IdentifyResult& res) {
  const ParamLayout& L = res.layout;
  for (size_t e = 0; e < L.effect_list.size(); ++e)
    for (const EffectValue& ev : nominal.spec().effects)
      if (same_effect(ev.effect, L.effect_list[e]) && static_cast<int>(ev.p.size()) == L.effect_list[e].size()) {
        const bool asked = e < opt.effects.size();
        for (size_t k = 0; k < ev.p.size(); ++k) {
          const int i = L.effect_offset[e] + static_cast<int>(k);
          res.start[i] = ev.p[k];
          if (!asked) res.fix(i, "carried by the starting model (not asked for)");
        }
      }
}

/// The free parameters; InputError when the data give no more equations than them or, with priors,
/// fewer measured points than there are free parameters without a prior (the frames: what only the
/// data can determine; a frame held as unseen, hold_unseen_frames, counts as free).
std::vector<int> free_parameters(const MeasurementSet& data, const IdentifyResult& res, const std::vector<double>& sd) {
  std::vector<int> free_idx;
  size_t unconstrained = 0, unseen = 0;  // the frames held because these rows do not see them count as free here
  for (int i = 0; i < res.layout.size; ++i) {
    if (!res.fixed[i]) free_idx.push_back(i), unconstrained += std::isfinite(sd[i]) ? 0 : 1;
    if (held_unseen(res, i)) ++unseen;
  }
  const size_t n_free = free_idx.size() + unseen;
  unconstrained += unseen;
  size_t nres = 0;  // a reflector row among 6-D rows gives 3 equations
  for (const auto& r : data.rows) nres += data.orientation && r.has_abc ? 6 : position_equations(r);
  nres += data.artifact.size();
  const std::string points = data.source + ": " + std::to_string(data.rows.size()) + " measured points";
  if (unconstrained == n_free && nres <= n_free)
    throw InputError(points + " give " + std::to_string(nres) + " equations for " + std::to_string(n_free) +
                     " free parameters: too few to identify the model");
  if (unconstrained < n_free && data.rows.size() < unconstrained)
    throw InputError(points + " for " + std::to_string(unconstrained) +
                     " free parameters without a prior (frames and targets): too few to identify the model");
  return free_idx;
}

}  // namespace kincal::fit_setup

namespace kincal {

/// InputError unless the effects are valid for the robot and the data carry the columns they read
/// (identify.hpp).
void check_effect_columns(const Model& nominal, const MeasurementSet& data, const std::vector<Effect>& effects) {
  for (const Effect& e : effects) check_effect(e, nominal.dof(), "");
  for (const Effect& e : effects) {  // the column each effect reads (the registry's "needs")
    const std::string& column = e.kind().needs;
    for (const auto& r : data.rows) {
      if (column == "temperature_c" && std::isnan(r.temperature_c))
        throw InputError(fit_setup::where(data, r) + ": " + e.name + " needs the temperature_c column");
      if (column == "time_s" && std::isnan(r.time_s))
        throw InputError(fit_setup::where(data, r) + ": " + e.name + " needs the time_s column (when each point was measured, s)");
      if (column == "dir" && r.dir.size() != nominal.dof())
        throw InputError(fit_setup::where(data, r) + ": " + e.name + " needs the dir1..dir" + std::to_string(nominal.dof()) +
                         " columns (the sign of each joint's last motion into the pose)");
    }
  }
}

}  // namespace kincal
