// kincal: the text of KRL data: aggregates, the declarations of data lists (read_krl_declarations, the
// backup's context of KRL programs), the top-level parts of a statement.
#include "krl_text.hpp"

#include "kincal/io/file.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>

namespace kincal {

namespace krl {

std::string code_of(const std::string& l) { return code_before(l, ';'); }
std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}
bool is_pos(const std::string& t) { return t == "E6POS" || t == "POS" || t == "FRAME"; }
bool is_axis(const std::string& t) { return t == "E6AXIS" || t == "AXIS"; }

const std::regex kDecl(R"(^\s*(?:DECL\s+)?(GLOBAL\s+)?(E6POS|POS|FRAME|E6AXIS|AXIS|FDAT|PDAT|LDAT)\s+(\w+)\s*(?:=\s*(\{.*\}))?\s*$)",
                       std::regex::icase);
const std::regex kElement(R"(^\s*\$?((?:TOOL|BASE)_DATA)\s*\[\s*(\d+)\s*\]\s*=\s*(\{.*\})\s*$)", std::regex::icase);
const std::regex kAssign(R"(^\s*(\$?\w+)(\.\w+)?\s*=(?!=)\s*(.*?)\s*$)");
const std::regex kApprox(R"(\s+C_(PTP|DIS|VEL|ORI|SPL)\b)", std::regex::icase);

// The fields of an aggregate "{X 1,Y 2,S 'B110',...}" by upper-case key, values trimmed.
std::map<std::string, std::string> fields_of(const std::string& agg) {
  std::map<std::string, std::string> out;
  for (const std::string& item : split_top(agg.substr(1, agg.size() - 2))) {
    size_t k = 0;
    while (k < item.size() && (std::isalnum(static_cast<unsigned char>(item[k])) || item[k] == '_')) ++k;
    out[upper_case(item.substr(0, k))] = trim(item.substr(k));
  }
  return out;
}

double number(const std::string& key, const std::string& val, const std::string& at) {
  char* end = nullptr;
  const double v = std::strtod(val.c_str(), &end);
  if (val.empty() || end == val.c_str() || *end != '\0' || !std::isfinite(v))
    throw InputError(at + ": " + key + " '" + val + "' is not a number");
  return v;
}

// S and T: a number or a KRL bit / hex literal 'B110', 'H1F'
int bits(const std::string& key, const std::string& val, const std::string& at) {
  if (val.size() >= 3 && val.front() == '\'' && val.back() == '\'') {
    const char radix = static_cast<char>(std::toupper(static_cast<unsigned char>(val[1])));
    char* end = nullptr;
    const std::string digits = val.substr(2, val.size() - 3);
    const long v = std::strtol(digits.c_str(), &end, radix == 'B' ? 2 : 16);
    if ((radix == 'B' || radix == 'H') && !digits.empty() && digits.size() < 16 && *end == '\0') return static_cast<int>(v);
    throw InputError(at + ": " + key + " " + val + " is not a number");
  }
  const double v = number(key, val, at);
  if (v != std::floor(v) || v < 0 || v > 1e6) throw InputError(at + ": " + key + " '" + val + "' is not a whole number");
  return static_cast<int>(v);
}

Aggregate read_aggregate(const std::string& agg, const std::string& at) {
  Aggregate a;
  bool seen[6] = {false, false, false, false, false, false};
  int s = -1, t = -1;
  for (const auto& [key, val] : fields_of(agg)) {
    for (int f = 0; f < 6; ++f) {
      if (key == std::string(1, "XYZABC"[f])) (f < 3 ? a.pose.xyz : a.pose.abc)[f % 3] = number(key, val, at), seen[f] = true;
      if (key == "A" + std::to_string(f + 1)) a.joints = true;
      if (key == "E" + std::to_string(f + 1)) a.external[static_cast<size_t>(f)] = number(key, val, at);
    }
    if (key == "S") s = bits(key, val, at);
    if (key == "T") t = bits(key, val, at);
  }
  for (int f = 5; f >= 0; --f)
    if (!seen[f]) a.missing = std::string(1, "XYZABC"[f]);
  if (s >= 0 && t >= 0) {
    a.taught = ControllerTarget{};
    a.taught->kuka_s = s;
    a.taught->kuka_t = t;
  }
  return a;
}

bool same_file(const std::string& a, const std::string& b) {
  if (a == b) return true;
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec) && !ec;
}

