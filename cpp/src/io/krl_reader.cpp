// kincal: KRL programs read in: each .src with its .dat (DEF/END, DEFDAT/ENDDAT checked), names the
// program does not declare looked up in a backup's declarations ($config.dat, other data lists' DECL
// GLOBAL). Motions: PTP/LIN/CIRC (C_PTP, C_DIS, C_VEL, C_ORI, CA), SPTP/SLIN/SCIRC with WITH, SPLINE and
// PTP_SPLINE blocks of SPL/SLIN/SCIRC/SPTP segments. Each motion's tool and base are followed in file order
// (FDAT_ACT applied by BAS(#PTP_PARAMS / #CP_PARAMS / #FRAMES), BAS(#TOOL / #BASE), $TOOL=, $BASE=,
// $IPO_MODE=, and a motion's own WITH $TOOL=STOOL2(FP1), ...); a declared target used in a second frame gets
// a copy. Run-time targets (assigned in the program, A:B, $POS_ACT, *_REL, declared nowhere) are unresolved
// with why; E6AXIS / AXIS targets are joints and stay as they are.
#include "controller_writers.hpp"
#include "krl_text.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <set>

namespace kincal {

using namespace krl;

namespace {

struct Decl {
  std::string type, name, value, path;  // name as written
  int file = -1, line = 0;               // file: index in p.paths, -1 while in the context only
  size_t begin = 0, end = 0, type_begin = 0, type_end = 0;
  bool run_time = false;
};

// A tool or base as the program sets it: key "" (tool 0 / base 0 / $NULLFRAME), "TOOL_DATA[2]", "BASE_DATA[1]"
// or a FRAME's name; why: set at run time (kincal cannot know it).
struct FrameRef {
  std::string key, why, error;  // error: an FDAT the files do not declare (raised at a Cartesian motion)
};
struct FrameState {
  FrameRef tool, base;
  std::string ipo = "#BASE", fdat;  // $IPO_MODE; FDAT_ACT's value, applied by BAS
};

class KrlReader {
 public:
  explicit KrlReader(const Declarations& context) : context_(context) {
    p.format = ControllerFormat::Krl;
    for (const auto& [name, d] : context.named) taken_.insert(name);
  }

  void read_program(const std::string& src_path) {
    prog_ = static_cast<int>(own_.size());
    own_.emplace_back();
    assigned_.emplace_back();
    const int src = add(src_path);
    for (const char* ext : {".dat", ".DAT", ".Dat"}) {  // its data list, in the case the controller wrote it
      const std::string dat_path = ctl::with_ext(src_path, ext);
      if (FILE* f = std::fopen(dat_path.c_str(), "rb")) {
        std::fclose(f);
        scan(add(dat_path), true);
        break;
      }
    }
    scan(src, false);
    motions(src);
  }

  NativeProgram p;

 private:
  const Declarations& context_;
  int prog_ = 0;
  std::vector<std::map<std::string, Decl>> own_;     // per program: its .src's and .dat's declarations
  std::vector<std::set<std::string>> assigned_;      // per program: the names its .src assigns
  std::set<std::string> taken_;                      // every declared name (copies take new ones)
  std::map<std::string, std::map<std::string, int>> uses_;  // declared target -> frame key -> target
  std::map<std::string, Decl> located_;              // context targets placed in p

  int add(const std::string& path) {
    for (size_t f = 0; f < p.paths.size(); ++f)
      if (same_file(p.paths[f], path)) return static_cast<int>(f);
    add_program_file(p, path);
    return static_cast<int>(p.paths.size() - 1);
  }
  std::string at(int f, size_t i) const { return where(p.paths[static_cast<size_t>(f)], static_cast<int>(i + 1)); }

  // A declaration on line `line` of file f, its value's and type's spans (false when the line is none).
  bool locate(int f, int line, Decl& d) const {
    const std::string code = code_of(p.lines[static_cast<size_t>(f)][static_cast<size_t>(line - 1)]);
    std::smatch m;
    if (!std::regex_match(code, m, kDecl)) return false;
    d.type = upper_case(m[2].str());
    d.name = m[3].str();
    d.value = m[4].str();
    d.file = f;
    d.line = line;
    d.path = p.paths[static_cast<size_t>(f)];
    std::tie(d.type_begin, d.type_end) = span_of(m, 2);
    if (m[4].matched) std::tie(d.begin, d.end) = span_of(m, 4);
    return true;
  }

