// kincal: FANUC LS programs read in: /PROG ... /MN ... /POS ... /END checked; the motions J, L, C (its
// second point on the continuation line ": P[m] ...") and A to P[n]; the /POS entries P[n]{ GP1: UF, UT,
// CONFIG, X Y Z W P R } (Cartesian: compensated) or J1..J6 (joints: kept). A motion to a position
// register PR[i], an indirect P[R[i]], or with Offset / Tool_Offset / INC / VOFFSET is unresolved (known
// at run time only). FANUC's W, P, R are KUKA's C, B, A. Each target keeps its position's user frame (UF)
// and tool (UT) numbers: compensate_native applies --uframe / --utool, or --program-base / --program-tool.
#include "controller_writers.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include <cmath>
#include <cstdio>
#include <iterator>
#include <cstdlib>
#include <map>
#include <regex>

namespace kincal {

namespace {

struct LsPos {
  int first = 0, last = 0;  // GP1's lines (1-based)
  bool cartesian = false;
  Pose6 pose;
  int uf = 0, ut = 0;
};

double number(const std::string& tok, const std::string& at, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(tok.c_str(), &end);
  if (tok.empty() || end == tok.c_str() || *end != '\0' || !std::isfinite(v))
    throw InputError(at + ": " + what + " '" + tok + "' is not a number");
  return v;
}

// one /POS entry's group 1, lines [first, last] of the file
LsPos parse_position(const std::vector<std::string>& lines, int first, int last, const std::string& path, int n) {
  LsPos p;
  p.first = first, p.last = last;
  static const std::regex field(R"(\b(UF|UT|X|Y|Z|W|P|R|J[1-6])\s*[:=]\s*([^\s,']+))");
  static const std::regex config(R"(\bCONFIG\s*:\s*'([^']*)')");
  double v[6];
  bool seen[6] = {false, false, false, false, false, false};
  int joints = 0;
  bool has_config = false;
  for (int l = first; l <= last; ++l) {
    const std::string& s = lines[static_cast<size_t>(l - 1)];
    const std::string at = where(path, l);
    if (std::regex_search(s, config)) has_config = true;
    for (auto it = std::sregex_iterator(s.begin(), s.end(), field); it != std::sregex_iterator(); ++it) {
      const std::string key = (*it)[1].str(), tok = (*it)[2].str();
      const std::string what = "P[" + std::to_string(n) + "] " + key;
      if (key == "UF") p.uf = static_cast<int>(number(tok, at, what));
      else if (key == "UT") p.ut = static_cast<int>(number(tok, at, what));
      else if (key[0] == 'J') number(tok, at, what), ++joints;
      else {
        const int f = static_cast<int>(std::string("XYZWPR").find(key[0]));
        v[f] = number(tok, at, what);
        seen[f] = true;
      }
    }
  }
  const std::string at = where(path, first);
  if (joints == 6 && !has_config) return p;  // a joint position: kept as it is
  if (!has_config) throw InputError(at + ": P[" + std::to_string(n) + "] has neither CONFIG with X..R nor J1..J6");
  for (int f = 0; f < 6; ++f)
    if (!seen[f]) throw InputError(at + ": P[" + std::to_string(n) + "] has no " + std::string(1, "XYZWPR"[f]) + " value");
  p.cartesian = true;
  p.pose.xyz = Vec3(v[0], v[1], v[2]);
  p.pose.abc = Vec3(v[5], v[4], v[3]);  // A = R, B = P, C = W
  return p;
}

}  // namespace

NativeProgram read_ls_program(const std::string& path) {
  NativeProgram p;
  p.format = ControllerFormat::FanucLs;
  add_program_file(p, path);
  const auto& lines = p.lines[0];
  enum Section { None, Head, Mn, Pos, End } sec = None;
  int prog_line = 0, open_pos = 0, open_n = 0, gp_first = 0, gp_last = 0;
  std::map<int, LsPos> pos;
  struct Use {
    int n, line;
    bool joint;  // a J motion
  };
  std::vector<Use> uses;
  std::vector<std::string> mn;  // the /MN statements but comments
  std::vector<int> motion_pos;  // per motion, its position's number (-1: a run-time target)
  static const std::regex comment(R"(^\s*\d+:\s*!)");
  static const std::regex motion(R"(^\s*\d+:\s*([JLCA])\s+(.*)$)"), cont(R"(^\s*:\s*(.*)$)");
  static const std::regex ref(R"(^(P|PR)\[\s*(R\[)?\s*(\d+))");
  static const std::regex runtime(R"((Offset|VOFFSET|\bINC\b))", std::regex::icase);
  static const std::regex pos_open(R"(^\s*P\[\s*(\d+)\s*(:[^\]]*)?\]\s*\{\s*$)"), pos_close(R"(^\s*\};\s*$)");
  bool want_circ_end = false;
  for (size_t i = 0; i < lines.size(); ++i) {
    std::string s = lines[i];
    if (!s.empty() && s.back() == '\r') s.pop_back();  // a CRLF file
    const int ln = static_cast<int>(i + 1);
    const std::string at = where(path, ln);
    std::smatch m;
    const size_t a = s.find_first_not_of(" \t\r");
    if (a == std::string::npos) continue;
    if (s[a] == '/') {
      const std::string kw = s.substr(a, s.find_first_of(" \t\r", a) - a);
      if (kw == "/PROG") {
        if (sec != None) throw InputError(at + ": a second /PROG");
        sec = Head, prog_line = ln;
      } else if (sec == None) {
        throw InputError(at + ": an LS program starts with /PROG");
      } else if (kw == "/ATTR" || kw == "/APPL") {
      } else if (kw == "/MN") {
        sec = Mn;
      } else if (kw == "/POS") {
        if (open_pos) throw InputError(where(path, open_pos) + ": P[" + std::to_string(open_n) + "] is not closed by '};'");
        sec = Pos;
      } else if (kw == "/END") {
        if (open_pos) throw InputError(where(path, open_pos) + ": P[" + std::to_string(open_n) + "] is not closed by '};'");
        sec = End;
      } else if (sec != Pos) {
        throw InputError(at + ": unknown section " + kw);
      }
      continue;
    }
    if (sec == None) throw InputError(at + ": an LS program starts with /PROG");
    if (sec == End) throw InputError(at + ": text after /END");
    if (sec == Mn) {
      if (!std::regex_search(s, comment)) mn.push_back(s);
      std::string rest;
      const bool is_cont = want_circ_end && std::regex_match(s, m, cont);
      char kind = 'C';
      size_t rest_at = 0;
      if (is_cont) rest = m[1].str(), rest_at = static_cast<size_t>(m.position(1));
      else if (std::regex_match(s, m, motion))
        rest = m[2].str(), rest_at = static_cast<size_t>(m.position(2)), kind = m[1].str()[0], want_circ_end = kind == 'C';
      else continue;
      if (is_cont) want_circ_end = false;
      const bool ends = rest.find(';') != std::string::npos;
      if (!ends && !want_circ_end) throw InputError(at + ": the motion does not end with ';'");
      std::smatch r;
      if (!std::regex_search(rest, r, ref)) throw InputError(at + ": the motion names no P[n] or PR[n] position");
      const size_t ref_at = rest_at + static_cast<size_t>(r.position(0));
      p.motions.push_back(motion_around(s, ln, kind == 'A' ? 'O' : kind, ref_at, s.find(']', ref_at) + 1 - ref_at));
      motion_pos.push_back(-1);
      if (r[1].str() == "PR" || r[2].matched || std::regex_search(rest, runtime)) {
        p.unresolved.push_back({at, s.substr(a)});
        continue;
      }
      uses.push_back({std::stoi(r[3].str()), ln, kind == 'J'});
      motion_pos.back() = uses.back().n;
    } else if (sec == Pos) {
      if (!open_pos) {
        if (!std::regex_match(s, m, pos_open)) throw InputError(at + ": expected P[n]{ in /POS");
        open_pos = ln, open_n = std::stoi(m[1].str()), gp_first = gp_last = 0;
        if (pos.count(open_n)) throw InputError(at + ": P[" + std::to_string(open_n) + "] is declared twice");
      } else if (std::regex_match(s, pos_close)) {
        if (!gp_first) throw InputError(where(path, open_pos) + ": P[" + std::to_string(open_n) + "] has no GP1");
        pos[open_n] = parse_position(lines, gp_first, gp_last ? gp_last : ln - 1, path, open_n);
        open_pos = 0;
      } else if (s.find("GP1:") != std::string::npos) {
        gp_first = ln + 1;
      } else if (std::regex_search(s, std::regex(R"(^\s*GP\d+:)"))) {
        if (gp_first && !gp_last) gp_last = ln - 1;  // another group (extended axes): kept
      }
    }
  }
  if (!prog_line) throw InputError(path + ": no /PROG in the file");
  if (sec != End) throw InputError(where(path, prog_line) + ": /PROG is not closed by /END (end of file)");
  std::map<int, bool> done;
  std::map<int, int> motions, joint_motions;  // per position, the motions to it and how many are J
  for (const Use& u : uses) ++motions[u.n], joint_motions[u.n] += u.joint;
  for (const Use& u : uses) {
    const auto it = pos.find(u.n);
    if (it == pos.end())
      throw InputError(where(path, u.line) + ": P[" + std::to_string(u.n) + "] is used but not declared in /POS");
    const LsPos& lp = it->second;
    if (!lp.cartesian || done[u.n]) continue;
    done[u.n] = true;
    NativeTarget t;
    t.uframe = lp.uf, t.utool = lp.ut;
    t.line = lp.first;
    t.last_line = lp.last;
    t.begin = 0;
    t.end = lines[static_cast<size_t>(lp.last - 1)].size();
    if (t.end > 0 && lines[static_cast<size_t>(lp.last - 1)].back() == '\r') --t.end;  // the '\r' stays
    t.pose = lp.pose;
    t.name = "P[" + std::to_string(u.n) + "]";
    for (size_t k = 0; k < p.motions.size(); ++k)
      if (motion_pos[k] == u.n) p.motions[k].target = static_cast<int>(p.targets.size());
    // every motion to it a J, and no other statement names it (a P[n] or P[n:comment])
    const std::regex named(R"(\bP\[\s*)" + std::to_string(u.n) + R"(\s*[:\]])");
    int mentions = 0;
    for (const std::string& l : mn)
      mentions += static_cast<int>(std::distance(std::sregex_iterator(l.begin(), l.end(), named), std::sregex_iterator()));
    t.joint_motion = joint_motions[u.n] == motions[u.n] && mentions == motions[u.n];
    p.targets.push_back(t);
  }
  return p;
}

// GP1's lines with CONFIG and X..R replaced (a shorter number right-aligned in the old one's width), every other
// character kept
std::string ls_position(const std::string& old, const Pose6& pose, const ControllerTarget& t) {
  std::string s = std::regex_replace(old, std::regex(R"((\bCONFIG\s*:\s*')[^']*('))"), "$1" + t.fanuc_config + "$2");
  const double v[6] = {pose.xyz[0], pose.xyz[1], pose.xyz[2], pose.abc[2], pose.abc[1], pose.abc[0]};
  for (int f = 0; f < 6; ++f) {
    std::smatch m;
    const std::regex re(std::string(R"(\b)") + "XYZWPR"[f] + R"(\s*=\s*([^\s,']+))");
    if (!std::regex_search(s, m, re)) continue;
    std::string num = ctl::fixed(v[f], 4);
    const size_t b = static_cast<size_t>(m.position(1)), len = static_cast<size_t>(m.length(1));
    if (num.size() < len) num.insert(0, len - num.size(), ' ');  // keeps the columns
    s.replace(b, len, num);
  }
  return s;
}

// GP1's lines of a Cartesian position in joint form: CONFIG dropped, X Y Z W P R (with their units)
// replaced by J1..J6 in deg, the line count and every other field (UF, UT, extended axes) kept
std::string ls_joint_position(const std::string& old, const Vec6& q_deg) {
  std::string s = std::regex_replace(old, std::regex(R"(\bCONFIG\s*:\s*'[^']*'\s*,?)"), "");
  for (int f = 0; f < 6; ++f) {
    const std::regex re(std::string(R"(\b)") + "XYZWPR"[f] + R"(\s*=\s*[^\s,']+(\s*(mm|deg)\b)?)");
    char buf[64];
    std::snprintf(buf, sizeof buf, "J%d=%11s deg", f + 1, ctl::fixed(q_deg[f], ctl::kLsDecimals).c_str());
    s = std::regex_replace(s, re, buf, std::regex_constants::format_first_only);
  }
  return s;
}

// The program with its /MN lines numbered 1, 2, ... again (each number in its old width) and LINE_COUNT
// set to their count: after --tolerance inserted motions.
std::string ls_renumbered(const std::string& text) {
  static const std::regex numbered(R"(^(\s*)(\d+):)");
  std::string out;
  bool mn = false;
  int n = 0;
  size_t b = 0;
  while (b < text.size()) {
    size_t e = text.find('\n', b);
    e = e == std::string::npos ? text.size() : e + 1;
    std::string l = text.substr(b, e - b);
    b = e;
    if (!l.empty() && l[0] == '/') mn = l.compare(0, 3, "/MN") == 0;
    std::smatch m;
    if (mn && std::regex_search(l, m, numbered)) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%*d", static_cast<int>(m.length(1) + m.length(2)), ++n);
      l.replace(0, static_cast<size_t>(m.length(1) + m.length(2)), buf);
    }
    out += l;
  }
  std::smatch m;
  if (std::regex_search(out, m, std::regex(R"(\bLINE_COUNT\s*=\s*(\d+))")))
    out.replace(static_cast<size_t>(m.position(1)), static_cast<size_t>(m.length(1)), std::to_string(n));
  return out;
}

}  // namespace kincal
