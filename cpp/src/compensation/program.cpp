#include "kincal/compensation/program.hpp"

#include "kincal/kinematics/kinematics.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace kincal {

namespace {


std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path + ": cannot open the file (" + std::strerror(errno) + ")");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::string where(const std::string& src, int line) { return src + ":" + std::to_string(line); }

// Parses a whole-field finite number; returns false when it is not one.
bool parse_double(const char* b, const char* e, double& v, bool& nonfinite) {
  nonfinite = false;
  if (b == e) return false;
  char buf[64];
  const size_t n = static_cast<size_t>(e - b);
  if (n >= sizeof buf) return false;
  std::memcpy(buf, b, n);
  buf[n] = 0;
  char* end = nullptr;
  v = std::strtod(buf, &end);
  if (end != buf + n) return false;
  if (!std::isfinite(v)) {
    nonfinite = true;
    return false;
  }
  return true;
}

const char* kPoseLetters = "XYZABC";

int pose_axis(char c) {
  const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const char* p = std::strchr(kPoseLetters, u);
  return (p && u) ? static_cast<int>(p - kPoseLetters) : -1;
}

struct WordSpan {
  int axis;  // pose: 0..5 (X Y Z A B C); joint: 0..N-1
  size_t begin, end;
  double value;
};

[[noreturn]] void fail_at(const char* src, int line, const std::string& cause) {
  throw InputError(std::string(src) + ":" + std::to_string(line) + ": " + cause);
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
  bool nonfinite;
  if (!parse_double(s + start, s + i, v, nonfinite)) fail_at(src, line, std::string("broken number in word ") + word);
  return i;
}

// Scans one G-code line. Pose mode: words X Y Z A B C; joint mode: words A1= .. AN=.
// Comments (';' to the end, '(...)') and quoted strings are skipped. Returns the number of spans.
int scan_gcode(const char* s, size_t n, bool joint_mode, int dof, WordSpan* spans, int cap, const char* src,
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
    if (!joint_mode) {
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
        spans[count++] = WordSpan{ax, i, e, v};
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
        spans[count++] = WordSpan{axis - 1, i, e, v};
        i = e;
        continue;
      }
    }
    i = j;
  }
  return count;
}

// Copies the line with the spans cut out (each with one following blank) into buf; insert_at is
// where the first span was. No allocation.
size_t cut_spans(const char* s, size_t n, const WordSpan* spans, int count, char* buf, size_t cap,
                 size_t& insert_at, const char* src, int line) {
  size_t len = 0, pos = 0;
  insert_at = static_cast<size_t>(-1);
  auto put = [&](const char* p, size_t m) {
    if (len + m >= cap) fail_at(src, line, "line too long");
    std::memcpy(buf + len, p, m);
    len += m;
  };
  for (int k = 0; k < count; ++k) {
    put(s + pos, spans[k].begin - pos);
    if (k == 0) insert_at = len;
    pos = spans[k].end;
    if (pos < n && (s[pos] == ' ' || s[pos] == '\t')) ++pos;
  }
  put(s + pos, n - pos);
  if (count == 0) insert_at = len;
  return len;
}

size_t format_joints(char* out, size_t cap, const Vec6& q, bool csv) {
  size_t len = 0;
  for (int j = 0; j < 6; ++j) {
    const int w = csv ? std::snprintf(out + len, cap - len, j ? ",%.10f" : "%.10f", q[j])
                      : std::snprintf(out + len, cap - len, j ? " A%d=%.10f" : "A%d=%.10f", j + 1, q[j]);
    if (w < 0 || static_cast<size_t>(w) >= cap - len) throw InputError("output line too long");
    len += static_cast<size_t>(w);
  }
  return len;
}

// A joint G-code line: the cut line with the joint words at insert_at. No allocation.
size_t emit_gcode_line(const char* cut, size_t n, size_t insert_at, const Vec6& q, char* out, size_t cap) {
  if (insert_at >= cap) throw InputError("output line too long");
  std::memcpy(out, cut, insert_at);
  size_t len = insert_at;
  len += format_joints(out + len, cap - len, q, false);
  if (insert_at < n && cut[insert_at] != ' ' && cut[insert_at] != '\t') {
    if (len + 1 >= cap) throw InputError("output line too long");
    out[len++] = ' ';
  }
  if (len + (n - insert_at) >= cap) throw InputError("output line too long");
  std::memcpy(out + len, cut + insert_at, n - insert_at);
  return len + (n - insert_at);
}

