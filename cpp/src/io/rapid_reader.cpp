// kincal: RAPID modules read in (the modules of one task read as one; the backup's other modules as
// context). A statement runs to its ';' over as many lines as it takes; MODULE/ENDMODULE are checked.
// Motions: every instruction of the RAPID manual that moves the robot to a robtarget (Move*, Trigg*,
// Search*, Arc*, Cap*), with the tooldata and wobjdata of each statement; MoveAbsJ, MoveExtJ and
// SearchExtJ are motions without a Cartesian target. A target the program computes (Offs, RelTool,
// CRobT, a VAR, an assigned one), a name declared nowhere, and any motion-looking instruction kincal
// does not read are listed as unresolved with why. A declared target used in a second (tool, wobj) gets
// a copy named after it (name_1, ...).
// (The writers of a read value, rapid_robtarget and rapid_jointtarget, are in rapid.cpp.)
#include "controller_writers.hpp"
#include "rapid_text.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <regex>
#include <set>

namespace kincal {

using namespace rapid;

namespace {

constexpr size_t kRapidNameLimit = 32;

// One data declaration of a module.
struct Decl {
  std::string type, storage, name, value, path;  // type and storage upper case
  int file = 0, line = 0;
  bool local = false, array = false;
  int vline = 0, vlast = 0, tline = 0;      // value's first and last line, the type's line
  size_t vbegin = 0, vend = 0, tbegin = 0, tend = 0;
};

std::vector<Decl> declarations_of(const std::vector<Stmt>& stmts, int file, const std::string& path) {
  static const std::regex decl_re(
      R"(^\s*(LOCAL\s+|TASK\s+)?(CONST|PERS|VAR)\s+(\w+)\s+(\w+)\s*(\{[^}]*\})?\s*(?::=\s*(.*?))?\s*;\s*$)", std::regex::icase);
  std::vector<Decl> out;
  for (const Stmt& s : stmts) {
    std::smatch m;
    if (!std::regex_match(s.text, m, decl_re)) continue;
    Decl d;
    d.local = upper_case(m[1].str()).rfind("LOCAL", 0) == 0;
    d.storage = upper_case(m[2].str()), d.type = upper_case(m[3].str()), d.name = m[4].str();
    d.array = m[5].matched, d.file = file, d.line = s.line(), d.path = path;
    std::tie(d.tline, d.tbegin) = s.pos(static_cast<size_t>(m.position(3)));
    d.tend = d.tbegin + static_cast<size_t>(m.length(3));
    if (m[6].matched && m.length(6) > 0) {
      d.value = m[6].str();
      const auto [b, e] = span_of(m, 6);
      std::tie(d.vline, d.vbegin) = s.pos(b);
      std::tie(d.vlast, d.vend) = s.pos(e - 1);
      ++d.vend;
    }
    out.push_back(d);
  }
  return out;
}

// A statement's arguments: the spans (in its text) of each top-level, comma-separated item's value,
// with the optional arguments (\Conc, \ID:=10, \WObj:=w, ...) before and after it left out. Pure
// switches give no item.
std::vector<std::pair<size_t, size_t>> positional(const std::string& s, size_t from) {
  std::vector<std::pair<size_t, size_t>> out;
  int depth = 0;
  bool str = false;
  size_t b = from;
  auto item = [&](size_t e) {
    size_t i = b;
    static const std::regex opt_re(R"(^\s*\\\w+(?:\s*:=\s*(?:"[^"]*"|[^\s\\,]+))?\s*)");
    std::smatch m;
    std::string rest = s.substr(i, e - i);
    while (std::regex_search(rest, m, opt_re) && m.length(0) > 0) i += static_cast<size_t>(m.length(0)), rest = rest.substr(static_cast<size_t>(m.length(0)));
    size_t j = i;
    int d = 0;
    for (; j < e; ++j) {
      if (s[j] == '[' || s[j] == '(' || s[j] == '{') ++d;
      if (s[j] == ']' || s[j] == ')' || s[j] == '}') --d;
      if (s[j] == '\\' && d == 0) break;
    }
    while (i < j && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    while (j > i && std::isspace(static_cast<unsigned char>(s[j - 1]))) --j;
    if (j > i) out.emplace_back(i, j);
  };
  for (size_t c = from; c < s.size(); ++c) {
    if (s[c] == '"') str = !str;
    if (str) continue;
    if (s[c] == '[' || s[c] == '(' || s[c] == '{') ++depth;
    if (s[c] == ']' || s[c] == ')' || s[c] == '}') --depth;
    if (depth == 0 && (s[c] == ',' || s[c] == ';')) item(c), b = c + 1;
  }
  if (b < s.size()) item(s.size());
  return out;
}

// The motion instructions read: the positional arguments that are targets, the tool's place counted
// from the last positional argument, the kind, and the search point (an output) if any.
struct Instr {
  int to[2];
  int n_to;
  int tool_back;
  char kind;
  int search_point = -1;
};

const Instr* instruction(const std::string& word) {
  static const std::map<std::string, Instr> table = [] {
    std::map<std::string, Instr> t;
    t["MOVEJ"] = {{0, 0}, 1, 1, 'J'};
    t["MOVEL"] = {{0, 0}, 1, 1, 'L'};
    t["MOVEC"] = {{0, 1}, 2, 1, 'C'};
    for (const char* x : {"DO", "AO", "GO"}) {  // Tool, Signal, Value
      t[std::string("MOVEJ") + x] = {{0, 0}, 1, 3, 'O'};
      t[std::string("MOVEL") + x] = {{0, 0}, 1, 3, 'O'};
      t[std::string("MOVEC") + x] = {{0, 1}, 2, 3, 'C'};
    }
    t["MOVEJSYNC"] = {{0, 0}, 1, 2, 'O'};  // Tool, ProcName
    t["MOVELSYNC"] = {{0, 0}, 1, 2, 'O'};
    t["MOVECSYNC"] = {{0, 1}, 2, 2, 'C'};
    t["TRIGGJ"] = t["TRIGGJIOS"] = {{0, 0}, 1, 1, 'J'};
    t["TRIGGL"] = t["TRIGGLIOS"] = {{0, 0}, 1, 1, 'L'};
    t["TRIGGC"] = {{0, 1}, 2, 1, 'C'};
    t["SEARCHL"] = t["SEARCHJ"] = {{2, 2}, 1, 1, 'O', 1};  // Signal, SearchPoint, ToPoint, Speed, Tool
    t["SEARCHC"] = {{2, 3}, 2, 1, 'C', 1};
    for (const char* n : {"", "1", "2"}) {  // ArcL1, ArcL2 ...: the MultiMove forms
      // (a copy of ArcLStart would strike the arc earlier: not a line kincal inserts targets on)
      t[std::string("ARCL") + n + "START"] = {{0, 0}, 1, 1, 'O'};
      t[std::string("ARCL") + n] = t[std::string("ARCL") + n + "END"] = {{0, 0}, 1, 1, 'L'};
      for (const char* e : {"", "START", "END"}) t[std::string("ARCC") + n + e] = {{0, 1}, 2, 1, 'C'};
    }
    t["SPOTL"] = {{0, 0}, 1, 1, 'L'};  // ToPoint, Speed, Spot, Tool (the spot welding option)
    t["SPOTJ"] = {{0, 0}, 1, 1, 'O'};
    t["CAPL"] = {{0, 0}, 1, 1, 'L'};
    t["CAPC"] = {{0, 1}, 2, 1, 'C'};
    t["MOVEABSJ"] = t["MOVEEXTJ"] = t["SEARCHEXTJ"] = {{0, 0}, 0, 0, 'O'};  // no robtarget
    return t;
  }();
  const auto it = table.find(word);
  return it == table.end() ? nullptr : &it->second;
}

// Instructions of the motion families that do not move the robot (settings, events, process data).
bool setting_instruction(const std::string& w) {
  static const std::set<std::string> s{
      "TRIGGIO", "TRIGGEQUIP", "TRIGGINT", "TRIGGCHECKIO", "TRIGGSPEED", "TRIGGRAMPAO", "TRIGGSTOPPROC",
      "TRIGGDATARESET", "TRIGGDATACOPY", "ARCREFRESH", "ARCKILL", "CAPREFRESH", "CAPCONDSETDO", "CAPEQUISETUP",
      "CAPAPTRSETUP", "CAPLATRSETUP", "CAPNOPROCESS", "CAPWEAVESYNC", "CAPINIT", "MOVEJSYNCSETUP"};
  return s.count(w) > 0;
}

// Motions of other process options, listed rather than read.
bool other_motion(const std::string& w) {
  static const std::regex family(R"(^(MOVE|ARC|TRIGG|SEARCH|CAP)\w+$)"),
      other(R"(^(SPOT(L|J|ML)|DISP(L|C)|PAINT(L|C)|CONTACTL)$)");
  return std::regex_match(w, family) || std::regex_match(w, other);
}

struct Module {
  std::string path;
  std::vector<Stmt> stmts;
  std::vector<Decl> decls;
};

Module module_of(const std::string& path, const std::vector<std::string>& lines, int file) {
  Module m{path, statements(lines), {}};
  m.decls = declarations_of(m.stmts, file, path);
  return m;
}

// names assigned (p := .., p.trans.z := .., p{2} := ..) or written by a search (its SearchPoint)
void assigned_names(const Module& m, std::map<std::string, std::string>& assigned) {
  static const std::regex assign_re(R"(^\s*(\w+)(?:\.\w+|\{[^}]*\})*\s*:=)"), instr_re(R"(^\s*(\w+))");
  for (const Stmt& s : m.stmts) {
    std::smatch a;
    const std::string at = where(m.path, s.line());
    if (std::regex_search(s.text, a, assign_re)) {
      assigned.emplace(upper_case(a[1].str()), at);
    } else if (std::regex_search(s.text, a, instr_re)) {
      const Instr* in = instruction(upper_case(a[1].str()));
      if (!in || in->search_point < 0) continue;
      const auto args = positional(s.text, static_cast<size_t>(a.length(0)));
      if (args.size() > static_cast<size_t>(in->search_point)) {
        const auto& [b, e] = args[static_cast<size_t>(in->search_point)];
        assigned.emplace(upper_case(s.text.substr(b, e - b)), at);
      }
    }
  }
}

void check_module(const Module& m) {
  static const std::regex mod_re(R"(^\s*MODULE\s+\w+)", std::regex::icase), end_re(R"(^\s*ENDMODULE\b)", std::regex::icase);
  int module_line = 0;
  bool closed = false;
  for (const Stmt& s : m.stmts) {
    const std::string at = where(m.path, s.line());
    if (!s.ended) throw InputError(at + ": a statement not ended by ';' (end of file)");
    if (std::regex_search(s.text, mod_re)) {
      if (module_line && !closed) throw InputError(at + ": MODULE inside MODULE");
      module_line = s.line(), closed = false;
    } else if (std::regex_search(s.text, end_re)) {
      if (!module_line || closed) throw InputError(at + ": ENDMODULE without MODULE");
      closed = true;
    }
  }
  if (!module_line) throw InputError(m.path + ": no MODULE in the file");
  if (!closed) throw InputError(where(m.path, module_line) + ": MODULE is not closed by ENDMODULE (end of file)");
}

std::vector<std::string> file_lines(const std::string& path) {
  NativeProgram tmp;
  add_program_file(tmp, path);
  return tmp.lines[0];
}

}  // namespace

Declarations read_rapid_declarations(const std::vector<std::string>& paths) {
  Declarations out;
  std::map<std::string, std::string> assigned;
  std::vector<Module> mods;
  for (const std::string& path : paths) {
    mods.push_back(module_of(path, file_lines(path), 0));
    assigned_names(mods.back(), assigned);
  }
  for (const Module& m : mods)
    for (const Decl& d : m.decls) {
      if (d.local) continue;
      Declaration x{d.type, d.name, m.path, d.line, trim(d.value), d.storage == "VAR" || assigned.count(upper_case(d.name)) > 0};
      out.named.emplace(upper_case(d.name), x);
    }
  return out;
}

namespace {

// The reader of one task's modules.
struct Reader {
  NativeProgram p;
  std::deque<Module> mods;                       // per file of p (context files: their declarations)
  std::deque<Decl> elsewhere;                    // the backup's declarations that do not join the program
  std::map<std::string, const Decl*> global;     // non-LOCAL declarations of the modules read
  std::map<std::string, std::string> assigned;   // name -> where
  std::set<std::string> routines, names;         // upper case
  const Declarations& context;
  std::map<std::string, std::vector<std::pair<std::string, size_t>>> uses;  // declaration -> (frames, target)

