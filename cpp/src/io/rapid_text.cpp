// kincal: the text of RAPID modules: statements over several lines, robtarget and frame values.
#include "rapid_text.hpp"

#include "kincal/io/file.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <regex>
#include <set>

namespace kincal::rapid {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// a line that is a statement without ';': MODULE, routine heads and ends, IF .. THEN, labels, ...
bool block_line(const std::string& text) {
  static const std::regex word_re(R"(^\s*(?:LOCAL\s+)?(\w+))"), then_re(R"(\b(THEN|DO)\s*$)", std::regex::icase),
      label_re(R"(^\s*(CASE\b[^;]*|DEFAULT\s*|\w+\s*):\s*$)", std::regex::icase);
  static const std::set<std::string> heads{"MODULE", "ENDMODULE", "PROC", "FUNC", "TRAP", "ENDPROC", "ENDFUNC",
                                           "ENDTRAP", "ELSE", "ENDIF", "ENDFOR", "ENDWHILE", "TEST", "ENDTEST",
                                           "ERROR", "BACKWARD", "UNDO", "RECORD", "ENDRECORD", "VERSION", "LANGUAGE"};
  const std::string t = trim(text);
  if (t.empty()) return false;
  if (t.rfind("%%%", 0) == 0) return true;
  std::smatch m;
  if (std::regex_search(t, m, word_re) && heads.count(upper_case(m[1].str()))) return true;
  return std::regex_search(t, then_re) || std::regex_search(t, label_re);
}

std::vector<Stmt> statements(const std::vector<std::string>& lines) {
  std::vector<Stmt> out;
  Stmt cur;
  auto add = [&](const std::string& piece, int line, size_t col) {  // a line joined after one blank
    if (cur.text.empty() && trim(piece).empty()) return;
    const size_t skip = cur.text.empty() ? 0 : std::min(piece.size(), piece.find_first_not_of(" \t"));
    if (!cur.text.empty()) cur.text += ' ';
    cur.pieces.push_back({cur.text.size(), line, col + skip});
    cur.text += piece.substr(skip);
  };
  auto flush = [&] {
    if (!trim(cur.text).empty()) cur.ended = true, out.push_back(cur);
    cur = Stmt{};
  };
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string code = code_before(lines[i], '!');
    bool str = false;
    size_t from = 0;
    for (size_t c = 0; c < code.size(); ++c) {
      if (code[c] == '"') str = !str;
      if (code[c] != ';' || str) continue;
      add(code.substr(from, c + 1 - from), static_cast<int>(i + 1), from);
      flush();
      from = c + 1;
    }
    add(code.substr(from), static_cast<int>(i + 1), from);
    if (block_line(cur.text)) flush();
  }
  if (!trim(cur.text).empty()) out.push_back(cur);  // not ended: an error where it matters
  return out;
}

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

std::vector<std::string> parts_of(const std::string& v) {
  const std::string t = trim(v);
  return t.size() >= 2 && t.front() == '[' && t.back() == ']' ? split_top(t.substr(1, t.size() - 2)) : std::vector<std::string>{};
}

Eigen::Isometry3d frame_of(const std::string& part, const std::string& at, const char* what) {
  const auto pq = parts_of(part);
  if (pq.size() != 2) throw InputError(at + ": " + what + " is [[x,y,z],[q1,q2,q3,q4]], not '" + part + "'");
  const auto t = numbers(pq[0], 3, at, what), q = numbers(pq[1], 4, at, what);
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  f.translation() = Vec3(t[0], t[1], t[2]);
  return f;
}

// a robtarget value [[x,y,z],[q1..q4],[cf1,cf4,cf6,cfx],[e1..e6]] into t (pose, taught, external)
void parse_robtarget(const std::string& v, const std::string& at, NativeTarget& t) {
  const auto parts = parts_of(v);
  if (parts.size() != 4)
    throw InputError(at + ": a robtarget has 4 parts [trans],[rot],[robconf],[extax], this one " + std::to_string(parts.size()));
  t.pose = iso_to_pose(frame_of("[" + parts[0] + "," + parts[1] + "]", at, "the robtarget's trans and rot"));
  numbers(parts[0], 3, at, "the robtarget's trans");
  numbers(parts[1], 4, at, "the robtarget's rot");
  const auto cf = numbers(parts[2], 4, at, "the robtarget's robconf");
  const auto ex = numbers(parts[3], 6, at, "the robtarget's extax");
  ControllerTarget taught;
  for (size_t k = 0; k < 4; ++k) taught.abb_conf[k] = static_cast<int>(std::lround(cf[k]));
  t.taught = taught;
  for (size_t k = 0; k < 6; ++k) t.external[k] = ex[k] >= 8.99e9 ? std::numeric_limits<double>::quiet_NaN() : ex[k];
}

}  // namespace kincal::rapid