Vec6 home_of(const Model& m) {
  Vec6 q = Vec6::Zero();
  if (m.spec().home_deg.size() == 6)
    for (int j = 0; j < 6; ++j) q[j] = m.spec().home_deg[j];
  return q;
}

}  // namespace

namespace {

// The limit a compensated solution violates, as a message; empty when inside the limits.
std::string limit_violation(const Model& m, const Vec6& q) {
  if (m.within_limits_deg(q)) return {};
  for (int j = 0; j < 6; ++j) {
    const auto& js = m.spec().joints[j];
    if (q[j] < js.lower_deg - 1e-9 || q[j] > js.upper_deg + 1e-9) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "compensated q%d = %.4f deg is outside its limits [%g, %g]", j + 1, q[j],
                    js.lower_deg, js.upper_deg);
      return buf;
    }
  }
  return "outside the joint limits";
}

// A converged compensation inside the limits is the answer; otherwise err says why not.
bool accept(const Model& m, const CompensationResult& r, Vec6& q_out, int& iterations, double& residual,
            std::string& err) {
  if (r.status != CompStatus::Converged) {
    char buf[160];
    std::snprintf(buf, sizeof buf, " (after %d iterations, |F| = %.3g)", r.iterations, r.residual);
    err = std::string("compensation failed: ") + to_string(r.status) + buf;
    return false;
  }
  err = limit_violation(m, r.q_deg);
  if (!err.empty()) return false;
  q_out = r.q_deg;
  iterations = r.iterations;
  residual = r.residual;
  return true;
}

// Newton on the calibrated model from one nominal IK solution q0 (corrected once, by default).
// Returns false with the cause in err.
bool compensate_from(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Eigen::Isometry3d& target,
                     Vec6 q0, bool approximate_start, const EffectContext& ctx, Vec6& q_out, int& iterations,
                     double& residual, std::string& err) {
  const Model& nom = *robot.nominal;
  const Model& cal = *robot.calibrated;
  if (opt.corrected_start && robot.identified()) {
    // one fixed-point step: the nominal IK of the target corrected by the model difference at q0,
    // e = FK_nom(q0)^-1 FK_cal(q0), where FK_nom(q0) is the target itself unless q0 only came near it
    const VecQ a = q0 * kDeg;
    const Eigen::Isometry3d at_q0 = approximate_start ? fk(nom, a) : target;
    const Eigen::Isometry3d e = at_q0.inverse() * fk_model(cal, a, ctx);
    const IkSolutions s2 = ik_all(nom, target * e.inverse(), q0.data(), false, true);
    const int k2 = ik_nearest(nom, s2, q0.data());
    if (k2 >= 0) q0 = s2.sol[k2].q_deg;
  }
  const CompensationResult r = compensate(cal, pose, q0, opt.comp, ctx);
  if (r.status != CompStatus::Converged && approximate_start) {
    err = "pose out of reach of the robot (beyond the nominal reach, and the model does not reach it either)";
    return false;
  }
  return accept(cal, r, q_out, iterations, residual, err);
}

}  // namespace

bool solve_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, const Vec6& ref, Vec6& q_out,
                int& iterations, double& residual, std::string& err) {
  bool changed;
  return solve_pose(robot, opt, pose, ref, EffectContext(), q_out, iterations, residual, changed, err);
}