  explicit Reader(const Declarations& c) : context(c) {}

  // a declaration visible from file f: its own LOCAL ones, then the task's, then the backup's (a
  // Cartesian target of the backup joins the program: its file is then written with it)
  const Decl* find(const std::string& name, int f, bool join) {
    const std::string u = upper_case(name);
    for (const Decl& d : mods[static_cast<size_t>(f)].decls)
      if (d.local && upper_case(d.name) == u) return &d;
    const auto it = global.find(u);
    if (it != global.end()) return it->second;
    const Declaration* c = context.find(name);
    if (!c) return nullptr;
    if (!join || c->type != "ROBTARGET" || c->run_time || c->value.empty()) {
      Decl d;
      d.type = c->type, d.storage = c->run_time ? "VAR" : "PERS", d.name = c->name, d.value = c->value;
      d.path = c->path, d.line = c->line, d.file = -1;
      elsewhere.push_back(d);
      return &elsewhere.back();
    }
    size_t file = static_cast<size_t>(std::find(p.paths.begin(), p.paths.end(), c->path) - p.paths.begin());
    if (file == p.paths.size()) {
      add_program_file(p, c->path);
      mods.push_back(module_of(c->path, p.lines.back(), static_cast<int>(file)));
    }
    for (const Decl& d : mods[file].decls)
      if (!d.local && upper_case(d.name) == u) return &d;
    throw InputError(where(c->path, c->line) + ": '" + name + "' is not declared here as the backup's files said");
  }

