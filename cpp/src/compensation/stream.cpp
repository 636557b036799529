#include "kincal/compensation/stream.hpp"
#include "kincal/model/joint_convention.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/gcode.hpp"
#include "kincal/io/programs.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>

namespace kincal {

namespace {

// The directions into the first pose: a stream cannot look ahead to the first motion.
Vec6 stream_directions(const Robot& robot, const ProgramOptions& opt) {
  if (!opt.compensate || !robot.calibrated()->needs_dir()) return Vec6::Ones();
  if (opt.initial_direction.empty())
    throw InputError("the model has backlash and a stream cannot look ahead to the first motion: give each "
                     "joint's direction into the first pose (--initial-direction)");
  return initial_directions(opt.initial_direction);
}

// The next comma-separated field of [f, e) without its surrounding blanks (RFC 4180: a field in double
// quotes may hold commas; its quotes are not part of it, a quote written twice inside stays so); f moves
// past its comma. `broken`: an unclosed quote, or text after the closing one.
struct Field {
  const char* begin;
  const char* end;
  bool broken = false;
  bool quoted = false;
};
Field next_field(const char*& f, const char* e) {
  auto blank = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  const char* c = f;
  while (c < e && blank(*c)) ++c;
  if (c < e && *c == '"') {
    Field field{c + 1, c + 1, false, true};
    for (++c; c < e; ++c) {
      if (*c != '"') continue;
      if (c + 1 < e && c[1] == '"') {
        ++c;
        continue;
      }
      break;
    }
    field.end = c;
    field.broken = c >= e;
    if (c < e) ++c;
    while (c < e && blank(*c)) ++c;
    field.broken = field.broken || (c < e && *c != ',');
    while (c < e && *c != ',') ++c;
    f = c + 1;
    return field;
  }
  while (c < e && *c != ',') ++c;
  Field field{f, c};
  while (field.begin < field.end && blank(*field.begin)) ++field.begin;
  while (field.end > field.begin && blank(field.end[-1])) --field.end;
  f = c + 1;
  return field;
}

// Whether a line with commas reads as G-code rather than as a CSV header: its first field (unquoted)
// holds a blank, a comment or a parenthesis, as "G1 X1,5" or "G1 X10 (a, b)" do.
bool gcode_with_commas(const char* s, size_t n) {
  const char* f = s;
  const Field fl = next_field(f, s + n);
  if (fl.quoted) return false;
  for (const char* c = fl.begin; c < fl.end; ++c)
    if (*c == ' ' || *c == '\t' || *c == '(' || *c == ';') return true;
  return false;
}

constexpr const char* kBrokenQuote = "a quoted field is not closed, or text follows its closing '\"'";

}  // namespace

StreamCompensator::StreamCompensator(Robot robot, ProgramOptions opt)
    : robot_(std::move(robot)), opt_(std::move(opt)), cursor_(robot_, opt_, stream_directions(robot_, opt_)) {
  warning_.reserve(512);
  if (opt_.compensate) periodic_ = periodic_joints(robot_.calibrated()->spec(), robot_.campaign().fitted_deg);
}

Vec6 StreamCompensator::solve(const Pose6& p, double temperature_c) {
  cursor_.ctx.temperature_c = std::isfinite(temperature_c) ? temperature_c : opt_.temperature_c;
  if (opt_.compensate && robot_.calibrated()->needs_temperature() && !std::isfinite(cursor_.ctx.temperature_c))
    fail_at("stdin", line_no_, kNeedsTemperature);
  const PoseSolution s = next_pose(robot_, opt_, p, cursor_);
  if (!s.ok()) throw InputError(std::string("stdin:") + std::to_string(line_no_) + ": " + s.error);
  if (s.branch_changed()) {
    if (opt_.keep_branch) fail_at("stdin", line_no_, branch_change_message(s.error));
    warning_ = "stdin:" + std::to_string(line_no_) + ": " + branch_change_message(s.error);
  }
  for (const Extrapolation& e : periodic_) {  // a joint leaving its fitted range: said once per excursion
    const size_t j = static_cast<size_t>(e.joint - 1);
    const bool out = j < 6 && outside_range(s.q_deg[static_cast<Eigen::Index>(j)], e.fitted);
    if (out && !outside_[j])
      warning_ += (warning_.empty() ? "" : "\n") + std::string("stdin:") + std::to_string(line_no_) + ": " +
                  leaving_message(e) + ": the effect is extrapolated from here, not measured";
    if (j < 6) outside_[j] = out;
  }
  Vec6 q = s.q_deg;  // the cursor keeps the model's angles; the line carries the controller's numbers
  joints_to_controller(robot_.nominal()->spec(), q.data(), 6);
  return q;
}

size_t StreamCompensator::process(const char* s, size_t n, char* out, size_t cap) {
  ++line_no_;
  warning_.clear();
  bool cr = false;  // a CRLF line: a G-code line comes out with its '\r' (the caller adds the '\n')
  while (n > 0 && (s[n - 1] == '\r' || s[n - 1] == '\n')) cr = cr || s[n - 1] == '\r', --n;
  // CSV when the line has commas, unless it reads as G-code (below); a header when it has letters
  bool has_comma = false, has_letter = false;
  for (size_t i = 0; i < n; ++i) {
    has_comma = has_comma || s[i] == ',';
    has_letter = has_letter || std::isalpha(static_cast<unsigned char>(s[i]));
  }
  // a stream of G-code stays G-code (a comma there is in a comment or a broken number)
  const bool gcode_seen = std::find(modal_set_, modal_set_ + 6, true) != modal_set_ + 6;
  if (!has_comma || gcode_seen || (!csv_header_seen_ && has_letter && gcode_with_commas(s, n))) {
    const size_t len = gcode_line(s, n, out, cap);
    if (!cr) return len;
    if (len + 1 >= cap) fail_at("stdin", line_no_, "line too long");
    out[len] = '\r';
    return len + 1;
  }
  if (line_no_ == 1 && n >= 3 && std::memcmp(s, "\xEF\xBB\xBF", 3) == 0) s += 3, n -= 3;  // Excel's byte order mark
  if (has_letter && !csv_header_seen_) return csv_header(s, n, out, cap);
  return csv_line(s, n, out, cap);
}

// The header: finds x,y,z,a,b,c (and temperature_c); the output header q1..q6.
size_t StreamCompensator::csv_header(const char* s, size_t n, char* out, size_t cap) {
  const char* names[6] = {"x", "y", "z", "a", "b", "c"};
  int found = 0, col = 0;
  for (const char* f = s; f <= s + n; ++col) {
    const Field fl = next_field(f, s + n);
    if (fl.broken) fail_at("stdin", line_no_, kBrokenQuote);
    for (int k = 0; k < 6; ++k)
      if (fl.end - fl.begin == 1 && *fl.begin == names[k][0]) csv_cols_[k] = col, found |= 1 << k;
    if (fl.end - fl.begin == 13 && std::strncmp(fl.begin, "temperature_c", 13) == 0) csv_temperature_col_ = col;
  }
  if (found != 63) fail_at("stdin", line_no_, "CSV header needs the columns x,y,z,a,b,c");
  csv_header_seen_ = true;
  const char hdr[] = "q1,q2,q3,q4,q5,q6";
  if (cap < sizeof hdr) fail_at("stdin", line_no_, "output buffer too small");
  std::memcpy(out, hdr, sizeof hdr - 1);
  return sizeof hdr - 1;
}

size_t StreamCompensator::csv_line(const char* s, size_t n, char* out, size_t cap) {
  double vals[7];
  vals[6] = std::numeric_limits<double>::quiet_NaN();
  int got = 0, col = 0;
  for (const char* f = s; f <= s + n; ++col) {
    const Field fl = next_field(f, s + n);
    if (fl.broken) fail_at("stdin", line_no_, kBrokenQuote);
    for (int k = 0; k < 7; ++k) {
      if (k < 6 ? csv_cols_[k] != col : csv_temperature_col_ != col) continue;
      const NumberParse r = parse_number(fl.begin, fl.end, vals[k]);
      if (r != NumberParse::Ok)
        fail_at("stdin", line_no_,
                std::string("column ") + (k < 6 ? std::string(1, "xyzabc"[k]) : std::string("temperature_c")) +
                    ": '" + std::string(fl.begin, fl.end) + "' is not a " +
                    (r == NumberParse::NotFinite ? "finite number" : "number"));
      got += k < 6;
    }
  }
  if (got != 6) fail_at("stdin", line_no_, "a CSV pose line needs x,y,z,a,b,c");
  Pose6 p;
  for (int k = 0; k < 3; ++k) p.xyz[k] = vals[k], p.abc[k] = vals[3 + k];
  return format_joints(out, cap, solve(p, vals[6]), ProgramFormat::Csv);
}

size_t StreamCompensator::gcode_line(const char* s, size_t n, char* out, size_t cap) {
  GcodeWord words[16];
  const int cnt = scan_gcode(s, n, GcodeWords::Pose, 6, words, 16, "stdin", line_no_);
  if (cnt == 0) {
    if (n >= cap) fail_at("stdin", line_no_, "line too long");
    std::memcpy(out, s, n);
    return n;
  }
  for (int k = 0; k < cnt; ++k) {
    (words[k].axis < 3 ? modal_.xyz : modal_.abc)[words[k].axis % 3] = words[k].value;
    modal_set_[words[k].axis] = true;
  }
  for (int k = 0; k < 6; ++k)
    if (!modal_set_[k])
      fail_at("stdin", line_no_, std::string("pose word ") + kPoseLetters[k] + " not set yet on the first motion line");
  const Vec6 q = solve(modal_, std::numeric_limits<double>::quiet_NaN());
  char cut[4096];
  const CutLine c = cut_words(s, n, words, cnt, cut, sizeof cut, "stdin", line_no_);
  return emit_gcode_line(cut, c.size, c.insert_at, q, out, cap);
}

}  // namespace kincal
