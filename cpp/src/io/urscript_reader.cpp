// kincal: URScript programs read in: def/thread/if/while/for blocks closed by end checked (elif, else inside
// them). The motions of the manual: movej, movel, movep, servoc (one target), movec (its via and end point),
// to a pose literal p[x,y,z,rx,ry,rz] (m, rad: a rotation vector) or to a variable assigned one pose literal
// in the program (the assignment is changed); movej to a pose is a Cartesian target in joint interpolation.
// A joint list [q1..q6] (a literal, or a variable assigned one) stays as it is; servoj (joint positions),
// speedj and speedl (speeds) are motions with no Cartesian target. A target computed at run time
// (pose_trans, pose_add, get_actual_tcp_pose, get_inverse_kin, ..., a variable assigned more than once or
// not a literal, a function's parameter, a pose literal with a computed value) is unresolved with why.
// Other p[...] (set_tcp, ...) are not targets and stay.
#include "controller_writers.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include <cmath>
#include <cstdlib>
#include <map>
#include <regex>
#include <tuple>

namespace kincal {

namespace {

std::string code_of(const std::string& l) { return code_before(l, '#'); }

// p[x,y,z,rx,ry,rz] in m and rad, as a pose in mm and KUKA ABC degrees
Pose6 parse_pose(const std::string& lit, const std::string& at) {
  const std::string inner = lit.substr(2, lit.size() - 3);
  const auto v = split_top(inner);
  if (v.size() != 6) throw InputError(at + ": a pose p[...] has 6 values, this one " + std::to_string(v.size()));
  double x[6];
  for (int k = 0; k < 6; ++k) {
    char* end = nullptr;
    x[k] = std::strtod(v[static_cast<size_t>(k)].c_str(), &end);
    if (v[static_cast<size_t>(k)].empty() || end == v[static_cast<size_t>(k)].c_str() || *end != '\0' || !std::isfinite(x[k]))
      throw InputError(at + ": pose value '" + v[static_cast<size_t>(k)] + "' is not a number");
  }
  const Vec3 rv(x[3], x[4], x[5]);
  const double angle = rv.norm();
  const Mat3 r = angle > 0 ? Mat3(Eigen::AngleAxisd(angle, rv / angle)) : Mat3::Identity();
  return {Vec3(x[0], x[1], x[2]) * 1000.0, rotation_to_abc(r)};
}

// the arguments of the call whose '(' is at open, and the position after its ')'
std::vector<std::string> call_args(const std::string& s, size_t open, size_t& close, const std::string& at) {
  int depth = 0;
  for (size_t i = open; i < s.size(); ++i) {
    if (s[i] == '(' || s[i] == '[') ++depth;
    if (s[i] == ')' || s[i] == ']') --depth;
    if (depth == 0) {
      close = i;
      return split_top(s.substr(open + 1, i - open - 1));
    }
  }
  throw InputError(at + ": unbalanced parentheses (kincal reads a motion on one line)");
}

bool is_pose_literal(const std::string& a) {
  return a.size() > 3 && a[0] == 'p' && a[1] == '[' && a.back() == ']' && a.find('[', 2) == std::string::npos;
}

// a pose literal one of whose values is computed (a name or an expression: p[x, y, 0.5, 0, 3.14, 0]); a value
// written as a number but malformed ("-0.4x8") is an error where it stands (parse_pose)
bool has_computed_value(const std::string& lit) {
  static const std::regex numberish(R"(^[+-]?[0-9.][0-9A-Za-z_.+-]*$)");
  for (const std::string& v : split_top(lit.substr(2, lit.size() - 3)))
    if (!v.empty() && !std::regex_match(v, numberish)) return true;
  return false;
}

// why a motion's argument that is neither a literal nor a variable is known at run time only
std::string why_computed(const std::string& a) {
  std::smatch m;
  static const std::regex call(R"(^([A-Za-z_]\w*)\s*\()");
  if (std::regex_search(a, m, call)) {
    const std::string f = m[1].str();
    if (f == "get_inverse_kin") return "get_inverse_kin(..): joints computed from a pose at run time";
    if (f == "get_actual_tcp_pose" || f == "get_target_tcp_pose")
      return f + "(): where the robot is at run time";
    if (f == "get_forward_kin") return "get_forward_kin(..): a pose computed from joints at run time";
    return f + "(..): computed at run time";
  }
  return "'" + a + "': an expression computed at run time";
}

struct UrAssign {
  int line = 0, count = 0;
  size_t begin = 0, end = 0;
  bool literal = false, joints = false;
  bool from_pose = false;  // an assignment computes joints from a pose (get_inverse_kin)
  std::string value;  // as written (the last assignment)
};

struct UrNames {  // what the program assigns, and the functions' parameters
  std::map<std::string, UrAssign> vars;
  std::map<std::string, std::string> params;  // a function's parameter: the function
};

/// The variables the program assigns and the functions' parameters; its blocks closed (file:line errors).
UrNames read_urscript_names(const std::vector<std::string>& lines, const std::string& path) {
  UrNames out;
  auto& vars = out.vars;
  auto& params = out.params;
  std::vector<std::pair<std::string, int>> blocks;  // opener and line
  static const std::regex opener(R"(^\s*(def|thread|if|while|for)\b.*:\s*$)"), closer(R"(^\s*end\s*$)");
  static const std::regex def(R"(^\s*def\s+([A-Za-z_]\w*)\s*\(([^)]*)\)\s*:\s*$)");
  static const std::regex assign(R"(^\s*(?:global\s+|local\s+)?([A-Za-z_]\w*)\s*=\s*(.*?)\s*$)");
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string code = code_of(lines[i]);
    const int ln = static_cast<int>(i + 1);
    std::smatch m;
    if (std::regex_match(code, m, opener)) {
      blocks.push_back({m[1].str(), ln});
      if (std::regex_match(code, m, def))
        for (const std::string& a : split_top(m[2].str()))
          if (!a.empty()) params[a.substr(0, a.find('='))] = m[1].str();
    } else if (std::regex_match(code, closer)) {
      if (blocks.empty()) throw InputError(where(path, ln) + ": 'end' without def, thread, if, while or for");
      blocks.pop_back();
    } else if (std::regex_match(code, m, assign) && code.find("==") == std::string::npos) {
      UrAssign& a = vars[m[1].str()];
      ++a.count;
      a.line = ln;
      a.value = m[2].str();
      a.from_pose |= a.value.find("get_inverse_kin") != std::string::npos;
      a.literal = is_pose_literal(a.value) && !has_computed_value(a.value);
      a.joints = !a.value.empty() && a.value[0] == '[';
      std::tie(a.begin, a.end) = span_of(m, 2);
      if (a.literal) parse_pose(a.value, where(path, ln));  // checked where it is written
    }
  }
  if (!blocks.empty())
    throw InputError(where(path, blocks.back().second) + ": '" + blocks.back().first + "' is not closed by 'end' (end of file)");
  return out;
}

/// A motion's target argument ``a`` (at a_at in its line ln; its motion the last of p.motions): a
/// pose written there or a variable assigned once with one, into p.targets; a value known at run time
/// into p.unresolved; joints kept.
void add_urscript_target(NativeProgram& p, const UrNames& names, std::map<std::string, size_t>& used,
                         const std::vector<std::string>& lines, const std::string& path, const std::string& a,
                         size_t a_at, int ln, const std::string& statement, bool movej) {
  const std::string at = where(path, ln);
  if (a[0] == '[') return;  // joints: kept
  if (is_pose_literal(a)) {
    if (has_computed_value(a)) {
      p.unresolved.push_back({at, statement, "'" + a + "': a pose with a value computed at run time"});
      return;
    }
    NativeTarget t;
    t.line = ln;
    t.begin = a_at;
    t.end = t.begin + a.size();
    t.pose = parse_pose(a, at);
    t.joint_motion = movej;
    p.motions.back().target = static_cast<int>(p.targets.size());
    p.targets.push_back(t);
    return;
  }
  if (!std::regex_match(a, std::regex(R"([A-Za-z_]\w*)"))) {
    p.unresolved.push_back({at, statement, why_computed(a)});
    return;
  }
  const auto v = names.vars.find(a);
  if (v == names.vars.end()) {
    const auto f = names.params.find(a);
    if (f == names.params.end()) throw InputError(at + ": target '" + a + "' is not assigned in the program");
    p.unresolved.push_back({at, statement, "'" + a + "': a parameter of " + f->second + "(), known at run time"});
    return;
  }
  if (v->second.joints && v->second.count == 1) return;  // a joint list: kept
  if (v->second.count != 1) {
    p.unresolved.push_back({at, statement, "'" + a + "' is assigned " + std::to_string(v->second.count) +
                                               " times: its value at this motion is known at run time"});
    return;
  }
  if (!v->second.literal) {
    const std::string& val = v->second.value;
    p.unresolved.push_back({at, statement, "'" + a + "' is assigned " +
                                               (is_pose_literal(val) ? "'" + val + "': a pose with a value computed at run time"
                                                                     : why_computed(val))});
    return;
  }
  if (used.count(a)) {
    p.targets[used[a]].joint_motion &= movej;
    p.motions.back().target = static_cast<int>(used[a]);
    return;
  }
  p.motions.back().target = static_cast<int>(p.targets.size());
  used[a] = p.targets.size();
  NativeTarget t;
  t.line = v->second.line;
  t.begin = v->second.begin;
  t.end = v->second.end;
  t.name = a;
  const std::string& l = lines[static_cast<size_t>(t.line - 1)];
  t.pose = parse_pose(l.substr(t.begin, t.end - t.begin), where(path, t.line));
  t.joint_motion = movej;
  p.targets.push_back(t);
}

}  // namespace

