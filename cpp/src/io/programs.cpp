#include "kincal/io/programs.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/gcode.hpp"

#include <cstdio>
#include <cstring>
#include <sstream>

namespace kincal {

namespace {

void parse_joint_csv(const std::string& text, JointProgram& p) {
  const CsvTable t = parse_csv(text, p.source);
  std::vector<int> col;
  for (int j = 0; j < p.dof; ++j) col.push_back(t.require("q" + std::to_string(j + 1)));
  if (t.find("q" + std::to_string(p.dof + 1)) >= 0)
    throw InputError(p.source + ":1: column q" + std::to_string(p.dof + 1) + " but the robot has " +
                     std::to_string(p.dof) + " joints");
  for (size_t r = 0; r < t.cells.size(); ++r) {
    std::vector<double> q(p.dof);
    for (int j = 0; j < p.dof; ++j) q[j] = t.number(r, col[j]);
    p.q.push_back(q);
    p.line.push_back(t.line[r]);
  }
}

void parse_joint_gcode(const std::string& text, JointProgram& p) {
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  std::vector<double> modal(p.dof, 0.0);
  std::vector<bool> set(p.dof, false);
  GcodeWord words[kMaxJoints * 2];
  while (std::getline(in, raw)) {
    ++line;
    const int n =
        scan_gcode(raw.data(), raw.size(), GcodeWords::Joint, p.dof, words, kMaxJoints * 2, p.source.c_str(), line);
    if (n == 0) continue;
    for (int k = 0; k < n; ++k) {
      modal[words[k].axis] = words[k].value;
      set[words[k].axis] = true;
    }
    for (int j = 0; j < p.dof; ++j)
      if (!set[j]) fail_at(p.source.c_str(), line, "joint word A" + std::to_string(j + 1) + "= not set yet");
    p.q.push_back(modal);
    p.line.push_back(line);
  }
}

}  // namespace

ProgramFormat program_format(const std::string& path) {
  return is_csv_path(path) ? ProgramFormat::Csv : ProgramFormat::Gcode;
}

namespace {
constexpr const char* kPoseColumns[6] = {"x", "y", "z", "a", "b", "c"};
}  // namespace

PoseProgramReader::PoseProgramReader(const std::string& path, size_t chunk_bytes)
    : source_(path), format_(program_format(path)) {
  if (format_ == ProgramFormat::Csv) {
    csv_ = std::make_unique<CsvReader>(path, chunk_bytes);
  } else {
    text_ = std::make_unique<TextChunks>(path, chunk_bytes);
  }
  if (csv_) {
    for (int k = 0; k < 6; ++k) {
      const std::string e = csv_->missing(kPoseColumns[k], cols_[k]);
      if (!e.empty()) fail_after_rest(e);
    }
    temperature_col_ = csv_->find("temperature_c");
  }
}

PoseProgramReader::PoseProgramReader(std::string text, const std::string& source, ProgramFormat format)
    : source_(source), format_(format) {
  if (format_ == ProgramFormat::Csv) {
    csv_ = std::make_unique<CsvReader>(std::move(text), source);
    for (int k = 0; k < 6; ++k) {
      const std::string e = csv_->missing(kPoseColumns[k], cols_[k]);
      if (!e.empty()) fail_after_rest(e);
    }
    temperature_col_ = csv_->find("temperature_c");
  } else {
    text_ = std::make_unique<TextChunks>(std::move(text));
  }
}

// An error that comes after the broken rows of the whole file (CSV: a missing column, a cell that is not
// a number): the rest of the file is read first, and its first broken row is the error.
void PoseProgramReader::fail_after_rest(const std::string& error) {
  if (csv_)
    while (csv_->next()) {
    }
  throw InputError(error);
}

bool PoseProgramReader::next(ProgramLine& l) { return csv_ ? next_csv(l) : next_gcode(l); }

void PoseProgramReader::rest() {
  ProgramLine l;
  while (next(l)) {
  }
}

bool PoseProgramReader::next_csv(ProgramLine& l) {
  if (!csv_->next()) {
    if (poses_ == 0) throw InputError(source_ + ": the program has no poses");
    return false;
  }
  std::string error;
  double v[7];
  for (int k = 0; k < 6 && error.empty(); ++k) v[k] = csv_->number(cols_[k], &error);
  v[6] = temperature_col_ >= 0 && error.empty() ? csv_->number(temperature_col_, &error)
                                                : std::numeric_limits<double>::quiet_NaN();
  if (!error.empty()) fail_after_rest(error);
  l.has_pose = true;
  l.pose.xyz = Vec3(v[0], v[1], v[2]);
  l.pose.abc = Vec3(v[3], v[4], v[5]);
  l.temperature_c = v[6];
  l.line = csv_->line();
  ++poses_;
  return true;
}

// The lines as lines_with_ends would split the whole text: each without its end, and its end: "\n",
// "\r\n", or for a last line without a newline "" (or "\r").
bool PoseProgramReader::next_gcode(ProgramLine& l) {
  if (pos_ >= text_->limit() && !text_->more(pos_)) {
    if (poses_ == 0) throw InputError(source_ + ": the program has no poses (no X Y Z A B C words)");
    return false;
  }
  const char* b = text_->data() + pos_;
  const char* end = text_->data() + text_->limit();
  const char* e = static_cast<const char*>(std::memchr(b, '\n', static_cast<size_t>(end - b)));
  const bool nl = e != nullptr;
  if (!nl) e = end;
  const bool cr = e > b && e[-1] == '\r';
  const size_t n = static_cast<size_t>(e - b) - (cr ? 1 : 0);
  l.eol.assign(cr ? "\r" : "");
  if (nl) l.eol += '\n';
  pos_ = static_cast<size_t>(e - text_->data()) + (nl ? 1 : 0);
  ++line_;
  l.line = line_;
  l.temperature_c = std::numeric_limits<double>::quiet_NaN();
  GcodeWord words[16];
  const int cnt = scan_gcode(b, n, GcodeWords::Pose, 6, words, 16, source_.c_str(), line_);
  if (cnt == 0) {
    l.has_pose = false;
    l.text.assign(b, n);
    l.insert_at = 0;
    return true;
  }
  for (int k = 0; k < cnt; ++k) {
    (words[k].axis < 3 ? modal_.xyz : modal_.abc)[words[k].axis % 3] = words[k].value;
    set_[words[k].axis] = true;
  }
  std::string missing;
  for (int k = 0; k < 6; ++k)
    if (!set_[k]) missing += std::string(missing.empty() ? "" : " ") + kPoseLetters[k];
  if (!missing.empty())
    fail_at(source_.c_str(), line_, "pose word(s) " + missing + " not set yet on the first motion line");
  char buf[4096];
  const CutLine cut = cut_words(b, n, words, cnt, buf, sizeof buf, source_.c_str(), line_);
  l.has_pose = true;
  l.pose = modal_;
  l.text.assign(buf, cut.size);
  l.insert_at = cut.insert_at;
  ++poses_;
  return true;
}

PoseProgram parse_pose_program(const std::string& text, const std::string& source, ProgramFormat format) {
  PoseProgramReader rd(text, source, format);
  PoseProgram p;
  p.source = source;
  p.format = format;
  ProgramLine l;
  bool first = true;
  while (rd.next(l)) {
    if (format == ProgramFormat::Gcode) {
      if (first) p.eol = l.eol == "\r\n" ? "\r\n" : "\n";
      first = false;
      p.final_newline = !l.eol.empty() && l.eol.back() == '\n';
      p.lines.push_back({l.text, l.insert_at, l.has_pose ? static_cast<int>(p.poses.size()) : -1, l.eol});
    }
    if (!l.has_pose) continue;
    p.poses.push_back(l.pose);
    p.pose_line.push_back(l.line);
    if (rd.has_temperature()) p.temperature_c.push_back(l.temperature_c);
  }
  return p;
}

PoseProgram read_pose_program(const std::string& path) {
  return parse_pose_program(read_text_file(path), path, program_format(path));
}

JointProgram parse_joint_program(const std::string& text, const std::string& source, ProgramFormat format, int dof) {
  JointProgram p;
  p.source = source;
  p.dof = dof;
  if (format == ProgramFormat::Csv)
    parse_joint_csv(text, p);
  else
    parse_joint_gcode(text, p);
  if (p.q.empty()) throw InputError(source + ": the joint program has no motion lines");
  return p;
}

JointProgram read_joint_program(const std::string& path, int dof) {
  return parse_joint_program(read_text_file(path), path, program_format(path), dof);
}

size_t format_joints(char* out, size_t cap, const Vec6& q, ProgramFormat format) {
  const bool csv = format == ProgramFormat::Csv;
  size_t len = 0;
  for (int j = 0; j < 6; ++j) {
    const int w = csv ? std::snprintf(out + len, cap - len, j ? ",%.10f" : "%.10f", q[j])
                      : std::snprintf(out + len, cap - len, j ? " A%d=%.10f" : "A%d=%.10f", j + 1, q[j]);
    if (w < 0 || static_cast<size_t>(w) >= cap - len) throw InputError("output line too long");
    len += static_cast<size_t>(w);
  }
  return len;
}

std::string format_joint_program(const PoseProgram& in, const std::vector<Vec6>& q_deg, ProgramFormat format) {
  std::string out;
  char buf[512];
  if (format == ProgramFormat::Csv) {
    out = "q1,q2,q3,q4,q5,q6\n";
    for (const Vec6& q : q_deg) {
      out.append(buf, format_joints(buf, sizeof buf, q, ProgramFormat::Csv));
      out += '\n';
    }
    return out;
  }
  if (in.format != ProgramFormat::Gcode) {
    for (const Vec6& q : q_deg) {
      out += "G1 ";
      out.append(buf, format_joints(buf, sizeof buf, q, ProgramFormat::Gcode));
      out += '\n';
    }
    return out;
  }
  for (size_t i = 0; i < in.lines.size(); ++i) {
    const PoseProgram::Line& l = in.lines[i];
    if (l.pose < 0) {
      out += l.text;
    } else {
      char line[8192];
      out.append(line, emit_gcode_line(l.text.data(), l.text.size(), l.insert_at,
                                       q_deg[static_cast<size_t>(l.pose)], line, sizeof line));
    }
    // each line keeps its own end; a line without one (inserted after reading) takes the program's,
    // but for the last line of a file that ends without a newline
    const bool last = i + 1 == in.lines.size();
    out += !l.eol.empty() ? l.eol : (last && !in.final_newline) ? std::string() : in.eol;
  }
  return out;
}

}  // namespace kincal
