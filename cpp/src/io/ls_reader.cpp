// kincal: FANUC LS programs read in. /PROG ... /ATTR ... /APPL ... /MN ... /POS ... /END checked; /MN statements
// numbered "  12:" (or written " : " without numbers), a statement running over continuation lines "    :  ..."
// until its ';'; comments '!' and commented-out statements '//' are not read. The motions of the manual: J, L,
// C (its end point on the continuation line ": P[m] ..."), A (circular arcs through consecutive A points), with
// their options (CNT/FINE/CD, ACC, Wjnt, TB/TA/DB, PTH, Skip,LBL[], arc welding, ...) to P[n]. A motion to a
// position register PR[i], an indirect P[R[i]], or with Offset / Tool_Offset / INC / VOFFSET is unresolved with
// why (known at run time only); COORD (coordinated with a positioner) and RTCP (remote TCP) are refused by name.
// /POS entries P[n]{ GP1: UF, UT, CONFIG, X Y Z W P R, E1..E3 } (Cartesian: compensated, CONFIG kept as the
// taught branch, E1..E3 as the external axes) or J1..J6 (joints: kept); other groups (GP2: a positioner) are
// kept as written, and a position of another group only is not the robot's. A position not taught (********)
// is unresolved at its motions. FANUC's W, P, R are KUKA's C, B, A. Each target keeps its position's user frame
// (UF) and tool (UT) numbers: compensate_native applies --uframe / --utool, or --program-base / --program-tool.
#include "controller_writers.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <map>
#include <regex>

