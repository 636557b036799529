// kincal: the controller program formats: choosing one, the shared helpers, and the dispatch to the
// writers of each language (krl.cpp, rapid.cpp, fanuc_ls.cpp, urscript.cpp; CSV and G-code here).
#include "controller_writers.hpp"

#include "kincal/io/file.hpp"
#include "kincal/io/gcode.hpp"
#include "kincal/io/programs.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace kincal {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool ends_with(const std::string& s, const std::string& e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

}  // namespace

TargetKind target_kind_named(const std::string& name) {
  if (name == "joints") return TargetKind::Joints;
  if (name == "filtered") return TargetKind::Filtered;
  throw InputError("--targets " + name + ": joints or filtered");
}

ControllerFormat controller_format_named(const std::string& name) {
  const std::string n = lower(name);
  if (n == "krl") return ControllerFormat::Krl;
  if (n == "rapid") return ControllerFormat::Rapid;
  if (n == "fanuc-ls" || n == "ls") return ControllerFormat::FanucLs;
  if (n == "urscript") return ControllerFormat::UrScript;
  if (n == "gcode") return ControllerFormat::Gcode;
  if (n == "csv") return ControllerFormat::Csv;
  throw InputError("--format " + name + ": not a format (krl, rapid, fanuc-ls, urscript, gcode, csv)");
}

ControllerFormat controller_format_of_path(const std::string& path) {
  const std::string p = lower(path);
  if (ends_with(p, ".src") || ends_with(p, ".dat")) return ControllerFormat::Krl;
  if (ends_with(p, ".mod") || ends_with(p, ".modx") || ends_with(p, ".sys")) return ControllerFormat::Rapid;
  if (ends_with(p, ".ls")) return ControllerFormat::FanucLs;
  if (ends_with(p, ".script")) return ControllerFormat::UrScript;
  if (ends_with(p, ".csv")) return ControllerFormat::Csv;
  return ControllerFormat::Gcode;
}

const char* format_name(ControllerFormat f) {
  switch (f) {
    case ControllerFormat::Krl: return "krl";
    case ControllerFormat::Rapid: return "rapid";
    case ControllerFormat::FanucLs: return "fanuc-ls";
    case ControllerFormat::UrScript: return "urscript";
    case ControllerFormat::Gcode: return "gcode";
    case ControllerFormat::Csv: return "csv";
  }
  return "?";
}

int controller_max_targets(ControllerFormat f) {
  // kincal's own conservative sizes per file (the controllers' memory decides the real ones)
  if (f == ControllerFormat::Krl) return 2000;
  if (f == ControllerFormat::FanucLs) return 2000;
  return 0;
}

namespace ctl {

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) throw InputError("a target value is not a finite number");
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s(buf);
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // no "-0.000"
  return s;
}

double joint_speed_pct(const WriterOptions& o) {
  if (std::isnan(o.speed)) return 20.0;
  if (!(o.speed > 0 && o.speed <= 100)) throw InputError("--speed: a joint motion's speed is a percentage in (0, 100]");
  return o.speed;
}

double linear_speed_mm_s(const WriterOptions& o) {
  if (std::isnan(o.speed)) return 250.0;
  if (!(o.speed > 0 && o.speed <= 10000)) throw InputError("--speed: a linear motion's speed is in mm/s, in (0, 10000]");
  return o.speed;
}

double zone_of(const WriterOptions& o) {
  if (std::isnan(o.zone)) return 0.0;
  if (!(o.zone >= 0 && std::isfinite(o.zone))) throw InputError("--zone must be a number >= 0");
  return o.zone;
}

std::string dir_of(const std::string& path) {
  const size_t s = path.find_last_of('/');
  return s == std::string::npos ? std::string() : path.substr(0, s + 1);
}

std::string stem_of(const std::string& path) {
  const std::string f = path.substr(dir_of(path).size());
  const size_t d = f.find_last_of('.');
  return d == std::string::npos || d == 0 ? f : f.substr(0, d);
}

std::string with_ext(const std::string& path, const std::string& ext) { return dir_of(path) + stem_of(path) + ext; }