// Nominal IK start (nearest ref) and Newton compensation of one pose; the other branches, nearest
// first, when the nearest one's compensated solution is not inside the limits. Returns false with
// the cause in err; allocates nothing when the nearest branch succeeds.
bool solve_pose(const Robot& robot, const ProgramOptions& opt, const Pose6& pose_in, const Vec6& ref,
                const EffectContext& ctx, Vec6& q_out, int& iterations, double& residual, bool& branch_changed,
                std::string& err) {
  const Model& nom = *robot.nominal;
  const Model& cal = *robot.calibrated;
  branch_changed = false;
  iterations = 0;
  residual = 0;
  if (nom.dof() != 6) {
    err = "programs need a 6-joint robot";
    return false;
  }
  Pose6 pose = pose_in;
  if (opt.instrument_frame) pose = iso_to_pose(cal.base_in_instrument().inverse() * pose_to_iso(pose_in));
  if (robot.ik().structure().spherical_wrist_parallel_23) {
    const Eigen::Isometry3d target = pose_to_iso(pose);
    // the branch nearest the reference first; all branches when it is out of limits
    IkSolutions s = ik_all(nom, target, ref.data(), false, true);
    bool all = false;
    if (s.status != IkStatus::Ok || !s.sol[0].within_limits) s = ik_all(nom, target, ref.data()), all = true;
    // a calibrated robot may reach a little beyond the nominal one: start from the nearest
    if (s.status != IkStatus::Ok && opt.compensate) s = ik_all(nom, target, ref.data(), true), all = true;
    if (s.status != IkStatus::Ok) {
      err = "pose out of reach of the robot (no inverse-kinematics solution)";
      return false;
    }
    const int k = ik_nearest(nom, s, ref.data());
    if (!opt.compensate) {
      if (k < 0) {
        err = "no inverse-kinematics solution within the joint limits";
        return false;
      }
      q_out = s.sol[k].q_deg;
      return true;
    }
    if (k >= 0 && compensate_from(robot, opt, pose, target, s.sol[k].q_deg, s.sol[k].approximate, ctx, q_out,
                                  iterations, residual, err))
      return true;
    // the nearest branch does not give a compensated solution inside the limits: the others, nearest
    // first (a nominal solution a little outside the limits may come inside once compensated)
    const std::string first_err = k >= 0 ? err : "no inverse-kinematics solution within the joint limits";
    const Vec6 tried = k >= 0 ? s.sol[k].q_deg : Vec6::Constant(1e300);
    if (!all) s = ik_all(nom, target, ref.data(), false, false);
    std::array<int, 8> order;
    std::array<double, 8> dist;
    for (int i = 0; i < s.count; ++i) order[i] = i, dist[i] = (s.sol[i].q_deg - ref).cwiseAbs().maxCoeff();
    for (int i = 1; i < s.count; ++i)  // insertion sort by distance (at most 8)
      for (int j = i; j > 0 && dist[order[j]] < dist[order[j - 1]]; --j) std::swap(order[j], order[j - 1]);
    for (int i = 0; i < s.count; ++i) {
      const IkSolution& c = s.sol[order[i]];
      if ((c.q_deg - tried).cwiseAbs().maxCoeff() < 1e-9) continue;  // the nearest branch, tried first
      if (compensate_from(robot, opt, pose, target, c.q_deg, c.approximate, ctx, q_out, iterations, residual, err)) {
        branch_changed = true;
        return true;
      }
    }
    err = first_err + (s.count > 1 ? "; no other branch reaches the pose inside the limits" : "");
    return false;
  }
  // nominal robots without closed-form IK, and every calibrated robot: Newton on the model
  const Model& target_model = opt.compensate ? cal : nom;
  const EffectContext none;
  const EffectContext& c = opt.compensate ? ctx : none;
  CompensationResult r = compensate(target_model, pose, ref, opt.comp, c);
  if (r.status == CompStatus::Converged) r.q_deg = wrap_near(target_model, r.q_deg, ref);
  if (r.status != CompStatus::Converged || !target_model.within_limits_deg(r.q_deg)) {
    // no closed form to start from: a numerical IK from the reference, home and seeded starts
    Vec6 qn;
    if (numeric_ik(target_model, pose, ref, qn, opt.comp, 48, c)) r = compensate(target_model, pose, qn, opt.comp, c);
    if (r.status == CompStatus::Converged) r.q_deg = wrap_near(target_model, r.q_deg, ref);
  }
  return accept(target_model, r, q_out, iterations, residual, err);
}