  // Declarations and the DEF/END (DEFDAT/ENDDAT) structure of one file; a .src's assignments.
  void scan(int f, bool dat) {
    const auto& lines = p.lines[static_cast<size_t>(f)];
    const char* open = dat ? "DEFDAT" : "DEF";
    const char* close = dat ? "ENDDAT" : "END";
    static const std::regex global_def(R"(^\s*GLOBAL\s+DEF(FCT)?\b)", std::regex::icase);
    int open_line = 0;
    bool closed = false;
    for (size_t i = 0; i < lines.size(); ++i) {
      const std::string code = code_of(lines[i]);
      std::string first = upper_case(trim(code));
      first = first.substr(0, first.find_first_of(" \t("));
      if (first == "GLOBAL" && std::regex_search(code, global_def)) first = "DEF";
      if (first == open || (!dat && first == "DEFFCT")) {
        if (open_line && !closed && dat) throw InputError(at(f, i) + ": DEFDAT inside DEFDAT");
        open_line = static_cast<int>(i + 1);
        closed = false;
      } else if (first == close || (!dat && first == "ENDFCT")) {
        if (!open_line || closed) throw InputError(at(f, i) + ": " + first + " without " + open);
        closed = true;
      }
      Decl d;
      std::smatch m;
      if (locate(f, static_cast<int>(i + 1), d)) {
        own_[static_cast<size_t>(prog_)].emplace(upper_case(d.name), d);
        taken_.insert(upper_case(d.name));
      } else if (!dat && std::regex_search(code, m, kAssign)) {
        assigned_[static_cast<size_t>(prog_)].insert(upper_case(m[1].str()));
      }
    }
    if (!open_line) throw InputError(p.paths[static_cast<size_t>(f)] + ": no " + open + " in the file");
    if (!closed) throw InputError(where(p.paths[static_cast<size_t>(f)], open_line) + ": " + open + " is not closed by " + close + " (end of file)");
  }

  // A name the program declares, or else the backup's declarations do; false when none does.
  bool lookup(const std::string& name, Decl& d) const {
    const std::string key = upper_case(name);
    const auto& own = own_[static_cast<size_t>(prog_)];
    if (auto it = own.find(key); it != own.end()) return d = it->second, true;
    if (auto it = located_.find(key); it != located_.end()) return d = it->second, true;
    const Declaration* c = context_.find(key);
    if (!c) return false;
    d = Decl{c->type, c->name, c->value, c->path, -1, c->line, 0, 0, 0, 0, c->run_time};
    return true;
  }

  // an FDAT's fields; none ("" for every field, missing set) when the files do not declare it
  std::map<std::string, std::string> fdat(const std::string& name, std::string& missing) const {
    Decl d;
    if (lookup(name, d) && d.type == "FDAT" && !d.value.empty()) return fields_of(d.value);
    missing = "the FDAT " + name + " is not declared: give the backup's $config.dat or --declarations";
    return {};
  }

  FrameRef numbered(const std::string& kind, const std::string& n, const std::string& where_, const std::string& missing = "") const {
    if (!missing.empty()) return {"", "", missing};
    const int k = static_cast<int>(bits(kind + "_NO", n, where_));
    return {k == 0 ? "" : kind + "_DATA[" + std::to_string(k) + "]", "", ""};
  }

