#include "kincal/io/model_json.hpp"

#include "kincal/model/coverage.hpp"
#include "kincal/model/joint_convention.hpp"

#include "kincal/model/robots.hpp"

#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

namespace kincal {

using json = nlohmann::json;

namespace {

json v3(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }
json pose_json(const Pose6& p) { return json{{"xyz_mm", v3(p.xyz)}, {"abc_deg", v3(p.abc)}}; }

json effect_json(const Effect& e, const std::vector<double>& p) {
  json params = json::array();
  const auto names = e.parameter_names();
  const auto units = e.file_units();
  const auto scale = e.file_scale();
  for (size_t k = 0; k < p.size(); ++k)
    params.push_back(json{{"name", names[k]}, {"value", p[k] * scale[k]}, {"unit", units[k]}});
  json o{{"effect", e.name}, {"joint", e.joint >= 0 ? json(e.joint + 1) : json(nullptr)}, {"parameters", params}};
  if (e.id() == EffectId::joint_map) o["order"] = e.order();  // its harmonics are 1..order
  else if (e.harmonic()) o["harmonics"] = e.harmonics;
  return o;
}

/// Version 2: every effect of the model, compliance included (effect, joint from 1, parameters with
/// units of the file: degrees, not radians)
json effects_json(const ModelSpec& s) {
  json out = json::array();
  for (size_t j = 0; j < s.joints.size(); ++j)
    if (s.joints[j].compliance_deg_per_knm != 0)
      out.push_back(effect_json(Effect{effect_kind(EffectId::joint_compliance).name, static_cast<int>(j), {}},
                                {s.joints[j].compliance_deg_per_knm}));
  for (const EffectValue& ev : s.effects) out.push_back(effect_json(ev.effect, ev.p));
  return out;
}

json spec_json(const ModelSpec& s) {
  json joints = json::array();
  for (const JointSpec& j : s.joints) {
    joints.push_back(json{{"name", j.name},
                          {"point_mm", v3(j.point)},
                          {"axis", v3(j.axis)},
                          {"limits_deg", json::array({j.lower_deg, j.upper_deg})},
                          {"max_velocity_deg_s", j.max_velocity_deg_s},
                          {"max_acceleration_deg_s2", j.max_acceleration_deg_s2},
                          {"max_jerk_deg_s3", j.max_jerk_deg_s3},
                          {"mass_kg", j.mass_kg},
                          {"com_mm", v3(j.com)},
                          {"compliance_deg_per_knm", j.compliance_deg_per_knm}});
  }
  json o{{"name", s.name},
         {"joints", joints},
         {"tool", pose_json(s.tool)},
         {"payload", json{{"mass_kg", s.payload_kg}, {"com_mm", v3(s.payload_com)}}},
         {"gravity_m_s2", v3(s.gravity)},
         {"home_deg", s.home_deg},
         {"effects", effects_json(s)},
         {"t_ref_c", s.t_ref_c}};
  return o;
}

/// Version 3's "campaign" section: the instrument's placement, every setup's when there are several,
/// its drift and the drift's centre when it drifts, the joint ranges the identification saw.
json campaign_json(const Campaign& c) {
  json o{{"base_in_instrument", pose_json(c.base_in_instrument)}};
  if (!c.setups.empty()) {
    json setups = json::array();
    for (const SetupFrame& f : c.setups)
      setups.push_back(json{{"name", f.name}, {"base_in_instrument", pose_json(f.base_in_instrument)}});
    o["setups"] = setups;
  }
  if (c.drift) {
    o["drift"] = effect_json(c.drift->effect, c.drift->p);
    o["t_mean_s"] = c.t_mean_s;
  }
  if (!c.fitted_deg.empty()) {
    json r = json::array();
    for (const JointRange& j : c.fitted_deg) r.push_back(json::array({j[0], j[1]}));
    o["fitted_joint_ranges_deg"] = r;
  }
  return o;
}

struct Reader {
  std::string source;
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InputError(source + ": " + where + ": " + what);
  }
  const json& at(const json& o, const char* key, const std::string& where) const {
    if (!o.is_object() || !o.contains(key)) fail(where, std::string("missing key '") + key + "'");
    return o.at(key);
  }
  double num(const json& o, const char* key, const std::string& where) const {
    const json& v = at(o, key, where);
    if (!v.is_number()) fail(where + "." + key, "not a number");
    return v.get<double>();
  }
  /// A figure that may be undefined: null (how kincal writes an undefined figure) reads as ``unknown``.
  double num_or_null(const json& o, const char* key, const std::string& where, double unknown) const {
    if (at(o, key, where).is_null()) return unknown;
    return num(o, key, where);
  }
  Vec3 vec(const json& o, const char* key, const std::string& where) const {
    const json& v = at(o, key, where);
    if (!v.is_array() || v.size() != 3) fail(where + "." + key, "needs 3 numbers");
    Vec3 r;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number()) fail(where + "." + key, "needs 3 numbers");
      r[i] = v[i].get<double>();
    }
    return r;
  }
  Pose6 pose(const json& o, const char* key, const std::string& where) const {
    const json& v = at(o, key, where);
    return Pose6{vec(v, "xyz_mm", where + "." + key), vec(v, "abc_deg", where + "." + key)};
  }
  ModelSpec spec(const json& o, const std::string& where) const {
    ModelSpec s;
    const json& name = at(o, "name", where);
    if (!name.is_string()) fail(where + ".name", "not a string");
    s.name = name.get<std::string>();
    const json& joints = at(o, "joints", where);
    if (!joints.is_array() || joints.empty()) fail(where + ".joints", "needs a non-empty list");
    for (size_t i = 0; i < joints.size(); ++i) {
      const std::string w = where + ".joints[" + std::to_string(i) + "]";
      const json& jo = joints[i];
      JointSpec j;
      if (jo.contains("name") && jo["name"].is_string()) j.name = jo["name"].get<std::string>();
      j.point = vec(jo, "point_mm", w);
      j.axis = vec(jo, "axis", w);
      const json& lim = at(jo, "limits_deg", w);
      if (!lim.is_array() || lim.size() != 2 || !lim[0].is_number() || !lim[1].is_number())
        fail(w + ".limits_deg", "needs [lower, upper]");
      j.lower_deg = lim[0].get<double>();
      j.upper_deg = lim[1].get<double>();
      // a limit not known (0) may be written as null (an infinite limit from a URDF: no limit known)
      j.max_velocity_deg_s = num_or_null(jo, "max_velocity_deg_s", w, 0.0);
      j.max_acceleration_deg_s2 = num_or_null(jo, "max_acceleration_deg_s2", w, 0.0);
      j.max_jerk_deg_s3 = num_or_null(jo, "max_jerk_deg_s3", w, 0.0);
      j.mass_kg = num(jo, "mass_kg", w);
      j.com = vec(jo, "com_mm", w);
      j.compliance_deg_per_knm = num(jo, "compliance_deg_per_knm", w);
      s.joints.push_back(j);
    }
    s.tool = pose(o, "tool", where);
    const json& pl = at(o, "payload", where);
    s.payload_kg = num(pl, "mass_kg", where + ".payload");
    s.payload_com = vec(pl, "com_mm", where + ".payload");
    s.gravity = vec(o, "gravity_m_s2", where);
    const json& home = at(o, "home_deg", where);
    if (!home.is_array()) fail(where + ".home_deg", "needs a list");
    for (const json& h : home) {
      if (!h.is_number()) fail(where + ".home_deg", "needs numbers");
      s.home_deg.push_back(h.get<double>());
    }
    if (o.contains("t_ref_c")) s.t_ref_c = num(o, "t_ref_c", where);
    if (o.contains("effects")) {
      const json& effs = o["effects"];
      if (!effs.is_array()) fail(where + ".effects", "needs a list");
      for (size_t i = 0; i < effs.size(); ++i) s.effects.push_back(effect(effs[i], where + ".effects[" + std::to_string(i) + "]"));
    }
    return s;
  }
  /// The campaign's keys of an object: version 3's "campaign" section, or (`legacy`, versions 1 and 2)
  /// the model's own section, whose drift sits among its effects (moved out of *legacy here).
  Campaign campaign(const json& o, const std::string& where, int dof, ModelSpec* legacy) const {
    Campaign c;
    c.base_in_instrument = pose(o, "base_in_instrument", where);
    if (o.contains("t_mean_s")) c.t_mean_s = num(o, "t_mean_s", where);
    if (o.contains("setups")) {
      const json& setups = o["setups"];
      if (!setups.is_array()) fail(where + ".setups", "needs a list");
      for (size_t i = 0; i < setups.size(); ++i) {
        const std::string w = where + ".setups[" + std::to_string(i) + "]";
        const json& name = at(setups[i], "name", w);
        if (!name.is_string()) fail(w + ".name", "not a string");
        c.setups.push_back(SetupFrame{name.get<std::string>(), pose(setups[i], "base_in_instrument", w)});
      }
    }
    if (o.contains("fitted_joint_ranges_deg")) {
      const std::string w = where + ".fitted_joint_ranges_deg";
      const json& r = o["fitted_joint_ranges_deg"];
      if (!r.is_array()) fail(w, "needs a list of [lo, hi] per joint");
      for (size_t i = 0; i < r.size(); ++i) {
        const json& j = r[i];
        if (!j.is_array() || j.size() != 2 || !j[0].is_number() || !j[1].is_number())
          fail(w + "[" + std::to_string(i) + "]", "needs [lo, hi] (deg)");
        c.fitted_deg.push_back({j[0].get<double>(), j[1].get<double>()});
      }
      check_joint_ranges(c.fitted_deg, dof, source + ": " + w);
    }
    if (legacy) {
      std::vector<EffectValue> robot;
      for (EffectValue& ev : legacy->effects)
        if (!ev.effect.kind().of_instrument())
          robot.push_back(ev);
        else if (c.drift)
          fail(where + ".effects", "the instrument's drift is given twice");
        else
          c.drift = ev;
      legacy->effects = robot;
    } else if (o.contains("drift")) {
      c.drift = effect(o["drift"], where + ".drift");
    }
    return c;
  }
  EffectValue effect(const json& eo, const std::string& w) const {
    EffectValue ev;
    const json& name = at(eo, "effect", w);
    if (!name.is_string()) fail(w + ".effect", "not a string");
    ev.effect = Effect(name.get<std::string>());
    try {
      effect_kind(ev.effect.name);
    } catch (const InputError& e) {
      fail(w + ".effect", e.what());
    }
    const json& joint = at(eo, "joint", w);
    if (joint.is_null()) {
      ev.effect.joint = -1;
    } else if (joint.is_number_integer()) {
      ev.effect.joint = joint.get<int>() - 1;
    } else {
      fail(w + ".joint", "needs a joint number (from 1) or null");
    }
    if (eo.contains("harmonics")) {
      const json& h = eo["harmonics"];
      if (!h.is_array()) fail(w + ".harmonics", "needs a list of orders");
      ev.effect.harmonics.clear();
      for (const json& k : h) {
        if (!k.is_number_integer()) fail(w + ".harmonics", "needs integer orders");
        ev.effect.harmonics.push_back(k.get<int>());
      }
    }
    if (ev.effect.id() == EffectId::joint_map) {
      // joint_map: harmonics 1..K from its order K
      const json& k = at(eo, "order", w);
      if (!k.is_number_integer() || k.get<int>() < 1 || k.get<int>() > 64)
        fail(w + ".order", "joint_map needs its order K, an integer 1..64");
      ev.effect = joint_map(ev.effect.joint, k.get<int>());
    } else if (!ev.effect.harmonic()) {
      ev.effect.harmonics.clear();
    }
    const json& params = at(eo, "parameters", w);
    if (!params.is_array()) fail(w + ".parameters", "needs a list");
    const auto names = ev.effect.parameter_names();
    const auto units = ev.effect.file_units();
    const auto scale = ev.effect.file_scale();
    if (params.size() != names.size())
      fail(w + ".parameters", std::to_string(params.size()) + " values for " + std::to_string(names.size()) + " parameters");
    for (size_t k = 0; k < params.size(); ++k) {
      const std::string pw = w + ".parameters[" + std::to_string(k) + "]";
      const json& n = at(params[k], "name", pw);
      if (!n.is_string() || n.get<std::string>() != names[k]) fail(pw + ".name", "expected '" + names[k] + "'");
      const json& u = at(params[k], "unit", pw);
      if (!u.is_string() || u.get<std::string>() != units[k]) fail(pw + ".unit", "expected '" + units[k] + "'");
      ev.p.push_back(num(params[k], "value", pw) / scale[k]);
    }
    return ev;
  }
};

}  // namespace