  // the tool's or work object's frame; "" or why the statement cannot be compensated
  std::string frame(const std::string& name, bool tool, int f, const std::string& at, Eigen::Isometry3d& out) {
    out = Eigen::Isometry3d::Identity();
    if (upper_case(name) == (tool ? "TOOL0" : "WOBJ0")) return "";
    const char* what = tool ? "tool" : "work object";
    if (!std::regex_match(name, std::regex(R"(\w+)"))) return std::string("its ") + what + " is computed at run time (" + name + ")";
    const Decl* d = find(name, f, false);
    if (!d) return std::string("its ") + what + " '" + name + "' is declared nowhere";
    const std::string type = tool ? "TOOLDATA" : "WOBJDATA";
    const std::string dat = where(d->path, d->line);
    if (d->type != type) throw InputError(at + ": " + what + " '" + name + "' is a " + d->type + " (" + dat + "), not a " + type);
    if (d->value.empty() || d->storage == "VAR" || assigned.count(upper_case(name)))
      return std::string("its ") + what + " '" + name + "' is set at run time";
    const auto parts = parts_of(d->value);
    if (tool) {
      if (parts.size() != 3) throw InputError(dat + ": a tooldata has 3 parts [robhold,tframe,tload], this one " + std::to_string(parts.size()));
      if (upper_case(parts[0]) == "FALSE")
        throw InputError(at + ": tool '" + name + "' is a stationary tool (robhold FALSE): kincal compensates tools the robot holds");
      out = frame_of(parts[1], dat, "the tooldata's tframe");
      return "";
    }
    if (parts.size() != 5) throw InputError(dat + ": a wobjdata has 5 parts [robhold,ufprog,ufmec,uframe,oframe], this one " + std::to_string(parts.size()));
    if (upper_case(parts[0]) == "TRUE")
      throw InputError(at + ": work object '" + name + "' is held by the robot (robhold TRUE): kincal does not compensate a stationary tool's programs");
    if (upper_case(parts[1]) == "FALSE" || trim(parts[2]) != "\"\"")
      throw InputError(at + ": work object '" + name + "' is a moving user frame (ufprog FALSE or ufmec " + parts[2] + "): kincal compensates fixed work objects");
    out = frame_of(parts[3], dat, "the wobjdata's uframe") * frame_of(parts[4], dat, "the wobjdata's oframe");
    return "";
  }