  // The frame of `$TOOL = rhs` (kind TOOL) or `$BASE = rhs` (BASE)
  FrameRef frame_of(const std::string& rhs_, const std::string& kind, const std::string& where_) const {
    const std::string rhs = upper_case(trim(rhs_));
    static const std::regex data(R"(\$?(TOOL|BASE)_DATA\s*\[\s*(\d+)\s*\])"), stool(R"(STOOL2?\s*\(\s*(\w+)\s*\))"),
        sbase(R"(SBASE\s*\(\s*(\w+)\s*\.\s*BASE_NO\s*\))"), word(R"(\w+)");
    std::smatch m;
    Decl d;
    std::string missing;
    if (rhs == "$NULLFRAME") return {};
    if (!rhs.empty() && rhs[0] == '{' && rhs.back() == '}') return {trim(rhs_), "", ""};  // a FRAME literal
    if (std::regex_match(rhs, m, data)) return numbered(m[1].str(), m[2].str(), where_);
    if (std::regex_match(rhs, m, stool)) return numbered("TOOL", fdat(m[1].str(), missing)["TOOL_NO"], where_, missing);
    if (std::regex_match(rhs, m, sbase)) return numbered("BASE", fdat(m[1].str(), missing)["BASE_NO"], where_, missing);
    if (std::regex_match(rhs, m, word) && lookup(rhs, d) && d.type == "FRAME" && !d.value.empty() && !d.run_time)
      return {rhs, "", ""};
    return {"", "$" + kind + " = " + trim(rhs_) + " is set at run time", ""};
  }

  void apply_fdat(FrameState& s, const std::string& where_) const {
    if (s.fdat.empty()) return;  // FDAT_ACT as a program before this one left it: the frames stay
    std::string missing;
    auto f = fdat(s.fdat, missing);
    s.tool = numbered("TOOL", f["TOOL_NO"], where_, missing);
    s.base = numbered("BASE", f["BASE_NO"], where_, missing);
    s.ipo = missing.empty() ? upper_case(f["IPO_FRAME"].empty() ? "#BASE" : f["IPO_FRAME"]) : "!" + missing;
  }

  void assign(FrameState& s, const std::string& lhs, const std::string& rhs, const std::string& where_) const {
    static const std::regex sipo(R"(SIPO_MODE\s*\(\s*(\w+)\s*\.\s*IPO_FRAME\s*\))", std::regex::icase);
    std::smatch m;
    const std::string l = upper_case(lhs), r = trim(rhs);
    if (l == "$TOOL") s.tool = frame_of(rhs, "TOOL", where_);
    if (l == "$BASE") s.base = frame_of(rhs, "BASE", where_);
    if (l == "FDAT_ACT") s.fdat = upper_case(trim(rhs));
    std::string missing;
    if (l == "$IPO_MODE" && std::regex_match(r, m, sipo)) {
      const std::string ipo = upper_case(fdat(m[1].str(), missing)["IPO_FRAME"]);
      s.ipo = !missing.empty() ? "!" + missing : ipo.empty() ? "#BASE" : ipo;
    } else if (l == "$IPO_MODE") {
      s.ipo = upper_case(r);
    }
  }

  // The assignments of a WITH list (each item up to an approximation C_SPL, C_DIS, ...)
  void apply_with(FrameState& s, const std::string& list, const std::string& where_) const {
    static const std::regex item_re(R"(^(\$?\w+)(?:\s*\[[^\]]*\])?\s*=\s*(.*)$)");
    for (std::string item : split_top(list)) {
      std::smatch m;
      if (std::regex_search(item, m, kApprox)) item = item.substr(0, static_cast<size_t>(m.position(0)));
      if (std::regex_match(item, m, item_re)) assign(s, m[1].str(), m[2].str(), where_);
    }
  }

  struct Frames {
    std::string key, named, why;
    Eigen::Isometry3d tool = Eigen::Isometry3d::Identity(), base = Eigen::Isometry3d::Identity();
  };

  Eigen::Isometry3d frame_value(const std::string& key, const char* what, const std::string& where_) const {
    if (key.empty()) return Eigen::Isometry3d::Identity();
    if (!key.empty() && key[0] == '{') {  // $TOOL = {X .., ..} or {FRAME: X .., ..}: the literal
      std::string text = key;
      static const std::regex typed(R"(^\{\s*FRAME\s*:\s*)", std::regex::icase);
      text = std::regex_replace(text, typed, "{");
      const Aggregate a = read_aggregate(text, where_);
      if (!a.missing.empty()) throw InputError(where_ + ": the motion's " + what + " " + key + " has no " + a.missing + " value");
      return pose_to_iso(a.pose);
    }
    Decl d;
    if (!lookup(key, d) || d.value.empty())
      throw InputError(where_ + ": the motion's " + what + " " + key + " is not declared: give the backup's $config.dat or --declarations");
    const Aggregate a = read_aggregate(d.value, where(d.path, d.line));
    if (!a.missing.empty()) throw InputError(where(d.path, d.line) + ": " + key + " has no " + a.missing + " value");
    return pose_to_iso(a.pose);
  }

