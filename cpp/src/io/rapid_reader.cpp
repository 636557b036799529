// kincal: RAPID modules read in: MODULE/ENDMODULE checked, robtarget and wobjdata declarations, and
// the motions MoveJ, MoveL, MoveC (and their DO/Sync/AO/GO variants) to declared names or inline
// robtargets, with the work object of \WObj applied (uframe * oframe). A target computed by a function
// (Offs, RelTool, CRobT, ...) is unresolved; MoveAbsJ (joints) stays as it is. Statements that carry a
// target must stand on one line (RobotStudio writes them so).
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

std::string code_of(const std::string& l) { return code_before(l, '!'); }

std::vector<double> numbers(const std::string& part, size_t n, const std::string& at, const char* what) {
  const std::string s = part.size() >= 2 && part.front() == '[' && part.back() == ']' ? part.substr(1, part.size() - 2) : "";
  if (s.empty()) throw InputError(at + ": " + what + " is not a bracketed list ('" + part + "')");
  std::vector<double> v;
  for (const std::string& x : split_top(s)) {
    char* end = nullptr;
    const double d = std::strtod(x.c_str(), &end);
    if (x.empty() || end == x.c_str() || *end != '\0' || !std::isfinite(d))
      throw InputError(at + ": " + what + ": '" + x + "' is not a number");
    v.push_back(d);
  }
  if (v.size() != n)
    throw InputError(at + ": " + what + " has " + std::to_string(v.size()) + " values, not " + std::to_string(n));
  return v;
}

Eigen::Isometry3d frame_of(const std::vector<double>& t, const std::vector<double>& q) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  f.translation() = Vec3(t[0], t[1], t[2]);
  return f;
}

// a robtarget value [[x,y,z],[q1..q4],[cf1,cf4,cf6,cfx],[e1..e6]]
Pose6 parse_robtarget(const std::string& v, const std::string& at) {
  const std::string inner = v.size() >= 2 && v.front() == '[' && v.back() == ']' ? v.substr(1, v.size() - 2) : "";
  const auto parts = split_top(inner);
  if (inner.empty() || parts.size() != 4)
    throw InputError(at + ": a robtarget has 4 parts [trans],[rot],[robconf],[extax], this one " +
                     std::to_string(inner.empty() ? 0 : parts.size()));
  const auto t = numbers(parts[0], 3, at, "the robtarget's trans");
  const auto q = numbers(parts[1], 4, at, "the robtarget's rot");
  numbers(parts[2], 4, at, "the robtarget's robconf");
  numbers(parts[3], 6, at, "the robtarget's extax");
  return iso_to_pose(frame_of(t, q));
}

}  // namespace

Declarations read_rapid_declarations(const std::vector<std::string>&) { return {}; }  // (being written)

