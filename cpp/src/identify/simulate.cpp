// kincal: the campaign simulator (every effect of the truth in simulate_point()) and the errors of
// a model's predictions against measured rows.
#include "kincal/identify/simulate.hpp"

#include "kincal/identify/so3.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <random>

namespace kincal {

namespace {

/// The context of a row for the model's effects (its dir and temperature).
EffectContext row_context(const Measurement& row) {
  EffectContext c;
  c.dir = row.dir;
  c.temperature_c = row.temperature_c;
  return c;
}

}  // namespace

Vec3 simulate_point(const Model& truth, const Measurement& row, const Vec3& target) {
  const EffectContext ctx = row_context(row);
  const Eigen::Isometry3d tool = fk(truth, joint_angles(truth, row.q_deg * kDeg, ctx));
  // thermal expansion: every length of the robot, the target's offset included, scales
  return truth.base_in_instrument() * (length_scale(truth, ctx) * (tool * target));
}

ModelSpec with_effects(const ModelSpec& truth, const std::vector<EffectValue>& effects, double t_ref) {
  ModelSpec s = truth;
  if (effects.empty()) return s;
  bool thermal = false;
  for (const auto& e : s.effects) thermal = thermal || e.effect.name == "thermal_expansion";
  if (!thermal) s.t_ref_c = t_ref;
  for (const auto& e : effects) s.effects.push_back(e);
  return s;
}

MeasurementSet simulate(const Model& truth_in, const SimulationOptions& opt) {
  if (opt.poses < 1) throw InputError("simulate: the number of poses must be positive");
  const Model truth(with_effects(truth_in.spec(), opt.effects, opt.t_ref));
  if (opt.targets.empty()) throw InputError("simulate: at least one target");
  MeasurementSet m;
  m.source = "simulated";
  m.n_targets = static_cast<int>(opt.targets.size());
  m.orientation = opt.orientation_noise_deg >= 0;
  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> ud(-0.5, 0.5), u01(0.0, 1.0);
  std::normal_distribution<double> nd(0.0, 1.0);
  const int n = truth.dof();
  for (int p = 0; p < opt.poses; ++p) {
    Measurement row;  // the pose: the same commanded angles, directions and temperature for every target
    row.pose = p;
    row.q_deg.resize(n);
    for (int j = 0; j < n; ++j) {
      const JointSpec& js = truth.spec().joints[j];
      const double mid = 0.5 * (js.lower_deg + js.upper_deg), span = js.upper_deg - js.lower_deg;
      row.q_deg[j] = mid + ud(rng) * span * opt.limit_margin;
    }
    row.dir.resize(n);
    for (int j = 0; j < n; ++j) row.dir[j] = u01(rng) < 0.5 ? -1.0 : 1.0;
    // the temperature drifts through [t_min, t_max] over the campaign (a warm-up, then noise)
    const double frac = opt.poses > 1 ? static_cast<double>(p) / (opt.poses - 1) : 0.0;
    row.temperature_c = opt.t_min + (opt.t_max - opt.t_min) * std::sqrt(frac) + 0.3 * nd(rng);
    for (int t = 0; t < m.n_targets; ++t) {
      row.target = t;
      row.xyz = simulate_point(truth, row, opt.targets[t]);
      row.xyz += Vec3(nd(rng), nd(rng), nd(rng)) * opt.noise_mm;
      if (opt.orientation_noise_deg >= 0) {
        // the measured tool frame (a 6-D probe): truth orientation, then a small random rotation
        const Mat3 r = truth.base_in_instrument().linear() * fk_model(truth, row.q_deg * kDeg, row_context(row)).linear();
        const Vec3 e = Vec3(nd(rng), nd(rng), nd(rng)) * opt.orientation_noise_deg * kDeg;
        row.has_abc = true;
        row.abc = rotation_to_abc(so3::exp(e) * r);
      }
      if (opt.outlier_fraction > 0 && u01(rng) < opt.outlier_fraction)
        row.xyz += Vec3(nd(rng), nd(rng), nd(rng)).normalized() * opt.outlier_mm;
      m.rows.push_back(row);
    }
  }
  return m;
}

std::vector<double> point_errors(const Model& model, const std::vector<Vec3>& targets, const MeasurementSet& data) {
  std::vector<double> e;
  e.reserve(data.rows.size());
  std::map<double, std::shared_ptr<const Model>> variants;
  for (const auto& r : data.rows) {
    const Model* m = &model;
    if (!std::isnan(r.payload_kg) && r.payload_kg != model.spec().payload_kg) {
      auto& v = variants[r.payload_kg];
      if (!v) {
        ModelSpec s = model.spec();
        s.payload_kg = r.payload_kg;
        v = std::make_shared<const Model>(s);
      }
      m = v.get();
    }
    const Vec3 t = r.target < static_cast<int>(targets.size()) ? targets[r.target] : Vec3::Zero();
    e.push_back((simulate_point(*m, r, t) - r.xyz).norm());
  }
  return e;
}

}  // namespace kincal