// The spans of the top-level comma-separated parts of code[from, to), trimmed.
std::vector<std::pair<size_t, size_t>> top_args(const std::string& code, size_t from, size_t to) {
  std::vector<std::pair<size_t, size_t>> out;
  int depth = 0;
  bool str = false;
  size_t b = from;
  for (size_t i = from; i <= to; ++i) {
    const char c = i < to ? code[i] : ',';
    if (c == '"') str = !str;
    if (!str && (c == '{' || c == '[' || c == '(')) ++depth;
    if (!str && (c == '}' || c == ']' || c == ')')) --depth;
    if (str || depth != 0 || c != ',') continue;
    size_t x = b, y = i;
    while (x < y && std::isspace(static_cast<unsigned char>(code[x]))) ++x;
    while (y > x && std::isspace(static_cast<unsigned char>(code[y - 1]))) --y;
    out.emplace_back(x, y);
    b = i + 1;
  }
  return out;
}

// Where the word WITH stands in code from `from` on, outside brackets and strings; npos when nowhere.
size_t with_at(const std::string& code, size_t from) {
  const std::string up = upper_case(code);
  int depth = 0;
  bool str = false;
  auto word = [&](size_t i) { return i < up.size() && (std::isalnum(static_cast<unsigned char>(up[i])) || up[i] == '_'); };
  for (size_t i = from; i < up.size(); ++i) {
    if (up[i] == '"') str = !str;
    if (!str && (up[i] == '{' || up[i] == '[' || up[i] == '(')) ++depth;
    if (!str && (up[i] == '}' || up[i] == ']' || up[i] == ')')) --depth;
    if (!str && depth == 0 && up.compare(i, 4, "WITH") == 0 && (i == 0 || !word(i - 1)) && !word(i + 4)) return i;
  }
  return std::string::npos;
}

bool top_colon(const std::string& s) {
  int depth = 0;
  for (char c : s) {
    depth += (c == '{' || c == '(' || c == '[') - (c == '}' || c == ')' || c == ']');
    if (c == ':' && depth == 0) return true;
  }
  return false;
}

std::string file_name(const std::string& path) { return path.substr(path.find_last_of("/\\") + 1); }

}  // namespace krl

using namespace krl;

Declarations read_krl_declarations(const std::vector<std::string>& paths) {
  Declarations d;
  std::vector<std::string> assigned;
  for (const std::string& path : paths) {
    const std::string name = upper_case(file_name(path));
    const bool config = name == "$CONFIG.DAT", src = name.size() > 4 && name.compare(name.size() - 4, 4, ".SRC") == 0;
    if (!src && (name.size() < 4 || name.compare(name.size() - 4, 4, ".DAT") != 0)) continue;
    const std::string text = read_text_file(path);
    size_t b = 0;
    for (int line = 1; b <= text.size(); ++line) {
      size_t e = text.find('\n', b);
      if (e == std::string::npos) e = text.size();
      const std::string code = code_of(text.substr(b, e - b));
      b = e + 1;
      std::smatch m;
      if (src) {
        if (std::regex_search(code, m, kAssign)) assigned.push_back(upper_case(m[1].str()));
        continue;
      }
      Declaration decl;
      decl.path = path;
      decl.line = line;
      if (std::regex_match(code, m, kDecl) && (config || m[1].matched)) {
        decl.type = upper_case(m[2].str());
        decl.name = m[3].str();
        decl.value = m[4].str();
      } else if (config && std::regex_match(code, m, kElement)) {
        decl.type = "FRAME";
        decl.name = upper_case(m[1].str()) + "[" + std::to_string(std::stoi(m[2].str())) + "]";
        decl.value = m[3].str();
      } else {
        continue;
      }
      d.named.emplace(upper_case(decl.name), decl);  // the first declaration of a name wins
    }
  }
  for (const std::string& n : assigned)
    if (auto it = d.named.find(n); it != d.named.end()) it->second.run_time = true;
  return d;
}

}  // namespace kincal