NativeProgram read_rapid_program(const std::vector<std::string>& paths, const Declarations&) {
  const std::string& path = paths[0];
  NativeProgram p;
  p.format = ControllerFormat::Rapid;
  add_program_file(p, path);
  const auto& lines = p.lines[0];
  static const std::regex decl_re(
      R"(^\s*(?:LOCAL\s+|TASK\s+)?(CONST|PERS|VAR)\s+(robtarget|wobjdata)\s+(\w+)\s*(:=\s*(.*?))?\s*;\s*$)",
      std::regex::icase);
  static const std::regex move_re(R"(^\s*(Move(?:J|L|C)\w*)\s+(.*?);?\s*$)", std::regex::icase);
  struct Decl {
    int line = 0;
    size_t begin = 0, end = 0, type_begin = 0, type_end = 0;
    bool has_value = false, robtarget = true;
    std::string value;
  };
  std::map<std::string, Decl> decls;
  std::map<std::string, bool> assigned;  // robtargets the module assigns (p := ..., p.trans.z := ...)
  static const std::regex assign_re(R"(^\s*(\w+)(?:\.\w+|\{[^}]*\})*\s*:=)");
  int module_line = 0;
  bool closed = false;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string code = code_of(lines[i]);
    const std::string at = where(path, static_cast<int>(i + 1));
    std::smatch m;
    static const std::regex mod_re(R"(^\s*MODULE\s+\w+)", std::regex::icase), end_re(R"(^\s*ENDMODULE\b)", std::regex::icase);
    if (std::regex_search(code, mod_re)) {
      if (module_line && !closed) throw InputError(at + ": MODULE inside MODULE");
      module_line = static_cast<int>(i + 1), closed = false;
    } else if (std::regex_search(code, end_re)) {
      if (!module_line || closed) throw InputError(at + ": ENDMODULE without MODULE");
      closed = true;
    }
    if (std::regex_search(code, std::regex(R"(\brobtarget\b)", std::regex::icase)) &&
        code.find(';') == std::string::npos)
      throw InputError(at + ": a robtarget declaration over several lines (kincal reads one per line)");
    if (std::regex_match(code, m, decl_re)) {
      Decl d;
      d.line = static_cast<int>(i + 1);
      d.robtarget = upper_case(m[2].str()) == "ROBTARGET";
      std::tie(d.type_begin, d.type_end) = span_of(m, 2);
      d.has_value = m[5].matched;
      if (d.has_value) {
        std::tie(d.begin, d.end) = span_of(m, 5);
        d.value = m[5].str();
        if (d.robtarget) parse_robtarget(d.value, at);  // checked here, where it is declared
      }
      decls[upper_case(m[3].str())] = d;
    } else if (std::regex_search(code, m, assign_re)) {
      assigned[upper_case(m[1].str())] = true;
    }
  }
  if (!module_line) throw InputError(path + ": no MODULE in the file");
  if (!closed) throw InputError(where(path, module_line) + ": MODULE is not closed by ENDMODULE (end of file)");
  std::map<std::string, size_t> used;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string code = code_of(lines[i]);
    std::smatch m;
    if (!std::regex_match(code, m, move_re)) continue;
    const std::string at = where(path, static_cast<int>(i + 1));
    if (code.find(';') == std::string::npos) throw InputError(at + ": a motion over several lines (kincal reads one per line)");
    std::vector<std::string> args = split_top(m[2].str());
    while (!args.empty() && !args[0].empty() && args[0][0] == '\\') args.erase(args.begin());  // \Conc ...
    const size_t n_targets = upper_case(m[1].str()).rfind("MOVEC", 0) == 0 ? 2 : 1;
    // MoveJ (not MoveJDO, MoveJSync, ...) becomes MoveAbsJ when its target is written as joints
    const bool movej = upper_case(m[1].str()) == "MOVEJ";
    const auto [move_begin, move_end] = span_of(m, 1);
    const NativeEdit to_absj{0, static_cast<int>(i + 1), move_begin, move_end, "MoveAbsJ"};
    if (args.size() < n_targets + 2) throw InputError(at + ": " + m[1].str() + " needs target(s), speed and zone");
    // the work object: \WObj:=name anywhere in the statement
    Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
    std::smatch w;
    if (std::regex_search(code, w, std::regex(R"(\\WObj\s*:=\s*(\w+))", std::regex::icase)) && upper_case(w[1].str()) != "WOBJ0") {
      const auto it = decls.find(upper_case(w[1].str()));
      if (it == decls.end() || it->second.robtarget || !it->second.has_value)
        throw InputError(at + ": work object '" + w[1].str() + "' is not declared with a value in the module");
      const auto parts = split_top(it->second.value.substr(1, it->second.value.size() - 2));
      const std::string wat = where(path, it->second.line);
      if (parts.size() != 5) throw InputError(wat + ": a wobjdata has 5 parts, this one " + std::to_string(parts.size()));
      const auto uf = split_top(parts[3].substr(1, parts[3].size() - 2)), of = split_top(parts[4].substr(1, parts[4].size() - 2));
      if (uf.size() != 2 || of.size() != 2) throw InputError(wat + ": uframe and oframe are [[x,y,z],[q1,q2,q3,q4]]");
      frame = frame_of(numbers(uf[0], 3, wat, "uframe"), numbers(uf[1], 4, wat, "uframe")) *
              frame_of(numbers(of[0], 3, wat, "oframe"), numbers(of[1], 4, wat, "oframe"));
    }
    const std::string instr = upper_case(m[1].str());
    const char kind = instr == "MOVEJ" ? 'J' : instr == "MOVEL" ? 'L' : n_targets == 2 ? 'C' : 'O';
    for (size_t a = 0; a < n_targets; ++a) {
      const std::string& arg = args[a];
      p.motions.push_back(motion_around(code, static_cast<int>(i + 1), kind, code.find(arg, static_cast<size_t>(m.position(2))),
                                        arg.size()));
      if (!arg.empty() && arg[0] == '[') {
        NativeTarget t;
        t.line = static_cast<int>(i + 1);
        t.begin = lines[i].find(arg);
        t.end = t.begin + arg.size();
        t.pose = parse_robtarget(arg, at);
        t.frame = frame;
        t.joint_motion = movej;
        t.joint_edits.push_back(to_absj);
        p.motions.back().target = static_cast<int>(p.targets.size());
        p.targets.push_back(t);
        continue;
      }
      if (!std::regex_match(arg, std::regex(R"(\w+)"))) {  // Offs(..), RelTool(..), CRobT(..), p{i}, ...
        p.unresolved.push_back({at, code});
        continue;
      }
      const auto it = decls.find(upper_case(arg));
      if (it == decls.end() || !it->second.robtarget)
        throw InputError(at + ": target '" + arg + "' is not declared as a robtarget in the module");
      if (!it->second.has_value || assigned[upper_case(arg)] ||
          !std::regex_search(lines[static_cast<size_t>(it->second.line - 1)],
                             std::regex(R"(\bCONST\b|\bPERS\b)", std::regex::icase))) {
        p.unresolved.push_back({at, code});  // a VAR, no value, or assigned in the module: set at run time
        continue;
      }
      if (used.count(upper_case(arg))) {
        NativeTarget& t = p.targets[used[upper_case(arg)]];
        t.joint_motion &= movej;
        t.joint_edits.push_back(to_absj);
        p.motions.back().target = static_cast<int>(used[upper_case(arg)]);
        continue;
      }
      p.motions.back().target = static_cast<int>(p.targets.size());
      used[upper_case(arg)] = p.targets.size();
      const Decl& d = it->second;
      NativeTarget t;
      t.line = d.line;
      t.begin = d.begin;
      t.end = d.end;
      t.name = arg;
      t.pose = parse_robtarget(d.value, where(path, d.line));
      t.frame = frame;
      t.joint_motion = movej;
      t.joint_edits.push_back({0, d.line, d.type_begin, d.type_end, "jointtarget"});
      t.joint_edits.push_back(to_absj);
      p.targets.push_back(t);
    }
  }
  keep_named_targets_cartesian(p, '!', true);
  return p;
}