namespace kincal {

namespace {

struct LsPos {
  int first = 0, last = 0;  // GP1's lines (1-based); 0: the position has no GP1
  bool cartesian = false, untaught = false;
  Pose6 pose;
  int uf = 0, ut = 0;
  std::string config;                                       // normalised, "N U T, 0, 0, 0"
  std::array<double, 6> external{{NAN, NAN, NAN, NAN, NAN, NAN}};  // E1..E3
};

double number(const std::string& tok, const std::string& at, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(tok.c_str(), &end);
  if (tok.empty() || end == tok.c_str() || *end != '\0' || !std::isfinite(v))
    throw InputError(at + ": " + what + " '" + tok + "' is not a number");
  return v;
}

// CONFIG 'F U T, 0, 0, 0' as set_branch_data writes it: "F U T, t1, t4, t6" (the letters and the turn numbers
// of J1, J4, J6); InputError for another form (a 4- or 5-axis robot's)
std::string normalised_config(const std::string& c, const std::string& at, int n) {
  static const std::regex form(R"(^\s*([FN])\s*,?\s*([UD])\s*,?\s*([TB])\s*,\s*([+-]?\d+)\s*,\s*([+-]?\d+)\s*,\s*([+-]?\d+)\s*$)");
  std::smatch m;
  if (!std::regex_match(c, m, form))
    throw InputError(at + ": P[" + std::to_string(n) + "] CONFIG '" + c +
                     "' is not a six-axis arm's configuration 'F|N U|D T|B, t1, t4, t6'");
  std::string s = m[1].str() + " " + m[2].str() + " " + m[3].str();
  for (int k = 4; k <= 6; ++k) s += ", " + std::to_string(std::stoi(m[k].str()));
  return s;
}

// one /POS entry's group 1, lines [first, last] of the file
LsPos parse_position(const std::vector<std::string>& lines, int first, int last, const std::string& path, int n) {
  LsPos p;
  p.first = first, p.last = last;
  static const std::regex field(R"(\b(UF|UT|X|Y|Z|W|P|R|J[1-6]|E[1-3])\s*[:=]\s*([^\s,']+))");
  static const std::regex config(R"(\bCONFIG\s*:\s*'([^']*)')");
  double v[6] = {0, 0, 0, 0, 0, 0};
  bool seen[6] = {false, false, false, false, false, false};
  int joints = 0;
  bool has_config = false;
  for (int l = first; l <= last; ++l) {
    const std::string& s = lines[static_cast<size_t>(l - 1)];
    const std::string at = where(path, l);
    std::smatch c;
    if (std::regex_search(s, c, config)) {
      has_config = true;
      p.config = normalised_config(c[1].str(), at, n);
    }
    for (auto it = std::sregex_iterator(s.begin(), s.end(), field); it != std::sregex_iterator(); ++it) {
      const std::string key = (*it)[1].str(), tok = (*it)[2].str();
      const std::string what = "P[" + std::to_string(n) + "] " + key;
      // a position recorded but never taught: UF : F, UT : F, X = ********
      if (tok.find('*') != std::string::npos || ((key == "UF" || key == "UT") && tok == "F")) {
        p.untaught = true;
        continue;
      }
      if (key == "UF") p.uf = static_cast<int>(number(tok, at, what));
      else if (key == "UT") p.ut = static_cast<int>(number(tok, at, what));
      else if (key[0] == 'J') number(tok, at, what), ++joints;
      else if (key[0] == 'E') p.external[static_cast<size_t>(key[1] - '1')] = number(tok, at, what);
      else {
        const int f = static_cast<int>(std::string("XYZWPR").find(key[0]));
        v[f] = number(tok, at, what);
        seen[f] = true;
      }
    }
  }
  const std::string at = where(path, first);
  if (p.untaught) return p;
  if (joints == 6 && !has_config) return p;  // a joint position: kept as it is
  if (!has_config) throw InputError(at + ": P[" + std::to_string(n) + "] has neither CONFIG with X..R nor J1..J6");
  for (int f = 0; f < 6; ++f)
    if (!seen[f]) throw InputError(at + ": P[" + std::to_string(n) + "] has no " + std::string(1, "XYZWPR"[f]) + " value");
  p.cartesian = true;
  p.pose.xyz = Vec3(v[0], v[1], v[2]);
  p.pose.abc = Vec3(v[5], v[4], v[3]);  // A = R, B = P, C = W
  return p;
}

// the text with every register's comment dropped ("PR[6:offset]" -> "PR[6]"), so that options are
// read from the instruction's own words
std::string without_register_comments(std::string s) {
  static const std::regex comment(R"(\[([^\[\]:]*):[^\[\]]*\])");
  for (std::string prev; prev != s;) prev = s, s = std::regex_replace(s, comment, "[$1]");
  return s;
}

// a position reference at s[at..]: P[n], P[n:comment], PR[i], P[R[i]], ...; its end (after the matching ']')
struct Ref {
  bool ok = false, is_p = false;  // is_p: P[n] with n a number
  int n = 0;
  size_t begin = 0, end = 0;
  std::string text;  // as written, register comments dropped
};
Ref position_ref(const std::string& s, size_t at) {
  Ref r;
  at = s.find_first_not_of(" \t", at);
  if (at == std::string::npos) return r;
  size_t open = std::string::npos;
  if (s.compare(at, 2, "P[") == 0) open = at + 1;
  else if (s.compare(at, 3, "PR[") == 0) open = at + 2;
  else return r;
  int depth = 0;
  for (size_t i = open; i < s.size(); ++i) {
    if (s[i] == '[') ++depth;
    if (s[i] == ']' && --depth == 0) {
      r.ok = true, r.begin = at, r.end = i + 1;
      r.text = without_register_comments(s.substr(at, i + 1 - at));
      std::smatch m;
      static const std::regex p_n(R"(^P\[\s*(\d+)\s*\]$)");
      if (std::regex_match(r.text, m, p_n)) r.is_p = true, r.n = std::stoi(m[1].str());
      return r;
    }
  }
  return r;
}

// why a motion's target is known at run time only ("" when it is not): its options (register comments dropped)
std::string run_time_option(const std::string& options) {
  static const std::regex offset(R"(\b(Tool_Offset|Offset|VOFFSET)\b(\s*,\s*(PR|VR)\[[^\]]*\])?)", std::regex::icase);
  static const std::regex inc(R"(\bINC\b)");
  std::smatch m;
  if (std::regex_search(options, m, offset)) {
    std::string name = m[1].str() + (m[2].matched ? "," + m[3].str() + m[2].str().substr(m[2].str().find('[')) : "");
    const std::string w = upper_case(m[1].str());
    if (w == "VOFFSET") return name + ": a vision offset measured at run time";
    if (!m[2].matched)
      return name + ": the target is shifted by the register of " + (w == "OFFSET" ? "OFFSET" : "TOOL_OFFSET") +
             " CONDITION at run time";
    return name + ": the target depends on a register at run time";
  }
  if (std::regex_search(options, inc)) return "INC: an incremental motion (its position is added to where the robot is)";
  return "";
}

struct LsUse {  // a motion to a P[n]
  int n, line;
  bool joint;        // a J motion
  std::string text;  // the statement
};

struct LsStatement {  // a /MN statement: its lines (the first numbered, the others continuation lines ": ...")
  std::vector<int> lines;  // 0-based
  bool done = false;
};

struct LsSections {  // what the /MN and /POS sections hold
  std::vector<LsStatement> statements;
  std::map<int, LsPos> pos;
};

struct LsMotions {  // what the motions name
  std::vector<LsUse> uses;
  std::vector<int> motion_pos;        // per motion, its position's number (-1: none)
  std::vector<std::string> named_in;  // the statements (their code), for P[n] named elsewhere
};

/// The file's sections: /PROG ... /END with /MN's statements and /POS's positions (file:line errors).
LsSections read_ls_sections(const std::vector<std::string>& lines, const std::string& path) {
  LsSections out;
  auto& statements = out.statements;
  auto& pos = out.pos;
  enum Section { None, Head, Mn, Pos, End } sec = None;
  int prog_line = 0, open_pos = 0, open_n = 0, gp_first = 0, gp_last = 0;
  bool other_group = false;  // the open position has a group other than GP1
  static const std::regex numbered(R"(^\s*(\d+)\s*:)"), unnumbered(R"(^\s*:)");
  static const std::regex pos_open(R"(^\s*P\[\s*(\d+)\s*(:[^\]]*)?\]\s*\{\s*$)"), pos_close(R"(^\s*\};\s*$)");
  static const std::regex group(R"(^\s*GP(\d+)\s*:)");
  for (size_t i = 0; i < lines.size(); ++i) {
    std::string s = lines[i];
    if (!s.empty() && s.back() == '\r') s.pop_back();  // a CRLF file
    const int ln = static_cast<int>(i + 1);
    const std::string at = where(path, ln);
    std::smatch m;
    const size_t a = s.find_first_not_of(" \t\r");
    if (a == std::string::npos) continue;
    if (s[a] == '/' && (sec != Mn || s.compare(a, 2, "//") != 0)) {
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
      const bool open = !statements.empty() && !statements.back().done;
      if (std::regex_search(s, m, numbered)) {
        statements.push_back({{static_cast<int>(i)}, false});
      } else if (std::regex_search(s, m, unnumbered)) {
        if (open) statements.back().lines.push_back(static_cast<int>(i));
        else statements.push_back({{static_cast<int>(i)}, false});
      } else {
        continue;  // not a statement line (kept as written)
      }
      const size_t e = s.find_last_not_of(" \t");
      statements.back().done = s[e] == ';';
    } else if (sec == Pos) {
      if (!open_pos) {
        if (!std::regex_match(s, m, pos_open)) throw InputError(at + ": expected P[n]{ in /POS");
        open_pos = ln, open_n = std::stoi(m[1].str()), gp_first = gp_last = 0, other_group = false;
        if (pos.count(open_n)) throw InputError(at + ": P[" + std::to_string(open_n) + "] is declared twice");
      } else if (std::regex_match(s, pos_close)) {
        if (gp_first) {
          pos[open_n] = parse_position(lines, gp_first, gp_last ? gp_last : ln - 1, path, open_n);
        } else if (other_group) {
          pos[open_n] = LsPos();  // another group's position only (a positioner's): not the robot's
        } else {
          throw InputError(where(path, open_pos) + ": P[" + std::to_string(open_n) + "] has no GP1");
        }
        open_pos = 0;
      } else if (std::regex_search(s, m, group)) {
        if (m[1].str() == "1") {
          gp_first = ln + 1;
        } else {
          other_group = true;
          if (gp_first && !gp_last) gp_last = ln - 1;  // another group (a positioner): kept as written
        }
      }
    }
  }
  if (!prog_line) throw InputError(path + ": no /PROG in the file");
  if (sec != End) throw InputError(where(path, prog_line) + ": /PROG is not closed by /END (end of file)");
  return out;
}

/// The motions of the statements, in the order of the file, into p.motions (those whose target is
/// known only at run time into p.unresolved), and the positions they use.
LsMotions read_ls_motions(const LsSections& sc, const std::vector<std::string>& lines, const std::string& path,
                          NativeProgram& p) {
  LsMotions out;
  static const std::regex motion(R"(^\s*\d*\s*:\s*([JLCA])\s)");
  for (const LsStatement& st : sc.statements) {
    std::vector<std::string> code;  // each line of the statement without '\r'
    for (const int l : st.lines) {
      std::string s = lines[static_cast<size_t>(l)];
      if (!s.empty() && s.back() == '\r') s.pop_back();
      code.push_back(s);
    }
    const int ln = st.lines[0] + 1;
    const std::string at = where(path, ln);
    // the statement's words: the first line after its number, the others after their ':'
    std::string body;
    for (const std::string& c : code) body += c.substr(c.find(':') + 1) + " ";
    const size_t b = body.find_first_not_of(" \t");
    if (b == std::string::npos || body[b] == '!' || body.compare(b, 2, "//") == 0) continue;  // a comment
    out.named_in.push_back(without_register_comments(body));
    std::smatch m;
    if (!std::regex_search(code[0], m, motion)) continue;
    if (!st.done) throw InputError(at + ": the motion does not end with ';'");
    const char letter = m[1].str()[0];
    std::string text = body.substr(b);
    text.erase(text.find_last_not_of(" \t") + 1);
    // the points: the first after the letter, a C's end point first on its next line (": P[m] ...")
    struct Point {
      Ref ref;
      int line;  // 0-based index into st.lines
    };
    std::vector<Point> points;
    const Ref first = position_ref(code[0], static_cast<size_t>(m.position(1) + 1));
    if (!first.ok) throw InputError(at + ": the motion names no P[n] or PR[n] position");
    points.push_back({first, 0});
    if (letter == 'C') {
      if (code.size() < 2)
        throw InputError(at + ": C: the arc's end point (': P[m] ...' on the next line) is missing");
      const Ref end = position_ref(code[1], code[1].find(':') + 1);
      if (!end.ok) throw InputError(where(path, st.lines[1] + 1) + ": C: the arc's end point is not a P[m] or PR[m] position");
      points.push_back({end, 1});
    }
    std::string options;
    for (size_t k = 0; k < code.size(); ++k) {
      const Point& last = points.back();
      if (static_cast<int>(k) < last.line) continue;
      options += (static_cast<int>(k) == last.line ? code[k].substr(last.ref.end) : code[k].substr(code[k].find(':') + 1)) + " ";
    }
    options = without_register_comments(options);
    static const std::regex coord(R"(\bCOORD\b)"), rtcp(R"(\bRTCP\b)"), wjnt(R"(\bWjnt\b)", std::regex::icase);
    if (std::regex_search(options, coord))
      throw InputError(at + ": COORD (a motion coordinated with a positioner: the target moves with the positioner's "
                            "axes) is not supported");
    if (std::regex_search(options, rtcp))
      throw InputError(at + ": RTCP (remote TCP: a stationary tool, the robot carrying the part) is not supported");
    // L, C, A with Wjnt keep the path but not the orientation's interpolation: not followed as a line
    const char kind = letter == 'A' ? 'C' : letter == 'L' && std::regex_search(options, wjnt) ? 'O' : letter;
    const std::string run_time = run_time_option(options);
    for (const Point& pt : points) {
      const int pl = st.lines[static_cast<size_t>(pt.line)] + 1;
      // a motion inserted before it (--tolerance) copies the whole statement: its continuation lines too
      std::string whole = lines[static_cast<size_t>(st.lines[static_cast<size_t>(pt.line)])];
      if (pt.line == 0)
        for (size_t k = 1; k < st.lines.size(); ++k) whole += "\n" + lines[static_cast<size_t>(st.lines[k])];
      p.motions.push_back(motion_around(whole, pl, kind, pt.ref.begin, pt.ref.end - pt.ref.begin));
      out.motion_pos.push_back(-1);
      std::string why = run_time;
      if (pt.ref.text.compare(0, 3, "PR[") == 0) why = pt.ref.text + ": a position register, known at run time";
      else if (!pt.ref.is_p) why = pt.ref.text + ": an indirect position, chosen at run time";
      if (!why.empty()) {
        p.unresolved.push_back({where(path, pl), text, why});
        continue;
      }
      out.uses.push_back({pt.ref.n, pl, letter == 'J', text});
      out.motion_pos.back() = pt.ref.n;
    }
  }
  return out;
}

/// The Cartesian positions the motions use, into p.targets (an untaught one's motions unresolved).
void read_ls_targets(const LsSections& sc, const LsMotions& mo, const std::vector<std::string>& lines,
                     const std::string& path, NativeProgram& p) {
  std::map<int, bool> done;
  std::map<int, int> motions, joint_motions;  // per position, the motions to it and how many are J
  for (const LsUse& u : mo.uses) ++motions[u.n], joint_motions[u.n] += u.joint;
  for (const LsUse& u : mo.uses) {
    const auto it = sc.pos.find(u.n);
    if (it == sc.pos.end())
      throw InputError(where(path, u.line) + ": P[" + std::to_string(u.n) + "] is used but not declared in /POS");
    const LsPos& lp = it->second;
    if (lp.untaught) {  // each motion to it unresolved (the controller stops there too)
      p.unresolved.push_back({where(path, u.line), u.text, "P[" + std::to_string(u.n) + "] is not taught (its values are ********)"});
      continue;
    }
    if (!lp.cartesian || done[u.n]) continue;
    done[u.n] = true;
    NativeTarget t;
    t.uframe = lp.uf, t.utool = lp.ut;
    if (lp.uf || lp.ut)
      t.frames_named = lp.uf && lp.ut ? "UF " + std::to_string(lp.uf) + ", UT " + std::to_string(lp.ut)
                       : lp.uf       ? "UF " + std::to_string(lp.uf)
                                     : "UT " + std::to_string(lp.ut);
    t.line = lp.first;
    t.last_line = lp.last;
    t.begin = 0;
    t.end = lines[static_cast<size_t>(lp.last - 1)].size();
    if (t.end > 0 && lines[static_cast<size_t>(lp.last - 1)].back() == '\r') --t.end;  // the '\r' stays
    t.pose = lp.pose;
    t.name = "P[" + std::to_string(u.n) + "]";
    ControllerTarget taught;
    taught.fanuc_config = lp.config;
    t.taught = taught;
    t.external = lp.external;
    for (size_t k = 0; k < p.motions.size(); ++k)
      if (mo.motion_pos[k] == u.n) p.motions[k].target = static_cast<int>(p.targets.size());
    // every motion to it a J, and no other statement names it (a P[n] or P[n:comment])
    const std::regex named(R"(\bP\[\s*)" + std::to_string(u.n) + R"(\s*\])");
    int mentions = 0;
    for (const std::string& l : mo.named_in)
      mentions += static_cast<int>(std::distance(std::sregex_iterator(l.begin(), l.end(), named), std::sregex_iterator()));
    t.joint_motion = joint_motions[u.n] == motions[u.n] && mentions == motions[u.n];
    p.targets.push_back(t);
  }
}

}  // namespace

NativeProgram read_ls_program(const std::string& path) {
  NativeProgram p;
  p.format = ControllerFormat::FanucLs;
  add_program_file(p, path);
  const auto& lines = p.lines[0];
  const LsSections sections = read_ls_sections(lines, path);
  const LsMotions motions = read_ls_motions(sections, lines, path, p);
  read_ls_targets(sections, motions, lines, path, p);
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
