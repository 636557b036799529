#include "kincal/io/gcode.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/programs.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <string>

namespace kincal {

namespace {

int pose_axis(char c) {
  const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const char* p = std::strchr(kPoseLetters, u);
  return (p && u) ? static_cast<int>(p - kPoseLetters) : -1;
}

// The word as written, for an error: from its letter to the next blank, ';', '(' or the line's end.
std::string word_text(const char* s, size_t begin, size_t n) {
  size_t e = begin;
  while (e < n && !std::isspace(static_cast<unsigned char>(s[e])) && s[e] != ';' && s[e] != '(') ++e;
  return std::string(s + begin, s + e);
}

[[noreturn]] void broken_number(const char* s, size_t word_begin, size_t n, const char* src, int line,
                                const std::string& word) {
  fail_at(src, line, "broken number in word " + word + " ('" + word_text(s, word_begin, n) +
                         "'): not a finite decimal number");
}

// Whether [b, e) spells NaN or infinity (any case): what strtod would take for a number.
// No allocation (the streaming corrector scans with it).
bool nonfinite_name(const char* b, const char* e) {
  auto is = [&](const char* w) {
    const size_t m = std::strlen(w);
    if (static_cast<size_t>(e - b) != m) return false;
    for (size_t k = 0; k < m; ++k)
      if (std::tolower(static_cast<unsigned char>(b[k])) != w[k]) return false;
    return true;
  };
  return is("nan") || is("inf") || is("infinity");
}

// Whether s[i] can start a number (or a NaN/infinity spelled out, which is then refused).
bool number_start(const char* s, size_t i, size_t n) {
  if (i >= n) return false;
  const char c = s[i];
  return std::isdigit(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
}

// Parses a G-code number at s[i..n): [+-]digits[.digits], followed by the line's end, a blank, a
// comment, a checksum '*', the next word's letter, or (allow_equals) '='. Anything else (a second
// '.', a decimal comma, an exponent, NaN, infinity) is not a finite decimal number: InputError naming
// the word (word_begin: where its letter stands). Returns the number's end.
size_t gcode_number(const char* s, size_t i, size_t n, double& v, const char* src, int line, const std::string& word,
                    size_t word_begin, bool allow_equals) {
  const size_t start = i;
  if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
  size_t digits = 0;
  while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
  if (i < n && s[i] == '.') {
    ++i;
    while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
  }
  bool ok = digits > 0;
  if (ok && i < n) {
    const char c = s[i];
    if (c == 'e' || c == 'E') {  // an exponent (1e400, 1E-3); a letter E with no number after is a word
      size_t k = i + 1;
      if (k < n && (s[k] == '+' || s[k] == '-')) ++k;
      ok = !(k < n && std::isdigit(static_cast<unsigned char>(s[k])));
    } else {
      ok = std::isspace(static_cast<unsigned char>(c)) || std::isalpha(static_cast<unsigned char>(c)) || c == ';' ||
           c == '(' || c == '*' || (allow_equals && c == '=');
    }
  }
  if (!ok || parse_number(s + start, s + i, v) != NumberParse::Ok) broken_number(s, word_begin, n, src, line, word);
  return i;
}

// Whether a line is a dwell (G4 / G04, outside comments): its X or P word is a time, not a position,
// so the line passes through as text in pose and joint programs alike.
bool dwell_line(const char* s, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const char c = s[i];
    if (c == ';') return false;
    if (c == '(') {
      while (i < n && s[i] != ')') ++i;
      continue;
    }
    if ((c == 'G' || c == 'g') && (i == 0 || !std::isalpha(static_cast<unsigned char>(s[i - 1])))) {
      size_t k = i + 1;
      while (k < n && s[k] == '0') ++k;
      if (k < n && s[k] == '4' && (k + 1 == n || !std::isdigit(static_cast<unsigned char>(s[k + 1]))) &&
          (k + 1 == n || s[k + 1] != '.' || (k + 2 < n && s[k + 2] == '0')))
        return true;
    }
  }
  return false;
}

}  // namespace

int scan_gcode(const char* s, size_t n, GcodeWords kind, int dof, GcodeWord* words, int cap, const char* src,
               int line) {
  int count = 0;
  size_t i = 0;
  if (dwell_line(s, n)) return 0;
  while (i < n) {
    const char c = s[i];
    if (c == ';') break;
    if (c == '(') {
      while (i < n && s[i] != ')') ++i;
      ++i;
      continue;
    }
    if (c == '"') {
      ++i;
      while (i < n && s[i] != '"') ++i;
      ++i;
      continue;
    }
    if (!std::isalpha(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    // a run of letters; only a single letter is a word address (a pose letter followed by NaN or
    // infinity spelled out is a word with a number that is not finite)
    size_t j = i;
    while (j < n && (std::isalpha(static_cast<unsigned char>(s[j])) || s[j] == '_')) ++j;
    const bool single = (j == i + 1);
    const int ax = pose_axis(c);
    const bool nonfinite = ax >= 0 && !single && nonfinite_name(s + i + 1, s + j);
    const std::string letter(1, static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (kind == GcodeWords::Pose) {
      if (nonfinite) broken_number(s, i, n, src, line, letter);
      if (single && ax >= 0) {
        if (!number_start(s, j, n)) fail_at(src, line, "word " + letter + " has no number");
        double v;
        const size_t e = gcode_number(s, j, n, v, src, line, letter, i, true);
        if (e < n && s[e] == '=')
          fail_at(src, line, std::string("joint word ") + std::string(s + i, s + e) +
                                 "= in a pose program (pose words are X Y Z A B C)");
        if (count == cap) fail_at(src, line, "too many pose words on one line");
        words[count++] = GcodeWord{ax, i, e, v};
        i = e;
        continue;
      }
    } else {
      if (single && (c == 'A' || c == 'a') && j < n && std::isdigit(static_cast<unsigned char>(s[j]))) {
        size_t k = j;
        int axis = 0;
        while (k < n && std::isdigit(static_cast<unsigned char>(s[k]))) {
          if (axis < 1000) axis = axis * 10 + (s[k] - '0');  // a huge index stays huge, never overflows
          ++k;
        }
        if (k < n && s[k] == '=') {
          const std::string word = std::string(s + i, s + k) + "=";
          if (axis < 1 || axis > dof)
            fail_at(src, line, "word " + word + " but the robot has " + std::to_string(dof) + " joints");
          double v;
          const size_t e = gcode_number(s, k + 1, n, v, src, line, word, i, false);
          if (count == cap) fail_at(src, line, "too many joint words on one line");
          words[count++] = GcodeWord{axis - 1, i, e, v};
          i = e;
          continue;
        }
      }
      // a pose word (X100, A180, Xnan) in a joint program: a Cartesian motion there is ambiguous
      if (nonfinite || (single && ax >= 0 && number_start(s, j, n)))
        fail_at(src, line, "pose word '" + word_text(s, i, n) + "' in a joint program (joint words are A1= .. A" +
                               std::to_string(dof) + "=): a Cartesian motion in a joint program is ambiguous");
    }
    i = j;
  }
  return count;
}

CutLine cut_words(const char* s, size_t n, const GcodeWord* words, int count, char* buf, size_t cap,
                  const char* src, int line) {
  CutLine cut;
  size_t pos = 0;
  cut.insert_at = static_cast<size_t>(-1);
  auto put = [&](const char* p, size_t m) {
    if (cut.size + m >= cap) fail_at(src, line, "line too long");
    std::memcpy(buf + cut.size, p, m);
    cut.size += m;
  };
  for (int k = 0; k < count; ++k) {
    put(s + pos, words[k].begin - pos);
    if (k == 0) cut.insert_at = cut.size;
    pos = words[k].end;
    if (pos < n && (s[pos] == ' ' || s[pos] == '\t')) ++pos;
  }
  put(s + pos, n - pos);
  if (count == 0) cut.insert_at = cut.size;
  return cut;
}

size_t emit_gcode_line(const char* cut, size_t n, size_t insert_at, const Vec6& q, char* out, size_t cap) {
  if (insert_at >= cap) throw InputError("output line too long");
  std::memcpy(out, cut, insert_at);
  size_t len = insert_at;
  len += format_joints(out + len, cap - len, q, ProgramFormat::Gcode);
  if (insert_at < n && cut[insert_at] != ' ' && cut[insert_at] != '\t') {
    if (len + 1 >= cap) throw InputError("output line too long");
    out[len++] = ' ';
  }
  if (len + (n - insert_at) >= cap) throw InputError("output line too long");
  std::memcpy(out + len, cut + insert_at, n - insert_at);
  return len + (n - insert_at);
}

}  // namespace kincal