// a robtarget value with trans, rot and robconf replaced (extax kept as written)
std::string rapid_robtarget(const std::string& old, const Pose6& pose, const ControllerTarget& t) {
  const auto parts = split_top(old.substr(1, old.size() - 2));
  const auto q = ctl::quaternion_of(pose.abc);
  std::string s = "[[";
  for (int k = 0; k < 3; ++k) s += (k ? "," : "") + ctl::fixed(pose.xyz[k], 4);
  s += "],[";
  for (int k = 0; k < 4; ++k) s += (k ? "," : "") + ctl::fixed(q[static_cast<size_t>(k)], 9);
  s += "],[";
  for (int k = 0; k < 4; ++k) s += (k ? "," : "") + std::to_string(t.abb_conf[static_cast<size_t>(k)]);
  return s + "]," + parts[3] + "]";
}

// a robtarget value as a jointtarget [[q1..q6],[extax]], its external axes kept as written
std::string rapid_jointtarget(const std::string& old, const Vec6& q_deg) {
  const auto parts = split_top(old.substr(1, old.size() - 2));
  std::string s = "[[";
  for (int j = 0; j < 6; ++j) s += (j ? "," : "") + ctl::fixed(q_deg[j], ctl::kJointDecimals);
  return s + "]," + parts[3] + "]";
}

}  // namespace kincal
