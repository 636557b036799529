#include "kincal/io/programs.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/gcode.hpp"

#include <cstdio>
#include <sstream>

namespace kincal {

namespace {

PoseProgram parse_pose_csv(const std::string& text, const std::string& source) {
  PoseProgram p;
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

// The text's lines without their ends, and each one's end: "\n", "\r\n", or for a last line without a
// newline "" (or "\r").
std::vector<std::pair<std::string, std::string>> lines_with_ends(const std::string& text) {
  std::vector<std::pair<std::string, std::string>> out;
  for (size_t b = 0; b < text.size();) {
    size_t e = text.find('\n', b);
    const bool nl = e != std::string::npos;
    if (!nl) e = text.size();
    const bool cr = e > b && text[e - 1] == '\r';
    out.emplace_back(text.substr(b, e - b - (cr ? 1 : 0)), std::string(cr ? "\r" : "") + (nl ? "\n" : ""));
    b = e + 1;
  }
  return out;
}

PoseProgram parse_pose_gcode(const std::string& text, const std::string& source) {
  PoseProgram p;
  int line = 0;
  Pose6 modal;
  bool set[6] = {false, false, false, false, false, false};
  GcodeWord words[16];
  const auto split = lines_with_ends(text);
  if (!split.empty()) {
    p.eol = split[0].second == "\r\n" ? "\r\n" : "\n";
    p.final_newline = !split.back().second.empty() && split.back().second.back() == '\n';
  }
  for (const auto& [raw, eol] : split) {
    ++line;
    const int n = scan_gcode(raw.data(), raw.size(), GcodeWords::Pose, 6, words, 16, source.c_str(), line);
    PoseProgram::Line l;
    l.eol = eol;
    if (n == 0) {
      l.text = raw;
      p.lines.push_back(std::move(l));
      continue;
    }
    for (int k = 0; k < n; ++k) {
      (words[k].axis < 3 ? modal.xyz : modal.abc)[words[k].axis % 3] = words[k].value;
      set[words[k].axis] = true;
    }
    std::string missing;
    for (int k = 0; k < 6; ++k)
      if (!set[k]) missing += std::string(missing.empty() ? "" : " ") + kPoseLetters[k];
    if (!missing.empty()) fail_at(source.c_str(), line, "pose word(s) " + missing + " not set yet on the first motion line");
    char buf[4096];
    const CutLine cut = cut_words(raw.data(), raw.size(), words, n, buf, sizeof buf, source.c_str(), line);
    l.text.assign(buf, cut.size);
    l.insert_at = cut.insert_at;
    l.pose = static_cast<int>(p.poses.size());
    p.poses.push_back(modal);
    p.pose_line.push_back(line);
    p.lines.push_back(std::move(l));
  }
  if (p.poses.empty()) throw InputError(source + ": the program has no poses (no X Y Z A B C words)");
  return p;
}

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

PoseProgram parse_pose_program(const std::string& text, const std::string& source, ProgramFormat format) {
  PoseProgram p = format == ProgramFormat::Csv ? parse_pose_csv(text, source) : parse_pose_gcode(text, source);
  p.source = source;
  p.format = format;
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