// ---------------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------------
int CsvTable::find(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

int CsvTable::require(const std::string& name) const {
  const int c = find(name);
  if (c < 0) {
    std::string cols;
    for (const auto& h : header) cols += (cols.empty() ? "" : ",") + h;
    throw InputError(source + ":1: missing column '" + name + "' (header: " + cols + ")");
  }
  return c;
}

double CsvTable::number(size_t row, int col) const {
  const std::string& s = cells[row][static_cast<size_t>(col)];
  double v;
  bool nonfinite;
  if (!parse_double(s.data(), s.data() + s.size(), v, nonfinite)) {
    if (nonfinite)
      throw InputError(where(row) + ": column '" + header[col] + "': '" + s + "' is not a finite number");
    throw InputError(where(row) + ": column '" + header[col] + "': '" + s + "' is not a number");
  }
  return v;
}

CsvTable parse_csv(const std::string& text, const std::string& source) {
  CsvTable t;
  t.source = source;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  bool have_header = false;
  while (std::getline(in, raw)) {
    ++line;
    const std::string s = trim(raw);
    if (s.empty()) continue;
    std::vector<std::string> fields;
    size_t pos = 0;
    while (true) {
      const size_t c = s.find(',', pos);
      fields.push_back(trim(s.substr(pos, c == std::string::npos ? std::string::npos : c - pos)));
      if (c == std::string::npos) break;
      pos = c + 1;
    }
    if (!have_header) {
      for (const auto& f : fields)
        if (f.empty()) throw InputError(where(source, line) + ": empty column name in the header");
      t.header = fields;
      have_header = true;
      continue;
    }
    if (fields.size() != t.header.size())
      throw InputError(where(source, line) + ": " + std::to_string(fields.size()) + " fields, the header has " +
                       std::to_string(t.header.size()));
    t.cells.push_back(std::move(fields));
    t.line.push_back(line);
  }
  if (!have_header) throw InputError(source + ": empty file (no header row)");
  return t;
}

CsvTable read_csv(const std::string& path) { return parse_csv(read_text(path), path); }

bool is_csv_path(const std::string& path) {
  if (path.size() < 4) return false;
  std::string e = path.substr(path.size() - 4);
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e == ".csv";
}

// ---------------------------------------------------------------------------------------------
// Programs
// ---------------------------------------------------------------------------------------------
PoseProgram parse_pose_program(const std::string& text, const std::string& source, bool gcode) {
  PoseProgram p;
  p.source = source;
  p.gcode = gcode;
  if (!gcode) {
    const CsvTable t = parse_csv(text, source);
    int col[6];
    const char* names[6] = {"x", "y", "z", "a", "b", "c"};
    for (int k = 0; k < 6; ++k) col[k] = t.require(names[k]);
    const int tc = t.find("temperature_c");
    for (size_t r = 0; r < t.cells.size(); ++r) {
      Pose6 pose;
      for (int k = 0; k < 3; ++k) pose.xyz[k] = t.number(r, col[k]);
      for (int k = 0; k < 3; ++k) pose.abc[k] = t.number(r, col[3 + k]);
      p.poses.push_back(pose);
      p.pose_line.push_back(t.line[r]);
      if (tc >= 0) p.temperature_c.push_back(t.number(r, tc));
    }
    if (p.poses.empty()) throw InputError(source + ": the program has no poses");
    return p;
  }
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  Pose6 modal;
  bool set[6] = {false, false, false, false, false, false};
  WordSpan spans[16];
  while (std::getline(in, raw)) {
    ++line;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    const int n = scan_gcode(raw.data(), raw.size(), false, 6, spans, 16, source.c_str(), line);
    PoseProgram::Line l;
    if (n == 0) {
      l.text = raw;
      p.lines.push_back(std::move(l));
      continue;
    }
    for (int k = 0; k < n; ++k) {
      (spans[k].axis < 3 ? modal.xyz : modal.abc)[spans[k].axis % 3] = spans[k].value;
      set[spans[k].axis] = true;
    }
    std::string missing;
    for (int k = 0; k < 6; ++k)
      if (!set[k]) missing += std::string(missing.empty() ? "" : " ") + kPoseLetters[k];
    if (!missing.empty()) fail_at(source.c_str(), line, "pose word(s) " + missing + " not set yet on the first motion line");
    char buf[4096];
    const size_t len = cut_spans(raw.data(), raw.size(), spans, n, buf, sizeof buf, l.insert_at, source.c_str(), line);
    l.text.assign(buf, len);
    l.pose = static_cast<int>(p.poses.size());
    p.poses.push_back(modal);
    p.pose_line.push_back(line);
    p.lines.push_back(std::move(l));
  }
  if (p.poses.empty()) throw InputError(source + ": the program has no poses (no X Y Z A B C words)");
  return p;
}

PoseProgram read_pose_program(const std::string& path) {
  return parse_pose_program(read_text(path), path, !is_csv_path(path));
}

JointProgram parse_joint_program(const std::string& text, const std::string& source, bool gcode, int dof) {
  JointProgram p;
  p.source = source;
  p.dof = dof;
  if (!gcode) {
    const CsvTable t = parse_csv(text, source);
    std::vector<int> col;
    for (int j = 0; j < dof; ++j) col.push_back(t.require("q" + std::to_string(j + 1)));
    if (t.find("q" + std::to_string(dof + 1)) >= 0)
      throw InputError(source + ":1: column q" + std::to_string(dof + 1) + " but the robot has " +
                       std::to_string(dof) + " joints");
    for (size_t r = 0; r < t.cells.size(); ++r) {
      std::vector<double> q(dof);
      for (int j = 0; j < dof; ++j) q[j] = t.number(r, col[j]);
      p.q.push_back(q);
      p.line.push_back(t.line[r]);
    }
  } else {
    std::istringstream in(text);
    std::string raw;
    int line = 0;
    std::vector<double> modal(dof, 0.0);
    std::vector<bool> set(dof, false);
    WordSpan spans[kMaxJoints * 2];
    while (std::getline(in, raw)) {
      ++line;
      const int n = scan_gcode(raw.data(), raw.size(), true, dof, spans, kMaxJoints * 2, source.c_str(), line);
      if (n == 0) continue;
      for (int k = 0; k < n; ++k) {
        modal[spans[k].axis] = spans[k].value;
        set[spans[k].axis] = true;
      }
      for (int j = 0; j < dof; ++j)
        if (!set[j]) fail_at(source.c_str(), line, "joint word A" + std::to_string(j + 1) + "= not set yet");
      p.q.push_back(modal);
      p.line.push_back(line);
    }
  }
  if (p.q.empty()) throw InputError(source + ": the joint program has no motion lines");
  return p;
}

JointProgram read_joint_program(const std::string& path, int dof) {
  return parse_joint_program(read_text(path), path, !is_csv_path(path), dof);
}

void write_file_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw InputError(path + ": cannot write the output file (" + std::strerror(errno) + ")");
    f << text;
    f.flush();
    if (!f) {
      std::remove(tmp.c_str());
      throw InputError(path + ": writing the output file failed");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot move the output file into place (" + std::strerror(errno) + ")");
  }
}

