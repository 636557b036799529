// kincal: KUKA KRL programs (KR C4/C5): NAME.src with the motions and NAME.dat declaring the targets,
// E6AXIS (A1..A6, E1..E6) for joint targets, E6POS (X Y Z A B C S T, E1..E6) for filtered ones.
// Names: up to 24 characters (letters, digits, '_'); a module's files carry its name. A program with
// more targets than a file takes is split into NAME_1, NAME_2, ... that NAME calls in turn.
#include "controller_writers.hpp"
#include "kincal/io/native.hpp"

#include <cctype>
#include <regex>

#include <cstdio>

namespace kincal::ctl {

namespace {


std::string header(const std::string& kind) { return "&ACCESS RVP\n&REL 1\n" + kind; }

std::string e6axis(const Vec6& q) {
  std::string s = "{";
  for (int j = 0; j < 6; ++j) s += std::string(j ? "," : "") + "A" + std::to_string(j + 1) + " " + fixed(q[j], kJointDecimals);
  return s + ",E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}";
}

std::string e6pos(const ControllerTarget& t) {
  const char* n[6] = {"X", "Y", "Z", "A", "B", "C"};
  std::string s = "{";
  for (int k = 0; k < 6; ++k)
    s += std::string(k ? "," : "") + n[k] + " " +
         fixed(k < 3 ? t.pose.xyz[k] : t.pose.abc[k - 3], k < 3 ? kMmDecimals : kJointDecimals);
  s += ",S " + std::to_string(t.kuka_s) + ",T " + std::to_string(t.kuka_t);
  return s + ",E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}";
}

// One module (a .src and its .dat) with the targets [b, e), numbered from b + 1.
std::vector<OutputFile> module(const std::string& dir, const std::string& name, const std::vector<ControllerTarget>& t,
                               size_t b, size_t e, const WriterOptions& o, bool last_part) {
  const bool filtered = o.targets == TargetKind::Filtered;
  const double zone = zone_of(o);
  std::string src = header("DEF " + name + "( )\n");
  std::string dat = header("DEFDAT " + name + "\n");
  char buf[160];
  src += "; kincal compensate: " + std::to_string(e - b) + (filtered ? " filtered Cartesian" : " joint") +
         " targets\n";
  src += "BAS(#INITMOV,0)\n";
  std::snprintf(buf, sizeof buf, "BAS(#VEL_PTP,%s)\n", fixed(joint_speed_pct(o), 1).c_str());
  src += buf;
  if (filtered) src += "$VEL.CP=" + fixed(linear_speed_mm_s(o) / 1000.0, 4) + "\n";
  if (zone > 0) src += "$APO.CDIS=" + fixed(zone, 3) + "\n";
  for (size_t i = b; i < e; ++i) {
    const std::string id = "XP" + std::to_string(i + 1);
    const bool linear = filtered && i > 0;  // the first target by PTP with its Status and Turn
    dat += (filtered ? "DECL E6POS " : "DECL E6AXIS ") + id + "=" + (filtered ? e6pos(t[i]) : e6axis(t[i].q_deg)) + "\n";
    src += (linear ? "LIN " : "PTP ") + id + (zone > 0 && !(last_part && i + 1 == e) ? " C_DIS" : "") + "\n";
  }
  src += "END\n";
  dat += "ENDDAT\n";
  return {{dir + name + ".src", src}, {dir + name + ".dat", dat}};
}

}  // namespace

std::vector<OutputFile> write_krl(const std::string& out, const std::vector<ControllerTarget>& t, const WriterOptions& o,
                                  const std::string& name) {
  const std::string dir = dir_of(out);
  const auto ranges = parts(t.size(), o.max_targets_per_file > 0 ? o.max_targets_per_file : controller_max_targets(o.format));
  if (ranges.size() == 1) return module(dir, name, t, 0, t.size(), o, true);
  // NAME calls the parts NAME_1 .. NAME_k, each a module of its own
  const std::string last = name + "_" + std::to_string(ranges.size());
  check_name(last, 24, "KRL");
  std::string src = header("DEF " + name + "( )\n");
  src += "; kincal compensate: " + std::to_string(t.size()) + " targets in " + std::to_string(ranges.size()) + " parts\n";
  std::vector<OutputFile> files;
  for (size_t p = 0; p < ranges.size(); ++p) {
    const std::string part = name + "_" + std::to_string(p + 1);
    src += part + "( )\n";
    auto f = module(dir, part, t, ranges[p].first, ranges[p].second, o, p + 1 == ranges.size());
    files.insert(files.end(), f.begin(), f.end());
  }
  src += "END\n";
  files.insert(files.begin(), {{dir + name + ".src", src}, {dir + name + ".dat", header("DEFDAT " + name + "\nENDDAT\n")}});
  return files;
}

}  // namespace kincal::ctl

namespace kincal {

// The values of a read program written back (native.cpp): KRL aggregates.

// a KRL aggregate with X..C, S and T replaced (every other field kept as written)
std::string krl_aggregate(const std::string& old, const Pose6& pose, const ControllerTarget& t, bool is_frame) {
  std::vector<std::string> items = split_top(old.substr(1, old.size() - 2));
  const double v[6] = {pose.xyz[0], pose.xyz[1], pose.xyz[2], pose.abc[0], pose.abc[1], pose.abc[2]};
  bool has_s = false, has_t = false;
  for (std::string& item : items) {
    size_t k = 0;
    while (k < item.size() && (std::isalnum(static_cast<unsigned char>(item[k])) || item[k] == '_')) ++k;
    const std::string key = upper_case(item.substr(0, k));
    const std::string sep = item.substr(k, item.find_first_not_of(" \t", k) - k);
    const std::string name = item.substr(0, k);
    for (int f = 0; f < 6; ++f)
      if (key == std::string(1, "XYZABC"[f])) item = name + sep + ctl::fixed(v[f], f < 3 ? 4 : 6);
    if (key == "S") item = name + sep + std::to_string(t.kuka_s), has_s = true;
    if (key == "T") item = name + sep + std::to_string(t.kuka_t), has_t = true;
  }
  std::string out = "{";
  for (size_t i = 0; i < items.size(); ++i) out += (i ? "," : "") + items[i];
  if (!is_frame && !has_s) out += ",S " + std::to_string(t.kuka_s);
  if (!is_frame && !has_t) out += ",T " + std::to_string(t.kuka_t);
  return out + "}";
}

// a KRL aggregate of a Cartesian target as an axis target {A1 .., .., A6 ..}, its external axes E1..E6 kept
std::string krl_axis(const std::string& old, const Vec6& q_deg) {
  std::string out = "{";
  for (int j = 0; j < 6; ++j) out += std::string(j ? "," : "") + "A" + std::to_string(j + 1) + " " + ctl::fixed(q_deg[j], ctl::kJointDecimals);
  for (const std::string& item : split_top(old.substr(1, old.size() - 2)))
    if (std::regex_match(item, std::regex(R"(E[1-6]\b.*)", std::regex::icase))) out += "," + item;
  return out + "}";
}

}  // namespace kincal
