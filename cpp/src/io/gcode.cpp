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

// Parses a G-code number at s[i..n): [+-]digits[.digits]; returns the end or fails.
size_t gcode_number(const char* s, size_t i, size_t n, double& v, const char* src, int line, const char* word) {
  const size_t start = i;
  if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
  size_t digits = 0;
  while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
  if (i < n && s[i] == '.') {
    ++i;
    while (i < n && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
  }
  if (digits == 0 || (i < n && (s[i] == '.' || s[i] == '+' || s[i] == '-')))
    fail_at(src, line, std::string("broken number in word ") + word + " ('" +
                           std::string(s + start - std::strlen(word), s + std::min(n, i + 1)) + "')");
  if (parse_number(s + start, s + i, v) != NumberParse::Ok)
    fail_at(src, line, std::string("broken number in word ") + word);
  return i;
}

}  // namespace

int scan_gcode(const char* s, size_t n, GcodeWords kind, int dof, GcodeWord* words, int cap, const char* src,
               int line) {
  int count = 0;
  size_t i = 0;
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
    // a run of letters; only a single letter is a word address
    size_t j = i;
    while (j < n && (std::isalpha(static_cast<unsigned char>(s[j])) || s[j] == '_')) ++j;
    const bool single = (j == i + 1);
    if (kind == GcodeWords::Pose) {
      const int ax = single ? pose_axis(c) : -1;
      if (ax >= 0) {
        const char word[2] = {static_cast<char>(std::toupper(static_cast<unsigned char>(c))), 0};
        if (j >= n || !(std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '+' || s[j] == '-' || s[j] == '.'))
          fail_at(src, line, std::string("word ") + word + " has no number");
        double v;
        const size_t e = gcode_number(s, j, n, v, src, line, word);
        if (e < n && s[e] == '=')
          fail_at(src, line, std::string("joint word ") + std::string(s + i, s + e) +
                                 "= in a pose program (pose words are X Y Z A B C)");
        if (count == cap) fail_at(src, line, "too many pose words on one line");
        words[count++] = GcodeWord{ax, i, e, v};
        i = e;
        continue;
      }
    } else if (single && (c == 'A' || c == 'a') && j < n && std::isdigit(static_cast<unsigned char>(s[j]))) {
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
        const size_t e = gcode_number(s, k + 1, n, v, src, line, word.c_str());
        if (count == cap) fail_at(src, line, "too many joint words on one line");
        words[count++] = GcodeWord{axis - 1, i, e, v};
        i = e;
        continue;
      }
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