  Frames frames_at(const FrameState& s, const std::string& where_) const {
    Frames fr;
    for (const std::string& e : {s.tool.error, s.base.error, s.ipo[0] == '!' ? s.ipo.substr(1) : std::string()})
      if (!e.empty()) throw InputError(where_ + ": " + e);
    if (!s.tool.why.empty() || !s.base.why.empty()) {
      fr.why = "its " + std::string(s.tool.why.empty() ? "base" : "tool") + " is not known before run time (" +
               (s.tool.why.empty() ? s.base.why : s.tool.why) + ")";
      return fr;
    }
    if (s.ipo == "#TCP") throw InputError(where_ + ": a stationary tool (IPO_FRAME #TCP): kincal does not compensate it");
    if (s.ipo != "#BASE") return fr.why = "its interpolation mode $IPO_MODE = " + s.ipo + " is set at run time", fr;
    fr.tool = frame_value(s.tool.key, "tool", where_);
    fr.base = frame_value(s.base.key, "base", where_);
    fr.named = s.tool.key + (s.tool.key.empty() || s.base.key.empty() ? "" : ", ") + s.base.key;
    fr.key = s.tool.key + "|" + s.base.key;
    return fr;
  }

  // a target whose value stands in file f, line, [begin, end), read as aggregate a
  static NativeTarget target_at(int f, int line, size_t begin, size_t end, const Aggregate& a) {
    NativeTarget t;
    t.file = f;
    t.line = line;
    t.begin = begin;
    t.end = end;
    t.pose = a.pose;
    t.taught = a.taught;
    t.external = a.external;
    return t;
  }

  static void in_frames(NativeTarget& t, const Frames& fr) {
    t.tool = fr.tool;
    t.frame = fr.base;
    t.frames_named = fr.named;
  }

  void unresolved(const std::string& where_, const std::string& code, const std::string& why) {
    p.unresolved.push_back({where_, trim(code), why});
  }