std::vector<Vec6> motion_directions(const std::vector<Vec6>& q, const std::vector<double>& initial) {
  Vec6 d = Vec6::Ones();
  if (initial.size() == 6) {
    d = Eigen::Map<const Vec6>(initial.data());
  } else if (initial.size() == 1) {
    d.setConstant(initial[0]);
  } else {  // the direction of each joint's first motion
    for (int j = 0; j < 6; ++j)
      for (size_t i = 1; i < q.size(); ++i) {
        const double delta = q[i][j] - q[i - 1][j];
        if (std::abs(delta) > kStillDeg) {
          d[j] = delta > 0 ? 1.0 : -1.0;
          break;
        }
      }
  }
  std::vector<Vec6> out(q.size());
  for (size_t i = 0; i < q.size(); ++i) {
    for (int j = 0; j < 6 && i > 0; ++j) {
      const double delta = q[i][j] - q[i - 1][j];
      if (std::abs(delta) > kStillDeg) d[j] = delta > 0 ? 1.0 : -1.0;
    }
    out[i] = d;
  }
  return out;
}

namespace {

Vec6 initial_direction(const std::vector<double>& v) {
  if (v.size() == 1) return Vec6::Constant(v[0]);
  if (v.size() != 6) throw InputError("--initial-direction needs one sign for every joint, or one for all");
  for (double x : v)
    if (x != 1.0 && x != -1.0) throw InputError("--initial-direction: the directions must be +1 or -1");
  return Eigen::Map<const Vec6>(v.data());
}

// One pose of a program in order: solved with the directions the joints have (held from the
// previous pose), then, with backlash, again with the directions of its own motion when that motion
// turns a joint around. ctx.dir holds the directions into the pose on return; prev the pose.
bool program_step(const Robot& robot, const ProgramOptions& opt, const Pose6& pose, bool first, Vec6& prev,
                  EffectContext& ctx, Vec6& q, int& it, double& r, bool& changed, std::string& err) {
  if (!solve_pose(robot, opt, pose, prev, ctx, q, it, r, changed, err)) return false;
  if (!first && opt.compensate && robot.calibrated->needs_dir()) {
    VecQ turned = ctx.dir;
    bool any = false;
    for (int j = 0; j < 6; ++j) {
      const double delta = q[j] - prev[j];
      if (std::abs(delta) > kStillDeg && (delta > 0 ? 1.0 : -1.0) != ctx.dir[j]) turned[j] = -ctx.dir[j], any = true;
    }
    if (any) {
      EffectContext c2 = ctx;
      c2.dir = turned;
      Vec6 q2;
      int it2;
      double r2;
      bool changed2;
      if (!solve_pose(robot, opt, pose, prev, c2, q2, it2, r2, changed2, err)) return false;
      q = q2, it = it2, r = r2, changed = changed || changed2;
      // the directions the commanded motion really has (a move inside the backlash keeps its sign)
      for (int j = 0; j < 6; ++j) {
        const double delta = q[j] - prev[j];
        if (std::abs(delta) > kStillDeg) ctx.dir[j] = delta > 0 ? 1.0 : -1.0;
      }
    }
  }
  prev = q;
  return true;
}

}  // namespace

