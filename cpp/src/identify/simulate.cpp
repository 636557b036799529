// kincal: the campaign simulator (every effect of the truth in simulate_point()) and the errors of
// a model's predictions against measured rows.
#include "kincal/identify/simulate.hpp"

#include "kincal/identify/so3.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <algorithm>
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

std::vector<Eigen::Isometry3d> setup_frames(const Campaign& campaign, const MeasurementSet& data) {
  const auto& known = campaign.setups;
  std::vector<Eigen::Isometry3d> out;
  if (known.empty()) {
    if (data.setup_names.size() > 1)
      throw InputError(data.source + ": " + std::to_string(data.setup_names.size()) +
                       " setups but the model knows one instrument placement (identify them together, or "
                       "validate, which refits the placements)");
    out.push_back(campaign.base());
    return out;
  }
  if (data.setup_names.empty()) {
    out.push_back(campaign.base());  // a set without a setup column: the first placement
    return out;
  }
  for (const std::string& name : data.setup_names) {
    const auto it = std::find_if(known.begin(), known.end(), [&](const SetupFrame& f) { return f.name == name; });
    if (it == known.end()) {
      std::string names;
      for (const SetupFrame& f : known) names += (names.empty() ? "" : ", ") + f.name;
      throw InputError(data.source + ": setup '" + name + "' is not one of the model's (" + names + ")");
    }
    out.push_back(pose_to_iso(it->base_in_instrument));
  }
  return out;
}

Eigen::Isometry3d drifted(const Campaign& campaign, const Eigen::Isometry3d& frame, double time_s) {
  if (!campaign.drift) return frame;
  const EffectValue* d = &*campaign.drift;
  if (std::isnan(time_s)) throw InputError("the model's drift needs the time of every measured point (time_s)");
  const double tau = (time_s - campaign.t_mean_s) / 3600.0;
  Eigen::Isometry3d out = frame;
  out.linear() = so3::exp(tau * Vec3(d->p[3], d->p[4], d->p[5])) * frame.linear();
  out.translation() += tau * Vec3(d->p[0], d->p[1], d->p[2]);
  return out;
}

Vec3 simulate_point(const Model& truth, const Campaign& campaign, const Measurement& row, const Vec3& target,
                    const Eigen::Isometry3d& base) {
  const EffectContext ctx = row_context(row);
  const Eigen::Isometry3d tool = fk(truth, joint_angles(truth, row.q_deg * kDeg, ctx));
  // thermal expansion: every length of the robot, the target's offset included, scales
  return drifted(campaign, base, row.time_s) * (length_scale(truth, ctx) * (tool * target));
}

Vec3 simulate_point(const Model& truth, const Campaign& campaign, const Measurement& row, const Vec3& target) {
  return simulate_point(truth, campaign, row, target, campaign.base());
}

ModelSpec with_effects(const ModelSpec& truth, const std::vector<EffectValue>& effects, double t_ref) {
  ModelSpec s = truth;
  bool thermal = false;
  for (const auto& e : s.effects) thermal = thermal || e.effect.kind().scales_lengths();
  for (const auto& e : effects)
    if (!e.effect.kind().of_instrument()) s.effects.push_back(e);  // a drift: the campaign's
  if (!effects.empty() && !thermal) s.t_ref_c = t_ref;
  return s;
}