  std::string copy_name(const std::string& name) {
    for (int k = 1;; ++k) {
      const std::string suffix = "_" + std::to_string(k);
      const std::string n = name.substr(0, std::min(name.size(), kRapidNameLimit - suffix.size())) + suffix;
      if (names.insert(upper_case(n)).second) return n;
    }
  }

  void motion(const Module& m, const Stmt& s, int f, size_t word_at, const std::string& word) {
    const std::string at = where(m.path, s.line()), statement = trim(s.text), W = upper_case(word);
    const Instr* in = instruction(W);
    if (!in) {
      p.unresolved.push_back({at, statement, "an instruction kincal does not read (" + word + ")"});
      return;
    }
    const auto args = positional(s.text, word_at + word.size());
    auto arg = [&](size_t i) { return s.text.substr(args[i].first, args[i].second - args[i].first); };
    auto line_of = [&](size_t o) { return s.pos(o); };
    if (in->n_to == 0) {  // joints or external axes: kept as written
      p.motions.push_back(motion_around(s.text, s.line(), W == "MOVEABSJ" ? 'J' : 'O', word_at, word.size()));
      p.motions.back().file = f;
      return;
    }
    const size_t need = static_cast<size_t>(std::max(in->to[0], in->to[1]) + in->tool_back + 1);
    if (args.size() < need) throw InputError(at + ": " + word + " needs target(s), speed, zone and tool (" + std::to_string(args.size()) + " arguments)");
    const std::string tool = arg(args.size() - static_cast<size_t>(in->tool_back));
    std::smatch w;
    const std::string wobj = std::regex_search(s.text, w, std::regex(R"(\\WObj\s*:=\s*([^\s\\,;]+))", std::regex::icase)) ? w[1].str() : "wobj0";
    Eigen::Isometry3d tframe, wframe;
    std::string why = frame(tool, true, f, at, tframe);
    if (why.empty()) why = frame(wobj, false, f, at, wframe);
    std::string named;
    for (const std::string& n : {tool, wobj})
      if (upper_case(n) != "TOOL0" && upper_case(n) != "WOBJ0") named += (named.empty() ? "" : ", ") + n;
    const bool movej = W == "MOVEJ";
    const auto [wl, wc] = line_of(word_at);
    const NativeEdit to_absj{f, wl, wc, wc + word.size(), "MoveAbsJ"};
    for (int a = 0; a < in->n_to; ++a) {
      const size_t i = static_cast<size_t>(in->to[a]);
      const std::string v = arg(i);
      p.motions.push_back(motion_around(s.text, s.line(), in->kind, args[i].first, v.size()));
      NativeMotion& mo = p.motions.back();
      mo.file = f;
      if (W.size() > 3 && W.compare(W.size() - 3, 3, "END") == 0 && in->kind == 'L')  // a target inserted before
        mo.head.replace(mo.head.find(word), word.size(), word.substr(0, word.size() - 3));  // ArcLEnd continues the seam
      if (!why.empty()) {
        if (a == 0) p.unresolved.push_back({at, statement, why});
        continue;
      }
      NativeTarget t;
      t.tool = tframe, t.frame = wframe, t.frames_named = named, t.file = f;
      if (v[0] == '[') {
        std::tie(t.line, t.begin) = line_of(args[i].first);
        int last = 0;
        std::tie(last, t.end) = line_of(args[i].second - 1);
        ++t.end;
        if (last != t.line) t.last_line = last;
        parse_robtarget(v, at, t);
        t.joint_motion = movej;
        t.joint_edits.push_back(to_absj);
        mo.target = static_cast<int>(p.targets.size());
        p.targets.push_back(t);
        continue;
      }
      if (!std::regex_match(v, std::regex(R"(\w+)"))) {  // Offs(..), RelTool(..), CRobT(..), p{i}, ...
        p.unresolved.push_back({at, statement, v.find('{') != std::string::npos ? "computed at run time (an array element)" : "computed at run time"});
        continue;
      }
      const Decl* d = find(v, f, true);
      if (!d) {
        p.unresolved.push_back({at, statement, "declared nowhere"});
        continue;
      }
      const std::string dat = where(d->path, d->line);
      if (d->type != "ROBTARGET") throw InputError(at + ": target '" + v + "' is not declared as a robtarget (a " + d->type + ", " + dat + ")");
      const Declaration* c = context.find(v);
      const auto as = assigned.find(upper_case(v));
      if (d->value.empty() || d->storage == "VAR" || as != assigned.end() || (c && c->path == d->path && c->run_time)) {
        p.unresolved.push_back({at, statement, "computed at run time (" + (as != assigned.end() ? "assigned at " + as->second : d->value.empty() ? "declared without a value" : "a VAR") + ")"});
        continue;
      }
      const std::string key = std::to_string(d->file) + ":" + upper_case(d->name), frames = upper_case(tool + "," + wobj);
      auto& u = uses[key];
      const auto same = std::find_if(u.begin(), u.end(), [&](const auto& x) { return x.first == frames; });
      if (same != u.end()) {
        NativeTarget& old = p.targets[same->second];
        mo.target = static_cast<int>(same->second);
        if (old.copy_of >= 0) {
          old.edits.push_back({f, to_absj.line, 0, 0, old.name});
          std::tie(old.edits.back().line, old.edits.back().begin) = line_of(args[i].first);
          old.edits.back().end = old.edits.back().begin + v.size();
          continue;
        }
        old.joint_motion &= movej;
        old.joint_edits.push_back(to_absj);
        continue;
      }
      t.line = d->vline, t.begin = d->vbegin, t.end = d->vend, t.file = d->file;
      if (d->vlast != d->vline) t.last_line = d->vlast;
      t.name = d->name;
      parse_robtarget(d->value, where(d->path, d->vline), t);
      if (u.empty()) {
        t.joint_motion = movej;
        t.joint_edits.push_back({d->file, d->tline, d->tbegin, d->tend, "jointtarget"});
        t.joint_edits.push_back(to_absj);
      } else {  // a second (tool, wobj): a copy, declared after the original, and this statement renamed
        t.copy_of = static_cast<int>(u.front().second);
        t.name = copy_name(d->name);
        NativeEdit e{f, 0, 0, 0, t.name};
        std::tie(e.line, e.begin) = line_of(args[i].first);
        e.end = e.begin + v.size();
        t.edits.push_back(e);
      }
      u.emplace_back(frames, p.targets.size());
      mo.target = static_cast<int>(p.targets.size());
      p.targets.push_back(t);
    }
  }