ProgramResult compensate_poses(const Robot& robot, const std::vector<Pose6>& poses,
                               const std::vector<std::string>& where_of, const ProgramOptions& opt,
                               const std::vector<double>& temperature_c) {
  const Model& cal = *robot.calibrated;
  auto where_i = [&](size_t i) { return i < where_of.size() ? where_of[i] : "pose " + std::to_string(i); };
  const bool needs_dir = opt.compensate && cal.needs_dir();
  const bool needs_t = opt.compensate && cal.needs_temperature();
  std::vector<double> temps(poses.size(), opt.temperature_c);
  for (size_t i = 0; i < temperature_c.size() && i < poses.size(); ++i)
    if (std::isfinite(temperature_c[i])) temps[i] = temperature_c[i];
  if (needs_t)
    for (size_t i = 0; i < poses.size(); ++i)
      if (!std::isfinite(temps[i]))
        throw InputError(where_i(i) + ": the model has thermal expansion: give the temperature (--temperature C, or "
                                      "a temperature_c column)");
  auto run = [&](const Vec6& dir0) {
    ProgramResult res;
    Vec6 prev = home_of(*robot.nominal);
    EffectContext ctx;
    if (needs_dir) ctx.dir = dir0;
    std::string err;
    for (size_t i = 0; i < poses.size(); ++i) {
      Vec6 q;
      int it;
      double r;
      bool changed;
      ctx.temperature_c = temps[i];
      if (!program_step(robot, opt, poses[i], i == 0, prev, ctx, q, it, r, changed, err))
        throw InputError(where_i(i) + ": " + err);
      if (changed && i > 0) {
        const std::string w = where_i(i) + ": branch changed: on the branch nearest the previous pose, " + err;
        if (opt.keep_branch) throw InputError(w + " (--keep-branch)");
        res.warnings.push_back(w);
      }
      res.q_deg.push_back(q);
      res.dir.push_back(needs_dir ? Vec6(ctx.dir) : Vec6::Zero());
      res.iterations.push_back(it);
      res.residual.push_back(r);
      res.max_iterations = std::max(res.max_iterations, it);
      res.max_residual = std::max(res.max_residual, r);
    }
    return res;
  };
  if (!needs_dir) return run(Vec6::Ones());
  if (!opt.initial_direction.empty()) return run(initial_direction(opt.initial_direction));
  // the direction of the first motion: from a first pass that assumes +1, then the program again
  const ProgramResult first = run(Vec6::Ones());
  return run(motion_directions(first.q_deg, {})[0]);
}