MeasurementSet simulate(const Model& truth_in, const SimulationOptions& opt, const Campaign& campaign_in) {
  if (opt.poses < 1) throw InputError("simulate: the number of poses must be positive");
  if (!(opt.duration_s >= 0) || !std::isfinite(opt.duration_s))
    throw InputError("simulate: the campaign's duration must be a finite non-negative number of seconds");
  bool hidden_drift = false;
  for (const auto& e : opt.effects) hidden_drift = hidden_drift || e.effect.kind().of_instrument();
  // a drift hidden without a duration: the campaign lasts 3 h; the drift is centred on its mean time
  const double duration = opt.duration_s > 0 ? opt.duration_s : (hidden_drift ? kDefaultDriftDuration_s : 0.0);
  const Model truth(with_effects(truth_in.spec(), opt.effects, opt.t_ref));
  Campaign campaign = campaign_in;  // a hidden drift: the truth's instrument drifts
  for (const auto& e : opt.effects)
    if (e.effect.kind().of_instrument()) {
      if (campaign.drift) throw InputError("simulate: the instrument's drift is given twice");
      campaign.t_mean_s = 0.5 * duration;
      campaign.drift = e;
    }
  campaign.check(truth.dof(), "simulate: ");
  if (campaign.drift && duration <= 0)
    throw InputError("simulate: the truth drifts: the campaign needs a duration (time_s)");
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
    if (duration > 0) row.time_s = duration * frac;  // drawn from nothing: the noise stream is unchanged
    for (int t = 0; t < m.n_targets; ++t) {
      row.target = t;
      row.xyz = simulate_point(truth, campaign, row, opt.targets[t]);
      row.xyz += Vec3(nd(rng), nd(rng), nd(rng)) * opt.noise_mm;
      row.has_abc = false;  // the row of the pose's previous target may have been the 6-D one
      row.abc = Vec3::Zero();
      if (opt.orientation_noise_deg >= 0 && t == 0) {
        // the measured frame (a 6-D probe, the first target; the others are reflectors, points): the
        // tool frame moved by that target's offset, truth orientation, then a small random rotation
        const Mat3 r = drifted(campaign, campaign.base(), row.time_s).linear() *
                       fk_model(truth, row.q_deg * kDeg, row_context(row)).linear();
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

namespace {

/// The model of a row's payload (variants built once per payload).
const Model& payload_model(const Model& model, double payload, std::map<double, std::shared_ptr<const Model>>& variants) {
  if (std::isnan(payload) || payload == model.spec().payload_kg) return model;
  auto& v = variants[payload];
  if (!v) {
    ModelSpec s = model.spec();
    s.payload_kg = payload;
    v = std::make_shared<const Model>(s);
  }
  return *v;
}

const Eigen::Isometry3d& row_frame(const std::vector<Eigen::Isometry3d>& frames, const MeasurementSet& data,
                                   const Measurement& r) {
  if (r.setup < 0 || r.setup >= static_cast<int>(frames.size()))
    throw InputError(data.source + ": a row of setup code " + std::to_string(r.setup) + " but " +
                     std::to_string(frames.size()) + " setup(s)");
  return frames[static_cast<size_t>(r.setup)];
}

}  // namespace

std::vector<double> orientation_errors(const Model& model, const Campaign& campaign, const MeasurementSet& data) {
  const std::vector<Eigen::Isometry3d> frames = setup_frames(campaign, data);
  std::map<double, std::shared_ptr<const Model>> variants;
  std::vector<double> e;
  e.reserve(data.rows.size());
  for (const auto& r : data.rows) {
    if (!r.has_abc) continue;  // a reflector row among 6-D rows
    const Model& m = payload_model(model, r.payload_kg, variants);
    const Mat3 rot = drifted(campaign, row_frame(frames, data, r), r.time_s).linear() *
                     fk_model(m, r.q_deg * kDeg, row_context(r)).linear();
    e.push_back(so3::log(abc_to_rotation(r.abc).transpose() * rot).norm() / kDeg);
  }
  return e;
}

std::vector<double> point_errors(const Model& model, const Campaign& campaign, const std::vector<Vec3>& targets,
                                 const MeasurementSet& data) {
  return point_errors(model, campaign, targets, data, {});
}

std::vector<double> point_errors(const Model& model, const Campaign& campaign, const std::vector<Vec3>& targets,
                                 const MeasurementSet& data, const std::vector<StationValue>& stations) {
  const std::vector<Eigen::Isometry3d> frames = setup_frames(campaign, data);
  std::vector<double> e;
  e.reserve(data.rows.size());
  std::map<double, std::shared_ptr<const Model>> variants;
  for (const auto& r : data.rows) {
    const Model& m = payload_model(model, r.payload_kg, variants);
    const Vec3 t = r.target < static_cast<int>(targets.size()) ? targets[r.target] : Vec3::Zero();
    const Vec3 y = simulate_point(m, campaign, r, t, row_frame(frames, data, r));
    if (!is_probe(r.kind)) {
      e.push_back((y - r.xyz).norm());
      continue;
    }
    const StationValue* s = station_of(stations, data, r);
    double res[3];
    e.push_back(s ? Eigen::Map<const Eigen::VectorXd>(res, probe_residual(*s, r, y, res)).norm() : std::nan(""));
  }
  return e;
}

}  // namespace kincal