NativeProgram read_urscript_program(const std::string& path) {
  NativeProgram p;
  p.format = ControllerFormat::UrScript;
  add_program_file(p, path);
  const auto& lines = p.lines[0];
  const UrNames names = read_urscript_names(lines, path);
  // the motions and how many points each takes (its first arguments); servoj, speedj, speedl: no Cartesian target
  static const std::regex move(R"(\b(movej|movel|movep|movec|servoc|servoj|speedj|speedl)\s*\()");
  std::map<std::string, size_t> used;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string code = code_of(lines[i]);
    const int ln = static_cast<int>(i + 1);
    const std::string at = where(path, ln);
    for (auto it = std::sregex_iterator(code.begin(), code.end(), move); it != std::sregex_iterator(); ++it) {
      size_t close = 0;
      const size_t open = static_cast<size_t>(it->position(0) + it->length(0) - 1);
      const auto args = call_args(code, open, close, at);
      const std::string name = (*it)[1].str();
      const size_t n = name == "movec" ? 2 : 1;
      const bool movej = name == "movej";
      if (args.size() < n || args[0].empty() || (n == 2 && args[1].empty()))
        throw InputError(at + ": " + name + " needs its target" + (n == 2 ? "s (via and end point)" : ""));
      const std::string statement = code.substr(code.find_first_not_of(" \t"));
      if (name == "servoj" || name == "speedj" || name == "speedl") {
        // joint positions streamed, or speeds: the motion is named, it has no target to compensate
        const std::string& a = args[0];
        p.motions.push_back(motion_around(code, ln, 'O', code.find(a, open), a.size()));
        // servoj to joints computed from a pose: a Cartesian target kincal cannot reach
        const auto v = names.vars.find(a);
        if (name == "servoj" && a.find("get_inverse_kin") != std::string::npos)
          p.unresolved.push_back({at, statement, why_computed(a)});
        else if (name == "servoj" && v != names.vars.end() && v->second.from_pose)
          p.unresolved.push_back({at, statement, "'" + a + "' is assigned get_inverse_kin(..): joints computed from a pose at run time"});
        continue;
      }
      const char kind = movej ? 'J' : name == "movel" ? 'L' : n == 2 ? 'C' : 'O';
      size_t from = open;
      for (size_t k = 0; k < n; ++k) {
        const std::string& a = args[k];
        const size_t a_at = code.find(a, from);
        from = a_at + a.size();
        p.motions.push_back(motion_around(code, ln, kind, a_at, a.size()));
        add_urscript_target(p, names, used, lines, path, a, a_at, ln, statement, movej);
      }
    }
  }
  keep_named_targets_cartesian(p, '#', false);
  return p;
}

// a pose literal p[x,y,z,rx,ry,rz] (m, rad) of a pose in mm and ABC degrees
std::string urscript_pose(const Pose6& pose) {
  const Vec3 rv = ctl::rotation_vector_of(pose.abc);
  std::string s = "p[";
  for (int k = 0; k < 3; ++k) s += (k ? ", " : "") + ctl::fixed(pose.xyz[k] / 1000.0, 8);
  for (int k = 0; k < 3; ++k) s += ", " + ctl::fixed(rv[k], 10);
  return s + "]";
}

// a joint list [q1..q6] in rad
std::string urscript_joints(const Vec6& q_deg) {
  std::string s = "[";
  for (int j = 0; j < 6; ++j) s += (j ? ", " : "") + ctl::fixed(q_deg[j] * kDeg, ctl::kRadDecimals);
  return s + "]";
}

}  // namespace kincal