std::string spec_to_json(const ModelSpec& spec) { return spec_json(spec).dump(2); }

std::string robot_to_json(const Robot& robot) {
  json o{{"format", "kincal-model"}, {"version", 3}, {"nominal", spec_json(robot.nominal()->spec())}};
  if (robot.identified()) o["calibrated"] = spec_json(robot.calibrated()->spec());
  o["campaign"] = campaign_json(robot.campaign());
  if (!robot.nominal()->spec().joint_convention.empty()) o["joint_convention"] = robot.nominal()->spec().joint_convention;
  if (!robot.calibrated()->spec().tcp.empty()) o["tcp"] = robot.calibrated()->spec().tcp;
  return o.dump(2) + "\n";
}

std::string tcp_warning(const Robot& robot, const std::string& source) {
  if (robot.calibrated()->spec().tcp != "nominal") return "";
  return source + ": the TCP is nominal (not measured): every pose carries the tool's error; identify with "
                  "--tool-targets or 6-D rows";
}

Robot robot_from_json(const std::string& text, const std::string& source) {
  json o;
  try {
    o = json::parse(text);
  } catch (const json::parse_error& e) {
    // nlohmann reports a byte offset; turn it into line:column
    size_t line = 1, col = 1;
    for (size_t i = 0; i < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw InputError(source + ":" + std::to_string(line) + ":" + std::to_string(col) + ": not valid JSON");
  } catch (const json::exception& e) {  // e.g. a number out of range (1e999)
    throw InputError(source + ": not valid JSON (" + e.what() + ")");
  }
  Reader r{source};
  if (!o.is_object() || !o.contains("format") || o["format"] != "kincal-model")
    throw InputError(source + ": not a kincal model (\"format\": \"kincal-model\" missing)");
  if (!o.contains("version") || !o["version"].is_number_integer() || o["version"].get<int>() < 1 ||
      o["version"].get<int>() > 3)
    throw InputError(source + ": model version " + (o.contains("version") ? o["version"].dump() : "missing") +
                     " is not supported (this kincal reads versions 1 to 3)");
  const bool legacy = o["version"].get<int>() < 3;  // the campaign inside the model's sections
  ModelPtr nominal, calibrated;
  Campaign campaign;
  std::string convention;  // the controller's joint numbers (joint_convention.hpp)
  if (o.contains("joint_convention")) {
    if (!o["joint_convention"].is_string()) throw InputError(source + ": joint_convention: not a string");
    convention = o["joint_convention"].get<std::string>();
  }
  std::string tcp;  // where the calibrated model's tool frame comes from (ModelSpec::tcp)
  if (o.contains("tcp")) {
    const json& t = o["tcp"];
    if (!t.is_string() || (t != "nominal" && t != "measured" && t != "tool-targets"))
      throw InputError(source + ": tcp: " + t.dump() + " is not one of \"nominal\", \"measured\", \"tool-targets\"");
    tcp = t.get<std::string>();
  }
  try {
    const json& no = r.at(o, "nominal", "model");
    ModelSpec ns = r.spec(no, "nominal");
    // versions 1 and 2: the campaign in the model's section (the calibrated one's when there is one)
    if (legacy) {
      Campaign nc = r.campaign(no, "nominal", static_cast<int>(ns.joints.size()), &ns);
      if (!o.contains("calibrated")) campaign = nc;
    }
    ns = with_joint_convention(ns, convention);
    if (!o.contains("calibrated")) ns.tcp = tcp;  // one model: the key is its
    nominal = std::make_shared<Model>(ns);
    if (o.contains("calibrated")) {
      ModelSpec cs = r.spec(o["calibrated"], "calibrated");
      if (legacy) campaign = r.campaign(o["calibrated"], "calibrated", static_cast<int>(cs.joints.size()), &cs);
      cs = with_joint_convention(cs, convention);
      cs.tcp = tcp;
      calibrated = std::make_shared<Model>(cs);
    } else {
      calibrated = nominal;
    }
    if (!legacy && o.contains("campaign"))
      campaign = r.campaign(o["campaign"], "campaign", calibrated->dof(), nullptr);
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.rfind(source, 0) == 0) throw;
    throw InputError(source + ": " + m);
  }
  if (calibrated->dof() != nominal->dof())
    throw InputError(source + ": nominal and calibrated models have different joint counts");
  try {
    return Robot{nominal, calibrated, campaign};
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

Robot load_robot(const std::string& name) {
  auto ends_with = [&](const char* s) {
    const std::string e(s);
    return name.size() >= e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
  };
  if (ends_with(".json")) {
    std::ifstream f(name);
    if (!f) throw InputError(name + ": cannot open the model file");
    std::stringstream ss;
    ss << f.rdbuf();
    return robot_from_json(ss.str(), name);
  }
  if (ends_with(".urdf"))
    throw InputError(name + ": URDF robots are read by the Python package (kincal); convert with "
                     "`kincal fk`/`identify` to a model .json for kincal-compensate");
  auto m = std::make_shared<Model>(builtin_spec(name));
  return Robot{m, m};
}

Robot with_joint_convention(const Robot& robot, const std::string& source, const std::string& convention) {
  if (convention.empty()) return robot;
  if (source.size() >= 5 && source.compare(source.size() - 5, 5, ".json") == 0)
    throw InputError(source + ": a model JSON carries its joint convention (\"joint_convention\"); "
                     "--joint-convention is for a URDF or a built-in robot");
  auto m = std::make_shared<Model>(with_joint_convention(robot.nominal()->spec(), convention));
  return Robot{m, m};
}

}  // namespace kincal