std::string format_joint_program(const PoseProgram& in, const ProgramResult& res, bool csv) {
  std::string out;
  char buf[512];
  if (csv) {
    out = "q1,q2,q3,q4,q5,q6\n";
    for (const Vec6& q : res.q_deg) {
      out.append(buf, format_joints(buf, sizeof buf, q, true));
      out += '\n';
    }
    return out;
  }
  if (!in.gcode) {
    for (const Vec6& q : res.q_deg) {
      out += "G1 ";
      out.append(buf, format_joints(buf, sizeof buf, q, false));
      out += '\n';
    }
    return out;
  }
  for (const PoseProgram::Line& l : in.lines) {
    if (l.pose < 0) {
      out += l.text;
    } else {
      char line[8192];
      out.append(line, emit_gcode_line(l.text.data(), l.text.size(), l.insert_at,
                                       res.q_deg[static_cast<size_t>(l.pose)], line, sizeof line));
    }
    out += '\n';
  }
  return out;
}

ProgramResult compensate_program_file(const Robot& robot, const std::string& in_path, const std::string& out_path,
                                      const ProgramOptions& opt) {
  const PoseProgram prog = read_pose_program(in_path);
  std::vector<std::string> where_of;
  where_of.reserve(prog.poses.size());
  for (int l : prog.pose_line) where_of.push_back(where(in_path, l));
  const ProgramResult res = compensate_poses(robot, prog.poses, where_of, opt, prog.temperature_c);
  write_file_atomic(out_path, format_joint_program(prog, res, is_csv_path(out_path)));
  return res;
}

// ---------------------------------------------------------------------------------------------
// Streaming
// ---------------------------------------------------------------------------------------------
StreamCompensator::StreamCompensator(Robot robot, ProgramOptions opt) : robot_(std::move(robot)), opt_(opt) {
  prev_ = home_of(*robot_.nominal);
  if (opt_.compensate && robot_.calibrated->needs_dir()) {
    if (opt_.initial_direction.empty())
      throw InputError("the model has backlash and a stream cannot look ahead to the first motion: give each "
                       "joint's direction into the first pose (--initial-direction)");
    ctx_.dir = initial_direction(opt_.initial_direction);
  }
  warning_.reserve(512);
}

Vec6 StreamCompensator::solve(const Pose6& p, double temperature_c) {
  Vec6 q;
  int it;
  double r;
  bool changed;
  std::string err;
  ctx_.temperature_c = std::isfinite(temperature_c) ? temperature_c : opt_.temperature_c;
  if (opt_.compensate && robot_.calibrated->needs_temperature() && !std::isfinite(ctx_.temperature_c))
    fail_at("stdin", line_no_, "the model has thermal expansion: give the temperature (--temperature C, or a "
                               "temperature_c column)");
  if (!program_step(robot_, opt_, p, first_, prev_, ctx_, q, it, r, changed, err))
    throw InputError(std::string("stdin:") + std::to_string(line_no_) + ": " + err);
  if (changed && !first_) {
    if (opt_.keep_branch) fail_at("stdin", line_no_, "branch changed: on the branch nearest the previous pose, " + err);
    warning_ = "stdin:" + std::to_string(line_no_) + ": branch changed: on the branch nearest the previous pose, " + err;
  }
  first_ = false;
  return q;
}