  // The target `text` at [b, ..) of a motion statement (p.motions.back()) in file f, line i
  void resolve(int f, size_t i, const std::string& code, size_t b, const std::string& text, const FrameState& s) {
    const std::string w = at(f, i);
    NativeMotion& mo = p.motions.back();
    const bool joint = mo.kind == 'J';
    if (top_colon(text)) return unresolved(w, code, "a geometric operator (" + text + "): computed at run time");
    if (text[0] == '{') {
      if (text.back() != '}') throw InputError(w + ": the aggregate " + text + " is not closed by }");
      const Aggregate a = read_aggregate(text, w);
      if (a.joints) return;  // axis values: joints, as written
      if (!a.missing.empty())
        return unresolved(w, code, "an aggregate without " + a.missing + ": the rest is where the robot is at run time");
      const Frames fr = frames_at(s, w);
      if (!fr.why.empty()) return unresolved(w, code, fr.why);
      NativeTarget t = target_at(f, static_cast<int>(i + 1), b, b + text.size(), a);
      in_frames(t, fr);
      t.joint_motion = joint;
      mo.target = static_cast<int>(p.targets.size());
      return p.targets.push_back(t);
    }
    if (text[0] == '$') return unresolved(w, code, "a system variable (" + text + "): where the robot is at run time");
    static const std::regex word(R"(\w+)");
    if (!std::regex_match(text, word)) return unresolved(w, code, "an expression (" + text + "): computed at run time");
    Decl d;
    if (!lookup(text, d)) return unresolved(w, code, "declared nowhere");
    if (is_axis(d.type)) return;  // joints, as written
    if (!is_pos(d.type)) throw InputError(w + ": target '" + text + "' is declared as " + d.type + ", not a position");
    if (d.run_time || assigned_[static_cast<size_t>(prog_)].count(upper_case(text)))
      return unresolved(w, code, "assigned in the program: computed at run time");
    if (d.value.empty()) return unresolved(w, code, "declared without a value: set at run time");
    const Frames fr = frames_at(s, w);
    if (!fr.why.empty()) return unresolved(w, code, fr.why);
    if (d.file < 0) {  // declared in the backup's other files: compensated there
      const int cf = add(d.path);
      if (!locate(cf, d.line, d) || upper_case(d.name) != upper_case(text))
        throw InputError(where(d.path, d.line) + ": the declaration of " + text + " is not one line");
      located_[upper_case(text)] = d;
    }
    const std::string key = std::to_string(d.file) + ":" + upper_case(d.name);
    auto& by_frame = uses_[key];
    if (auto it = by_frame.find(fr.key); it != by_frame.end()) {
      NativeTarget& t = p.targets[static_cast<size_t>(it->second)];
      t.joint_motion = t.joint_motion && joint;
      if (t.copy_of >= 0) t.edits.push_back({f, static_cast<int>(i + 1), b, b + text.size(), t.name});
      mo.target = it->second;
      return;
    }
    NativeTarget t;
    if (by_frame.empty()) {
      const std::string dw = where(d.path, d.line);
      const Aggregate a = read_aggregate(d.value, dw);
      if (!a.missing.empty()) throw InputError(dw + ": the target has no " + a.missing + " value");
      t = target_at(d.file, d.line, d.begin, d.end, a);
      t.name = d.name;
      t.joint_edits.push_back({d.file, d.line, d.type_begin, d.type_end, d.type == "E6POS" ? "E6AXIS" : "AXIS"});
      first_[key] = static_cast<int>(p.targets.size());
    } else {  // a second frame: a copy, declared after the original, that these motions name
      t = p.targets[static_cast<size_t>(first_[key])];
      t.copy_of = first_[key];
      t.name = copy_name(d.name);
      t.edits = {{f, static_cast<int>(i + 1), b, b + text.size(), t.name}};
    }
    in_frames(t, fr);
    t.joint_motion = joint;
    mo.target = static_cast<int>(p.targets.size());
    by_frame[fr.key] = mo.target;
    p.targets.push_back(t);
  }
  std::map<std::string, int> first_;  // declared target -> its original

  // NAME_1, NAME_2, ...: cut to KRL's 24 characters, unique among the declared names
  std::string copy_name(const std::string& name) {
    for (int n = 1;; ++n) {
      const std::string suffix = "_" + std::to_string(n);
      const std::string c = name.substr(0, std::min(name.size(), 24 - suffix.size())) + suffix;
      if (taken_.insert(upper_case(c)).second) return c;
    }
  }

  // The motions of the .src f, in order, with their tool and base.
  void motions(int f) {
    static const std::regex block_re(R"(^\s*(SPLINE|PTP_SPLINE)\b\s*(.*)$)", std::regex::icase),
        end_re(R"(^\s*ENDSPLINE\b.*$)", std::regex::icase),
        motion_re(R"(^\s*(PTP|LIN|CIRC|SPTP|SLIN|SCIRC|SPL|PTP_REL|LIN_REL|CIRC_REL|SPTP_REL|SLIN_REL|SCIRC_REL|SPL_REL)\b\s*(.*)$)",
                  std::regex::icase),
        bas_re(R"(^\s*BAS\s*\(\s*#(\w+)\s*(?:,\s*(.*?))?\s*\)\s*$)", std::regex::icase);
    FrameState s, block;  // the program's frames (tool 0, base 0 at its start); a spline block's
    std::string open;      // the spline block open, "" when none
    int open_line = 0;
    for (size_t i = 0; i < p.lines[static_cast<size_t>(f)].size(); ++i) {  // (a target's file may join p.lines)
      const std::string code = code_of(p.lines[static_cast<size_t>(f)][i]), w = at(f, i);
      std::smatch m;
      if (std::regex_match(code, m, block_re)) {
        if (!open.empty()) throw InputError(w + ": " + upper_case(m[1].str()) + " inside the " + open + " block of line " + std::to_string(open_line));
        open = upper_case(m[1].str());
        open_line = static_cast<int>(i + 1);
        block = s;
        const size_t with = with_at(code, static_cast<size_t>(m.position(2)));
        if (with != std::string::npos) apply_with(block, code.substr(with + 4), w);
      } else if (std::regex_match(code, end_re)) {
        if (open.empty()) throw InputError(w + ": ENDSPLINE without SPLINE");
        open.clear();
      } else if (std::regex_match(code, m, motion_re)) {
        motion(f, i, code, m, open.empty() ? s : block, open);
      } else if (std::regex_match(code, m, bas_re)) {
        const std::string what = upper_case(m[1].str());
        if (what == "PTP_PARAMS" || what == "CP_PARAMS" || what == "FRAMES") apply_fdat(s, w);
        if (what == "TOOL" || what == "BASE") s.*(what == "TOOL" ? &FrameState::tool : &FrameState::base) = numbered(what, trim(m[2].str()), w);
      } else if (std::regex_match(code, m, kAssign)) {
        assign(s, m[1].str(), m[3].str(), w);
      }
    }
    if (!open.empty()) throw InputError(where(p.paths[static_cast<size_t>(f)], open_line) + ": " + open + " is not closed by ENDSPLINE");
  }