  void read(const std::vector<std::string>& paths) {
    p.format = ControllerFormat::Rapid;
    for (const std::string& path : paths) {
      add_program_file(p, path);
      mods.push_back(module_of(path, p.lines.back(), static_cast<int>(mods.size())));
      check_module(mods.back());
    }
    static const std::regex routine_re(R"(^\s*(?:LOCAL\s+)?(?:PROC|TRAP|FUNC\s+\w+)\s+(\w+))", std::regex::icase);
    for (const Module& m : mods) {
      assigned_names(m, assigned);
      for (const Decl& d : m.decls) {
        names.insert(upper_case(d.name));
        if (!d.local) global.emplace(upper_case(d.name), &d);
      }
      for (const Stmt& s : m.stmts) {
        std::smatch r;
        if (std::regex_search(s.text, r, routine_re)) routines.insert(upper_case(r[1].str()));
      }
    }
    for (const auto& [n, d] : context.named) names.insert(n);
    // a statement's instruction: after a label, CASE ..:, or a compact IF's condition
    static const std::regex instr_re(
        R"(^(\s*(?:(?:CASE\b[^:;]*|DEFAULT\s*|\w+\s*):(?!=)\s*)?(?:IF\b.*?\s(?=(?:Move|Arc|Trigg|Search|Cap)\w*[\s\\]))?)([A-Za-z]\w*)(?=[\s\\;]))",
        std::regex::icase);
    const size_t n_read = mods.size();
    for (size_t f = 0; f < n_read; ++f)
      for (const Stmt& s : mods[f].stmts) {
        std::smatch m;
        if (!std::regex_search(s.text, m, instr_re)) continue;
        const std::string W = upper_case(m[2].str());
        if (routines.count(W) || setting_instruction(W) || !(instruction(W) || other_motion(W))) continue;
        motion(mods[f], s, static_cast<int>(f), static_cast<size_t>(m.position(2)), m[2].str());
      }
    keep_named_targets_cartesian(p, '!', true);
    for (NativeTarget& t : p.targets)
      if (t.copy_of >= 0) t.joint_motion = false, t.joint_edits.clear();  // (a copy stays a robtarget)
  }
};

}  // namespace

NativeProgram read_rapid_program(const std::vector<std::string>& paths, const Declarations& context) {
  Reader r(context);
  r.read(paths);
  return std::move(r.p);
}

}  // namespace kincal
