// kincal: KRL programs read in (.src with its .dat): DEF/END and DEFDAT/ENDDAT checked, the POS,
// E6POS and FRAME declarations, and the motions PTP, LIN, CIRC (and SPTP, SLIN, SCIRC) to declared
// names or inline aggregates. A target assigned in the program, a geometric operator (A:B), a _REL
// motion are unresolved; E6AXIS / AXIS targets are joints and stay as they are.
#include "controller_writers.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include <cctype>
#include <cstdlib>
#include <map>
#include <regex>
#include <tuple>

namespace kincal {

namespace {

std::string code_of(const std::string& l) { return code_before(l, ';'); }

}  // namespace


namespace {

struct Decl {
  std::string type;
  int file = 0, line = 0;
  size_t begin = 0, end = 0;
  size_t type_begin = 0, type_end = 0;  // the type's span
  bool has_value = false, assigned = false;
};

// the numbers X Y Z A B C of a KRL aggregate "{X 1,Y 2,...}"
Pose6 parse_aggregate(const std::string& agg, const std::string& at) {
  Pose6 p;
  bool seen[6] = {false, false, false, false, false, false};
  for (const std::string& item : split_top(agg.substr(1, agg.size() - 2))) {
    size_t k = 0;
    while (k < item.size() && (std::isalnum(static_cast<unsigned char>(item[k])) || item[k] == '_')) ++k;
    const std::string key = upper_case(item.substr(0, k));
    std::string val = item.substr(k);
    val.erase(0, val.find_first_not_of(" \t"));
    static const char* keys[6] = {"X", "Y", "Z", "A", "B", "C"};
    for (int f = 0; f < 6; ++f) {
      if (key != keys[f]) continue;
      char* end = nullptr;
      const double v = std::strtod(val.c_str(), &end);
      if (val.empty() || end == val.c_str() || *end != '\0' || !std::isfinite(v))
        throw InputError(at + ": " + key + " '" + val + "' is not a number");
      (f < 3 ? p.xyz : p.abc)[f % 3] = v;
      seen[f] = true;
    }
  }
  for (int f = 0; f < 6; ++f)
    if (!seen[f]) throw InputError(at + ": the target has no " + std::string(1, "XYZABC"[f]) + " value");
  return p;
}

}  // namespace


Declarations read_krl_declarations(const std::vector<std::string>&) { return {}; }  // (being written)

NativeProgram read_krl_program(const std::vector<std::string>& src_paths, const Declarations&) {
  const std::string& src_path = src_paths[0];
  NativeProgram p;
  p.format = ControllerFormat::Krl;
  add_program_file(p, src_path);
  const std::string dat_path = ctl::with_ext(src_path, ".dat");
  if (FILE* f = std::fopen(dat_path.c_str(), "rb")) {
    std::fclose(f);
    add_program_file(p, dat_path);
  }
  static const std::regex decl_re(
      R"(^\s*(?:DECL\s+)?(?:GLOBAL\s+)?(E6POS|POS|FRAME|E6AXIS|AXIS)\s+(\w+)\s*(=\s*(\{.*\}))?\s*$)", std::regex::icase);
  static const std::regex assign_re(R"(^\s*(\w+)(\.\w+)?\s*=)");
  static const std::regex motion_re(R"(^\s*(PTP|LIN|CIRC|SPTP|SLIN|SCIRC|PTP_REL|LIN_REL|CIRC_REL)\s+(.*)$)",
                                    std::regex::icase);
  std::map<std::string, Decl> decls;
  // declarations and block structure, in both files
  for (size_t f = 0; f < p.lines.size(); ++f) {
    const char* open = f == 0 ? "DEF" : "DEFDAT";
    const char* close = f == 0 ? "END" : "ENDDAT";
    int open_line = 0;
    bool closed = false;
    for (size_t i = 0; i < p.lines[f].size(); ++i) {
      const std::string code = code_of(p.lines[f][i]);
      const std::string at = where(p.paths[f], static_cast<int>(i + 1));
      std::string first = upper_case(code.substr(code.find_first_not_of(" \t") == std::string::npos ? code.size() : code.find_first_not_of(" \t")));
      first = first.substr(0, first.find_first_of(" \t(\r"));
      if (first == "GLOBAL" && std::regex_search(upper_case(code), std::regex(R"(^\s*GLOBAL\s+DEF(FCT)?\b)")))
        first = "DEF";
      if (first == open || (f == 0 && first == "DEFFCT")) {
        if (open_line && !closed && f == 1) throw InputError(at + ": DEFDAT inside DEFDAT");
        open_line = static_cast<int>(i + 1);
        closed = false;
      } else if (first == close || (f == 0 && first == "ENDFCT")) {
        if (!open_line || closed) throw InputError(at + ": " + first + " without " + open);
        closed = true;
      }
      std::smatch m;
      if (std::regex_match(code, m, decl_re)) {
        Decl d;
        d.type = upper_case(m[1].str());
        d.file = static_cast<int>(f);
        d.line = static_cast<int>(i + 1);
        std::tie(d.type_begin, d.type_end) = span_of(m, 1);
        d.has_value = m[4].matched;
        if (d.has_value) std::tie(d.begin, d.end) = span_of(m, 4);
        d.assigned = decls[upper_case(m[2].str())].assigned;  // (an assignment in the .src, read before its .dat)
        decls[upper_case(m[2].str())] = d;
      } else if (f == 0 && std::regex_search(code, m, assign_re)) {
        const auto it = decls.find(upper_case(m[1].str()));
        if (it != decls.end()) it->second.assigned = true;
        else decls[upper_case(m[1].str())].assigned = true;  // declared later or elsewhere: computed at run time
      }
    }
    if (!open_line) throw InputError(p.paths[f] + ": no " + open + " in the file");
    if (!closed)
      throw InputError(where(p.paths[f], open_line) + ": " + open + " is not closed by " + close + " (end of file)");
  }
  // the motions, in order
  std::map<std::string, size_t> used;
  for (size_t i = 0; i < p.lines[0].size(); ++i) {
    const std::string code = code_of(p.lines[0][i]);
    std::smatch m;
    if (!std::regex_match(code, m, motion_re)) continue;
    const std::string at = where(p.paths[0], static_cast<int>(i + 1));
    const std::string kind = upper_case(m[1].str());
    std::vector<std::string> args = split_top(m[2].str());
    const size_t n_targets = kind.find("CIRC") != std::string::npos ? 2 : 1;
    if (args.size() < n_targets) throw InputError(at + ": " + kind + " needs " + std::to_string(n_targets) + " target(s)");
    const size_t base_pos = static_cast<size_t>(m.position(2));
    const bool ptp = kind == "PTP" || kind == "SPTP";
    for (size_t a = 0; a < n_targets; ++a) {
      std::string arg = args[a];
      arg = arg.substr(0, arg.find_first_of(" \t") == std::string::npos || arg[0] == '{' ? arg.size() : arg.find_first_of(" \t"));
      p.motions.push_back(motion_around(code, static_cast<int>(i + 1), ptp ? 'J' : n_targets == 2 ? 'C' : 'L',
                                        code.find(arg, base_pos), arg.size()));
      if (kind.find("_REL") != std::string::npos || arg.find(':') != std::string::npos) {
        p.unresolved.push_back({at, code});
        continue;
      }
      if (!arg.empty() && arg[0] == '{') {
        if (std::regex_search(arg, std::regex(R"(\{\s*A1\s)", std::regex::icase))) continue;  // joints
        NativeTarget t;
        t.file = 0;
        t.line = static_cast<int>(i + 1);
        t.begin = p.lines[0][i].find(arg, base_pos);
        t.end = t.begin + arg.size();
        t.pose = parse_aggregate(arg, at);
        t.joint_motion = ptp;
        p.motions.back().target = static_cast<int>(p.targets.size());
        p.targets.push_back(t);
        continue;
      }
      const std::string key = upper_case(arg);
      if (key.empty() || key[0] == '$') {
        p.unresolved.push_back({at, code});
        continue;
      }
      const auto it = decls.find(key);
      if (it == decls.end() || it->second.type.empty())
        throw InputError(at + ": target '" + arg + "' is not declared (in the .src or its .dat)");
      const Decl& d = it->second;
      if (d.type == "E6AXIS" || d.type == "AXIS") continue;
      if (d.assigned || !d.has_value) {
        p.unresolved.push_back({at, code});
        continue;
      }
      if (used.count(key)) {
        p.targets[used[key]].joint_motion &= ptp;
        p.motions.back().target = static_cast<int>(used[key]);
        continue;
      }
      p.motions.back().target = static_cast<int>(p.targets.size());
      used[key] = p.targets.size();
      NativeTarget t;
      t.file = d.file;
      t.line = d.line;
      t.begin = d.begin;
      t.end = d.end;
      t.name = arg;
      t.pose = parse_aggregate(p.lines[static_cast<size_t>(d.file)][static_cast<size_t>(d.line - 1)].substr(d.begin, d.end - d.begin),
                               where(p.paths[static_cast<size_t>(d.file)], d.line));
      t.joint_motion = ptp;
      t.joint_edits.push_back({d.file, d.line, d.type_begin, d.type_end, d.type == "E6POS" ? "E6AXIS" : "AXIS"});
      p.targets.push_back(t);
    }
  }
  keep_named_targets_cartesian(p, ';', true);
  return p;
}

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