  void motion(int f, size_t i, const std::string& code, const std::smatch& m, const FrameState& outer, const std::string& block) {
    const std::string w = at(f, i), kw = upper_case(m[1].str());
    const std::string base_kw = kw.substr(0, kw.find("_REL"));
    const bool ok = block.empty()      ? base_kw != "SPL"
                    : block == "SPLINE" ? base_kw == "SPL" || base_kw == "SLIN" || base_kw == "SCIRC"
                                        : base_kw == "SPTP";
    if (!ok)
      throw InputError(w + ": " + kw + (block.empty() ? std::string(" outside a SPLINE ... ENDSPLINE block")
                                                      : " inside a " + block + " block (" + (block == "SPLINE" ? "SPL, SLIN, SCIRC" : "SPTP") + " only)"));
    FrameState s = outer;
    size_t end = code.size();
    const size_t with = with_at(code, static_cast<size_t>(m.position(2)));
    if (with != std::string::npos) {
      if (kw.find("_REL") == std::string::npos) apply_with(s, code.substr(with + 4), w);
      end = with;
    }
    const auto args = top_args(code, static_cast<size_t>(m.position(2)), end);
    const size_t n = base_kw.find("CIRC") != std::string::npos ? 2 : 1;
    if (args.size() < n || args[n - 1].first == args[n - 1].second)
      throw InputError(w + ": " + kw + " needs " + (n == 2 ? "an auxiliary point and an end point" : "a target"));
    for (size_t a = n; a < args.size(); ++a)
      if (n == 1 || upper_case(code.substr(args[a].first, 2)) != "CA")
        throw InputError(w + ": '" + code.substr(args[a].first, args[a].second - args[a].first) + "' after the target of " + kw);
    const char kind = base_kw == "PTP" || base_kw == "SPTP" ? 'J' : n == 2 ? 'C' : base_kw == "SPL" ? 'O' : 'L';
    for (size_t a = 0; a < n; ++a) {
      auto [b, e] = args[a];
      std::string text = code.substr(b, e - b);
      if (text.empty()) throw InputError(w + ": " + kw + " needs a target");
      std::smatch ap;
      const size_t brace = text[0] == '{' ? text.find('}') : 0;
      if (std::regex_search(text.cbegin() + static_cast<long>(brace == std::string::npos ? 0 : brace), text.cend(), ap, kApprox))
        text = trim(text.substr(0, static_cast<size_t>(ap.position(0)) + (brace == std::string::npos ? 0 : brace)));
      p.motions.push_back(motion_around(code, static_cast<int>(i + 1), kind, b, text.size()));
      p.motions.back().file = f;
      if (kw.find("_REL") != std::string::npos) {
        if (a == 0) unresolved(w, code, "a relative motion (" + kw + "): its target depends on where the robot is");
        continue;
      }
      resolve(f, i, code, b, text, s);
    }
  }
};

}  // namespace

NativeProgram read_krl_program(const std::vector<std::string>& src_paths, const Declarations& context) {
  KrlReader r(context);
  for (const std::string& src : src_paths) r.read_program(src);
  keep_named_targets_cartesian(r.p, ';', true);
  return std::move(r.p);
}

}  // namespace kincal
