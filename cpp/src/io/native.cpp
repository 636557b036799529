// kincal: native programs (KRL, RAPID, FANUC LS, URScript) in and out: the readers are krl_reader.cpp,
// rapid_reader.cpp, ls_reader.cpp and urscript_reader.cpp;
// the writer replaces each target's value span and keeps every other byte.
#include "kincal/io/native.hpp"

#include "controller_writers.hpp"
#include "kincal/io/file.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <regex>

namespace kincal {

NativeProgram read_krl_program(const std::vector<std::string>& src_paths, const Declarations& context);
NativeProgram read_rapid_program(const std::vector<std::string>& paths, const Declarations& context);
Declarations read_krl_declarations(const std::vector<std::string>& paths);
Declarations read_rapid_declarations(const std::vector<std::string>& paths);
std::string krl_aggregate(const std::string& old, const Pose6& pose, const ControllerTarget& t, bool is_frame);
std::string rapid_robtarget(const std::string& old, const Pose6& pose, const ControllerTarget& t);
NativeProgram read_ls_program(const std::string& path);
std::string ls_position(const std::string& old, const Pose6& pose, const ControllerTarget& t);
NativeProgram read_urscript_program(const std::string& path);
std::string urscript_pose(const Pose6& pose);
std::string krl_axis(const std::string& old, const Vec6& q_deg);
std::string rapid_jointtarget(const std::string& old, const Vec6& q_deg);
std::string ls_joint_position(const std::string& old, const Vec6& q_deg);
std::string urscript_joints(const Vec6& q_deg);
std::string ls_renumbered(const std::string& text);

NativeProgram read_native_programs(const std::vector<std::string>& paths, ControllerFormat format,
                                   const Declarations& context) {
  if (paths.empty()) throw InputError("no program to read");
  if (format == ControllerFormat::Krl) return read_krl_program(paths, context);
  if (format == ControllerFormat::Rapid) return read_rapid_program(paths, context);
  if (paths.size() > 1)
    throw InputError(paths[1] + ": a " + std::string(format_name(format)) + " program is read by itself");
  if (format == ControllerFormat::FanucLs) return read_ls_program(paths[0]);
  if (format == ControllerFormat::UrScript) return read_urscript_program(paths[0]);
  throw InputError(paths[0] + ": not a native program (" + format_name(format) + ")");
}

NativeProgram read_native_program(const std::string& path, ControllerFormat format, const Declarations& context) {
  return read_native_programs({path}, format, context);
}

const Declaration* Declarations::find(const std::string& name) const {
  const auto it = named.find(upper_case(name));
  return it == named.end() ? nullptr : &it->second;
}

Declarations read_declarations(const std::vector<std::string>& paths, ControllerFormat format) {
  if (format == ControllerFormat::Krl) return read_krl_declarations(paths);
  if (format == ControllerFormat::Rapid) return read_rapid_declarations(paths);
  return {};  // LS and URScript programs declare their own positions (the controller holds frames and registers)
}

namespace {

// the value of target k as the program writes it (an LS position: its GP1 lines)
std::string old_value(const NativeProgram& p, const NativeTarget& nt) {
  const auto& f = p.lines[static_cast<size_t>(nt.file)];
  if (nt.last_line <= nt.line) return f[static_cast<size_t>(nt.line - 1)].substr(nt.begin, nt.end - nt.begin);
  std::string joined;
  for (int l = nt.line; l <= nt.last_line; ++l) joined += f[static_cast<size_t>(l - 1)] + (l < nt.last_line ? "\n" : "");
  return joined.substr(nt.begin, joined.size() - f[static_cast<size_t>(nt.last_line - 1)].size() + nt.end - nt.begin);
}

// The lines of the program's first file with each inserted target's motion before the motion it precedes
// (LS: the new positions P[n] before /END, numbered after the largest in the program).
void with_inserted_targets(const NativeProgram& p, const std::vector<InsertedTarget>& inserted,
                           std::vector<std::vector<std::string>>& files) {
  if (inserted.empty()) return;
  std::map<std::pair<int, int>, std::string> before;  // per file and line: the motions inserted before it
  std::vector<std::string>& lines = files[static_cast<size_t>(p.motions[inserted[0].motion].file)];  // (LS: one file)
  const std::string eol = !lines.empty() && !lines[0].empty() && lines[0].back() == '\r' ? "\r\n" : "\n";
  std::string positions;
  int next_p = 0;
  for (const NativeTarget& nt : p.targets)
    if (p.format == ControllerFormat::FanucLs) next_p = std::max(next_p, std::stoi(nt.name.substr(2)));
  for (const std::string& l : lines) {  // joint positions and positions no motion uses count as well
    std::smatch m;
    if (p.format == ControllerFormat::FanucLs && std::regex_search(l, m, std::regex(R"(^\s*P\[\s*(\d+))")))
      next_p = std::max(next_p, std::stoi(m[1].str()));
  }
  for (const InsertedTarget& ins : inserted) {
    const NativeMotion& mo = p.motions[ins.motion];
    const NativeTarget& nt = p.targets[static_cast<size_t>(mo.target)];
    const std::string old = old_value(p, nt);
    std::string value;
    if (p.format == ControllerFormat::Krl) {
      value = krl_aggregate(old, ins.pose, ins.target, false);
    } else if (p.format == ControllerFormat::Rapid) {
      value = rapid_robtarget(old, ins.pose, ins.target);
    } else if (p.format == ControllerFormat::UrScript) {
      value = urscript_pose(ins.pose);
    } else {
      value = "P[" + std::to_string(++next_p) + "]";
      positions += value + "{" + eol + "   GP1:" + eol + ls_position(old, ins.pose, ins.target) + eol + "};" + eol;
    }
    before[{mo.file, mo.line}] += mo.indent + mo.head + value + mo.tail + eol;
  }
  for (const auto& [at, text] : before) files[static_cast<size_t>(at.first)][static_cast<size_t>(at.second - 1)].insert(0, text);
  if (positions.empty()) return;
  for (std::string& l : lines)
    if (l.compare(0, 4, "/END") == 0) l.insert(0, positions);
}

// A module written to a file of another name takes that name where the controller ties the two: KRL
// (the .src's first DEF or DEFFCT, the .dat's DEFDAT) and RAPID (MODULE). A name the controller would
// not take is refused, naming --out and the rule. Names are compared as the controllers do, ignoring case.
void rename_module(const NativeProgram& p, std::vector<std::vector<std::string>>& lines,
                   const std::vector<std::string>& out_paths) {
  const bool krl = p.format == ControllerFormat::Krl, ls = p.format == ControllerFormat::FanucLs;
  if (!krl && !ls) return;  // (a RAPID module's name is not its file's)
  const size_t max_len = krl ? 24 : 36;
  const char* language = krl ? "KRL" : "FANUC LS";
  static const std::regex def_re(R"(^(\s*(?:GLOBAL\s+)?DEF\s+)(\w+))", std::regex::icase),
      fct_re(R"(^(\s*(?:GLOBAL\s+)?DEFFCT\s+\w+(?:\s*\[\s*\d*\s*\])?\s+)(\w+))", std::regex::icase),
      dat_re(R"(^(\s*DEFDAT\s+)(\w+))", std::regex::icase), prog_re(R"(^(\s*/PROG\s+)(\w+))", std::regex::icase);
  for (size_t f = 0; f < lines.size(); ++f) {
    const std::string& out_path = out_paths[f];
    // an LS program's /PROG name is upper case on the controller (its file name is the same name)
    const std::string name = ls ? upper_case(ctl::stem_of(out_path)) : ctl::stem_of(out_path);
    if (upper_case(name) == upper_case(ctl::stem_of(p.paths[f]))) continue;  // written under its own name
    const bool dat = upper_case(p.paths[f]).size() >= 4 && upper_case(p.paths[f]).substr(p.paths[f].size() - 4) == ".DAT";
    for (std::string& l : lines[f]) {
      const std::string code = ls ? l : code_before(l, ';');
      std::smatch m;
      const bool found = ls     ? std::regex_search(code, m, prog_re)
                         : !dat ? std::regex_search(code, m, def_re) || std::regex_search(code, m, fct_re)
                                : std::regex_search(code, m, dat_re);
      if (!found) continue;
      if (upper_case(m[2].str()) != upper_case(name)) {
        bool valid = !name.empty() && name.size() <= max_len && std::isalpha(static_cast<unsigned char>(name[0]));
        for (char c : name) valid = valid && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
        if (!valid)
          throw InputError("--out " + out_path + ": a " + language + " module is named by its file" +
                           (krl ? "s" : "") + ", and '" + name + "' is not a " + language +
                           " name (a letter, then letters, digits or '_', at most " + std::to_string(max_len) +
                           " characters)");
        const auto [b, e] = span_of(m, 2);
        l.replace(b, e - b, name);
      }
      break;  // the module's own name: the first such line of the file
    }
  }
}

}  // namespace

namespace {

// each copy on a new line after its original's declaration: the original's lines as read, with the copy's
// name and value (added to the end of the declaration's last line, so that no line number moves)
void add_target_copies(const NativeProgram& p, const std::vector<Pose6>& pose, const std::vector<ControllerTarget>& t,
                       const std::vector<bool>& joints, std::vector<std::vector<std::string>>& lines) {
  for (size_t k = 0; k < p.targets.size(); ++k) {
    const NativeTarget& nt = p.targets[k];
    if (nt.copy_of < 0) continue;
    const NativeTarget& orig = p.targets[static_cast<size_t>(nt.copy_of)];
    const auto& f = p.lines[static_cast<size_t>(orig.file)];
    const int last = std::max(orig.line, orig.last_line);
    std::string decl;
    for (int l = orig.line; l <= last; ++l) decl += f[static_cast<size_t>(l - 1)] + (l < last ? "\n" : "");
    const size_t end = decl.size() - f[static_cast<size_t>(last - 1)].size() + orig.end;
    const std::string old = decl.substr(orig.begin, end - orig.begin);
    const bool as_joints = k < joints.size() && joints[k];
    std::string now;
    if (p.format == ControllerFormat::Krl)
      now = as_joints ? krl_axis(old, t[k].q_deg)
                      : krl_aggregate(old, pose[k], t[k], upper_case(decl.substr(0, orig.begin)).find("FRAME") != std::string::npos);
    else if (p.format == ControllerFormat::Rapid)
      now = as_joints ? rapid_jointtarget(old, t[k].q_deg) : rapid_robtarget(old, pose[k], t[k]);
    else
      throw InputError(where(p.paths[static_cast<size_t>(orig.file)], orig.line) + ": a copy of a " +
                       format_name(p.format) + " target is not written");
    decl.replace(orig.begin, end - orig.begin, now);
    // the name: its first whole word before the value
    const std::string head = upper_case(decl.substr(0, orig.begin)), name = upper_case(orig.name);
    size_t at = std::string::npos;
    for (size_t i = head.find(name); i != std::string::npos; i = head.find(name, i + 1)) {
      const auto word = [&](size_t c) { return c < head.size() && (std::isalnum(static_cast<unsigned char>(head[c])) || head[c] == '_'); };
      if ((i == 0 || !word(i - 1)) && !word(i + name.size())) { at = i; break; }
    }
    if (at == std::string::npos)
      throw InputError(where(p.paths[static_cast<size_t>(orig.file)], orig.line) + ": " + orig.name +
                       "'s declaration does not name it");
    decl.replace(at, name.size(), nt.name);
    lines[static_cast<size_t>(orig.file)][static_cast<size_t>(last - 1)] += "\n" + decl;
  }
}

}  // namespace

std::vector<OutputFile> write_native_program(const NativeProgram& p, const std::vector<Pose6>& pose,
                                             const std::vector<ControllerTarget>& t, const std::vector<bool>& joints,
                                             const std::vector<std::string>& out_paths,
                                             const std::vector<InsertedTarget>& inserted) {
  if (out_paths.size() != p.paths.size()) throw InputError(p.paths[0] + ": an output path for every file read is needed");
  std::vector<std::vector<std::string>> lines = p.lines;
  struct Replacement {
    size_t begin, end;
    std::string text;
  };
  // per line, the replacements (values and edits), applied from the right so that earlier spans keep their places
  std::map<std::pair<int, int>, std::vector<Replacement>> by_line;
  for (size_t k = 0; k < p.targets.size(); ++k) {
    const NativeTarget& nt = p.targets[k];
    const bool as_joints = k < joints.size() && joints[k];
    if (as_joints)
      for (const NativeEdit& e : nt.joint_edits) by_line[{e.file, e.line}].push_back({e.begin, e.end, e.text});
    for (const NativeEdit& e : nt.edits) by_line[{e.file, e.line}].push_back({e.begin, e.end, e.text});
    if (nt.copy_of >= 0) continue;  // declared on a line of its own, below
    auto& f = lines[static_cast<size_t>(nt.file)];
    if (nt.last_line <= nt.line) {
      const std::string& l = f[static_cast<size_t>(nt.line - 1)];
      const std::string old = l.substr(nt.begin, nt.end - nt.begin);
      std::string now;
      if (p.format == ControllerFormat::Krl) {
        if (as_joints) {
          now = krl_axis(old, t[k].q_deg);
        } else {
          const std::string head = upper_case(l.substr(0, nt.begin));
          now = krl_aggregate(old, pose[k], t[k], head.find("FRAME") != std::string::npos);
        }
      } else if (p.format == ControllerFormat::Rapid) {
        now = as_joints ? rapid_jointtarget(old, t[k].q_deg) : rapid_robtarget(old, pose[k], t[k]);
      } else if (p.format == ControllerFormat::FanucLs) {
        now = as_joints ? ls_joint_position(old, t[k].q_deg) : ls_position(old, pose[k], t[k]);
      } else {
        now = as_joints ? urscript_joints(t[k].q_deg) : urscript_pose(pose[k]);
      }
      by_line[{nt.file, nt.line}].push_back({nt.begin, nt.end, now});
      continue;
    }
    // a value over several lines (an LS /POS entry): replaced within them, the line count kept
    std::string joined;
    for (int l = nt.line; l <= nt.last_line; ++l) joined += f[static_cast<size_t>(l - 1)] + (l < nt.last_line ? "\n" : "");
    const size_t end = joined.size() - f[static_cast<size_t>(nt.last_line - 1)].size() + nt.end;
    const std::string old = joined.substr(nt.begin, end - nt.begin);
    joined.replace(nt.begin, end - nt.begin,
                   p.format == ControllerFormat::Rapid
                       ? (as_joints ? rapid_jointtarget(old, t[k].q_deg) : rapid_robtarget(old, pose[k], t[k]))
                       : (as_joints ? ls_joint_position(old, t[k].q_deg) : ls_position(old, pose[k], t[k])));
    size_t b = 0;
    for (int l = nt.line; l <= nt.last_line; ++l) {
      const size_t e = l < nt.last_line ? joined.find('\n', b) : joined.size();
      f[static_cast<size_t>(l - 1)] = joined.substr(b, e - b);
      b = e + 1;
    }
  }
  for (auto& [key, reps] : by_line) {
    std::sort(reps.begin(), reps.end(), [](const Replacement& a, const Replacement& b) { return a.begin > b.begin; });
    std::string& l = lines[static_cast<size_t>(key.first)][static_cast<size_t>(key.second - 1)];
    for (const Replacement& r : reps) l.replace(r.begin, r.end - r.begin, r.text);
  }
  add_target_copies(p, pose, t, joints, lines);
  with_inserted_targets(p, inserted, lines);
  rename_module(p, lines, out_paths);
  std::vector<OutputFile> out;
  for (size_t f = 0; f < lines.size(); ++f) {
    std::string text;
    for (size_t i = 0; i < lines[f].size(); ++i) {
      text += lines[f][i];
      if (i + 1 < lines[f].size() || p.final_newline[f]) text += '\n';
    }
    if (p.format == ControllerFormat::FanucLs && !inserted.empty()) text = ls_renumbered(text);
    out.push_back({out_paths[f], text});
  }
  return out;
}

std::vector<std::string> split_top(const std::string& s) {
  std::vector<std::string> out;
  int depth = 0;
  bool str = false;
  std::string cur;
  for (char c : s) {
    if (c == '"') str = !str;
    if (!str && (c == '{' || c == '[' || c == '(')) ++depth;
    if (!str && (c == '}' || c == ']' || c == ')')) --depth;
    if (!str && depth == 0 && c == ',') {
      out.push_back(cur);
      cur.clear();
      continue;
    }
    cur += c;
  }
  out.push_back(cur);
  for (auto& x : out) {
    const size_t a = x.find_first_not_of(" \t\r"), b = x.find_last_not_of(" \t\r");
    x = a == std::string::npos ? std::string() : x.substr(a, b - a + 1);
  }
  return out;
}

std::string upper_case(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string code_before(const std::string& line, char comment) {
  bool str = false;
  for (size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '"') str = !str;
    if (line[i] == comment && !str) return line.substr(0, i);
  }
  return !line.empty() && line.back() == '\r' ? line.substr(0, line.size() - 1) : line;
}

int word_count(const std::string& code, const std::string& name, bool ignore_case) {
  auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  const std::string hay = ignore_case ? upper_case(code) : code, needle = ignore_case ? upper_case(name) : name;
  int n = 0;
  if (needle.empty()) return 0;
  for (size_t at = hay.find(needle); at != std::string::npos; at = hay.find(needle, at + 1))
    if ((at == 0 || !word(hay[at - 1])) && (at + needle.size() >= hay.size() || !word(hay[at + needle.size()]))) ++n;
  return n;
}

namespace {

std::vector<std::string> lines_of(const std::string& text, bool& final_nl) {
  std::vector<std::string> out;
  size_t b = 0;
  while (b < text.size()) {
    const size_t e = text.find('\n', b);
    if (e == std::string::npos) {
      out.push_back(text.substr(b));
      final_nl = false;
      return out;
    }
    out.push_back(text.substr(b, e - b));
    b = e + 1;
  }
  final_nl = true;
  return out;
}

}  // namespace

void add_program_file(NativeProgram& p, const std::string& path) {
  bool nl = true;
  p.paths.push_back(path);
  p.lines.push_back(lines_of(read_text_file(path), nl));
  p.final_newline.push_back(nl);
}

std::pair<size_t, size_t> span_of(const std::smatch& m, int group) {
  const size_t b = static_cast<size_t>(m.position(group));
  return {b, b + static_cast<size_t>(m.length(group))};
}

NativeMotion motion_around(const std::string& code, int line, char kind, size_t begin, size_t size) {
  NativeMotion m;
  m.line = line;
  m.kind = kind;
  const size_t ind = std::min(code.find_first_not_of(" \t"), begin);
  m.indent = code.substr(0, ind);
  m.head = code.substr(ind, begin - ind);
  m.tail = code.substr(std::min(begin + size, code.size()));
  m.tail.erase(m.tail.find_last_not_of(" \t\r") + 1);
  return m;
}

void keep_named_targets_cartesian(NativeProgram& p, char comment, bool ignore_case) {
  // every whole word of the program's code counted once (one pass: programs of thousands of targets)
  const auto key = [&](std::string w) { return ignore_case ? upper_case(std::move(w)) : w; };
  std::map<std::string, int> wanted;
  for (const NativeTarget& t : p.targets)
    if (!t.name.empty() && t.joint_motion) wanted.emplace(key(t.name), 0);
  if (wanted.empty()) return;
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const auto& file : p.lines)
    for (const std::string& l : file) {
      const std::string code = code_before(l, comment);
      for (size_t i = 0; i < code.size();) {
        if (!word(code[i])) {
          ++i;
          continue;
        }
        size_t j = i;
        while (j < code.size() && word(code[j])) ++j;
        const auto it = wanted.find(key(code.substr(i, j - i)));
        if (it != wanted.end()) ++it->second;
        i = j;
      }
    }
  std::vector<int> motions(p.targets.size(), 0);
  for (const NativeMotion& m : p.motions)
    if (m.target >= 0) ++motions[static_cast<size_t>(m.target)];
  for (size_t k = 0; k < p.targets.size(); ++k) {
    NativeTarget& t = p.targets[k];
    if (t.name.empty() || !t.joint_motion) continue;
    t.joint_motion = wanted[key(t.name)] == motions[k] + 1;  // its declaration (or assignment) and its motions only
  }
}

}  // namespace kincal