size_t StreamCompensator::process(const char* s, size_t n, char* out, size_t cap) {
  ++line_no_;
  warning_.clear();
  while (n > 0 && (s[n - 1] == '\r' || s[n - 1] == '\n')) --n;
  // CSV when the line has commas and no pose letters in it
  bool has_comma = false, has_letter = false;
  for (size_t i = 0; i < n; ++i) {
    has_comma = has_comma || s[i] == ',';
    has_letter = has_letter || std::isalpha(static_cast<unsigned char>(s[i]));
  }
  if (has_comma) {
    const char* b = s;
    const char* e = s + n;
    if (has_letter && !csv_header_seen_) {
      // header: find x,y,z,a,b,c
      const char* names[6] = {"x", "y", "z", "a", "b", "c"};
      int found = 0, col = 0;
      for (const char* f = b; f <= e; ++col) {
        const char* c = f;
        while (c < e && *c != ',') ++c;
        const char* fb = f;
        const char* fe = c;
        while (fb < fe && std::isspace(static_cast<unsigned char>(*fb))) ++fb;
        while (fe > fb && std::isspace(static_cast<unsigned char>(fe[-1]))) --fe;
        for (int k = 0; k < 6; ++k)
          if (fe - fb == 1 && *fb == names[k][0]) csv_cols_[k] = col, found |= 1 << k;
        if (fe - fb == 13 && std::strncmp(fb, "temperature_c", 13) == 0) csv_temperature_col_ = col;
        f = c + 1;
      }
      if (found != 63) fail_at("stdin", line_no_, "CSV header needs the columns x,y,z,a,b,c");
      csv_header_seen_ = true;
      const char hdr[] = "q1,q2,q3,q4,q5,q6";
      if (cap < sizeof hdr) fail_at("stdin", line_no_, "output buffer too small");
      std::memcpy(out, hdr, sizeof hdr - 1);
      return sizeof hdr - 1;
    }
    Pose6 p;
    double vals[7];
    vals[6] = std::numeric_limits<double>::quiet_NaN();
    int got = 0, col = 0;
    for (const char* f = b; f <= e; ++col) {
      const char* c = f;
      while (c < e && *c != ',') ++c;
      for (int k = 0; k < 7; ++k) {
        if (k < 6 ? csv_cols_[k] != col : csv_temperature_col_ != col) continue;
        const char* fb = f;
        const char* fe = c;
        while (fb < fe && std::isspace(static_cast<unsigned char>(*fb))) ++fb;
        while (fe > fb && std::isspace(static_cast<unsigned char>(fe[-1]))) --fe;
        bool nonfinite;
        if (!parse_double(fb, fe, vals[k], nonfinite))
          fail_at("stdin", line_no_,
                  std::string("column ") + (k < 6 ? std::string(1, "xyzabc"[k]) : std::string("temperature_c")) +
                      ": '" + std::string(fb, fe) + "' is not a " + (nonfinite ? "finite number" : "number"));
        got += k < 6;
      }
      f = c + 1;
    }
    if (got != 6) fail_at("stdin", line_no_, "a CSV pose line needs x,y,z,a,b,c");
    for (int k = 0; k < 3; ++k) p.xyz[k] = vals[k], p.abc[k] = vals[3 + k];
    return format_joints(out, cap, solve(p, vals[6]), true);
  }
  // G-code
  WordSpan spans[16];
  const int cnt = scan_gcode(s, n, false, 6, spans, 16, "stdin", line_no_);
  if (cnt == 0) {
    if (n >= cap) fail_at("stdin", line_no_, "line too long");
    std::memcpy(out, s, n);
    return n;
  }
  for (int k = 0; k < cnt; ++k) {
    (spans[k].axis < 3 ? modal_.xyz : modal_.abc)[spans[k].axis % 3] = spans[k].value;
    modal_set_[spans[k].axis] = true;
  }
  for (int k = 0; k < 6; ++k)
    if (!modal_set_[k])
      fail_at("stdin", line_no_, std::string("pose word ") + kPoseLetters[k] + " not set yet on the first motion line");
  const Vec6 q = solve(modal_, std::numeric_limits<double>::quiet_NaN());
  char cut[4096];
  size_t insert_at;
  const size_t cn = cut_spans(s, n, spans, cnt, cut, sizeof cut, insert_at, "stdin", line_no_);
  return emit_gcode_line(cut, cn, insert_at, q, out, cap);
}

}  // namespace kincal