void check_name(const std::string& name, size_t max_len, const char* language) {
  const std::string head = std::string(language) + " program name '" + name + "': ";
  if (name.empty()) throw InputError(head + "empty (give --name)");
  if (!std::isalpha(static_cast<unsigned char>(name[0]))) throw InputError(head + "must start with a letter (give --name)");
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      throw InputError(head + "only letters, digits and '_' are allowed (give --name)");
  if (name.size() > max_len)
    throw InputError(head + "longer than the " + std::to_string(max_len) + " characters the controller takes");
}

std::vector<std::pair<size_t, size_t>> parts(size_t n, int max) {
  std::vector<std::pair<size_t, size_t>> r;
  if (max <= 0 || n <= static_cast<size_t>(max)) return {{0, n}};
  for (size_t b = 0; b < n; b += static_cast<size_t>(max)) r.emplace_back(b, std::min(n, b + static_cast<size_t>(max)));
  return r;
}

std::array<double, 4> quaternion_of(const Vec3& abc) {
  Eigen::Quaterniond q(pose_to_iso(Pose6{Vec3::Zero(), abc}).linear());
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return {{q.w(), q.x(), q.y(), q.z()}};
}

Vec3 rotation_vector_of(const Vec3& abc) {
  const Eigen::AngleAxisd aa(pose_to_iso(Pose6{Vec3::Zero(), abc}).linear());
  return aa.axis() * aa.angle();
}

}  // namespace ctl

std::string controller_program_name(const std::string& out_path, const WriterOptions& opt) {
  std::string name = opt.name.empty() ? ctl::stem_of(out_path) : opt.name;
  switch (opt.format) {
    case ControllerFormat::Krl:
      if (lower(name) != lower(ctl::stem_of(out_path)))
        throw InputError("KRL program name '" + name + "': a KRL module is named by its files: write it to " +
                         name + ".src");
      ctl::check_name(name, 24, "KRL");
      break;
    case ControllerFormat::Rapid: ctl::check_name(name, 32, "RAPID"); break;
    case ControllerFormat::FanucLs:
      for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      ctl::check_name(name, 36, "FANUC LS");
      break;
    case ControllerFormat::UrScript: ctl::check_name(name, 64, "URScript"); break;
    default: break;
  }
  return name;
}

std::vector<OutputFile> write_controller_program(const std::string& out, const std::vector<ControllerTarget>& t,
                                                 const WriterOptions& o) {
  if (t.empty()) throw InputError(out + ": no targets to write");
  const std::string name = controller_program_name(out, o);
  switch (o.format) {
    case ControllerFormat::Krl: return ctl::write_krl(out, t, o, name);
    case ControllerFormat::Rapid: return ctl::write_rapid(out, t, o, name);
    case ControllerFormat::FanucLs: return ctl::write_fanuc_ls(out, t, o, name);
    case ControllerFormat::UrScript: return ctl::write_urscript(out, t, o, name);
    default: break;
  }
  const bool csv = o.format == ControllerFormat::Csv;
  std::string text;
  if (o.targets == TargetKind::Joints) {
    char buf[512];
    text = csv ? "q1,q2,q3,q4,q5,q6\n" : "";
    for (const ControllerTarget& x : t) {
      if (!csv) text += "G1 ";
      text.append(buf, format_joints(buf, sizeof buf, x.q_deg, csv ? ProgramFormat::Csv : ProgramFormat::Gcode));
      text += '\n';
    }
  } else {
    text = csv ? "x,y,z,a,b,c\n" : "";
    for (const ControllerTarget& x : t) {
      const double v[6] = {x.pose.xyz[0], x.pose.xyz[1], x.pose.xyz[2], x.pose.abc[0], x.pose.abc[1], x.pose.abc[2]};
      for (int k = 0; k < 6; ++k) {
        if (csv)
          text += (k ? "," : "") + ctl::fixed(v[k], 10);
        else
          text += std::string(k ? " " : "G1 ") + kPoseLetters[k] + ctl::fixed(v[k], 10);
      }
      text += '\n';
    }
  }
  return {{out, text}};
}

void write_files_atomic(const std::vector<OutputFile>& files) {
  for (size_t i = 0; i < files.size(); ++i) {
    try {
      write_file_atomic(files[i].path, files[i].text);
    } catch (...) {
      for (size_t k = 0; k < i; ++k) std::remove(files[k].path.c_str());
      throw;
    }
  }
}

}  // namespace kincal
