// kincal: FANUC LS programs (R-30iB, compiled on the controller or by maketp): /PROG, /ATTR, /MN with
// J (and, for filtered targets, L) motions, /POS with P[n] in joint form (J1..J6 deg) or XYZWPR with
// the configuration string ('N U T, t1, t4, t6'). FANUC's W, P, R are KUKA's C, B, A. Names: letters,
// digits, '_', uppercase, up to 36 characters (an R-30iA takes 8); speeds are whole numbers (%,
// mm/sec), the zone a CNT value 0..100 (0: FINE). UF 0 (world) and UT 1 (the model's tool must be
// tool 1). More targets than a file takes: NAME_1, NAME_2, ... that NAME calls.
#include "controller_writers.hpp"

#include <cmath>
#include <cstdio>

namespace kincal::ctl {

namespace {


std::string attr(const std::string& name, size_t lines) {
  return "/PROG  " + name + "\n/ATTR\nOWNER\t\t= MNEDITOR;\nCOMMENT\t\t= \"kincal\";\nPROG_SIZE\t= 0;\n"
         "FILE_NAME\t= ;\nVERSION\t\t= 0;\nLINE_COUNT\t= " + std::to_string(lines) + ";\nMEMORY_SIZE\t= 0;\n"
         "PROTECT\t\t= READ_WRITE;\nTCD:  STACK_SIZE\t= 0,\n      TASK_PRIORITY\t= 50,\n      TIME_SLICE\t= 0,\n"
         "      BUSY_LAMP_OFF\t= 0,\n      ABORT_REQUEST\t= 0,\n      PAUSE_REQUEST\t= 0;\n"
         "DEFAULT_GROUP\t= 1,*,*,*,*;\nCONTROL_CODE\t= 00000000 00000000;\n/MN\n";
}

std::string line_no(size_t n) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%4zu:  ", n);
  return buf;
}

std::string value(const char* label, double v, const char* unit) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s=%11s %s", label, fixed(v, kLsDecimals).c_str(), unit);
  return buf;
}

OutputFile program(const std::string& path, const std::string& name, const std::vector<ControllerTarget>& t, size_t b,
                   size_t e, const WriterOptions& o, bool last_part) {
  const bool filtered = o.targets == TargetKind::Filtered;
  const double zone = zone_of(o);
  if (zone > 100) throw InputError("--zone: a FANUC zone is a CNT value 0..100");
  const long pct = std::lround(joint_speed_pct(o));
  const long mm_s = std::lround(linear_speed_mm_s(o));
  std::string mn, pos;
  for (size_t i = b; i < e; ++i) {
    const size_t n = i - b + 1;
    const std::string term = zone > 0 && !(last_part && i + 1 == e) ? "CNT" + std::to_string(std::lround(zone)) : "FINE";
    if (filtered && i > 0)
      mn += line_no(n) + "L P[" + std::to_string(n) + "] " + std::to_string(mm_s) + "mm/sec " + term + "    ;\n";
    else
      mn += line_no(n) + "J P[" + std::to_string(n) + "] " + std::to_string(std::max(1L, pct)) + "% " + term + "    ;\n";
    pos += "P[" + std::to_string(n) + "]{\n   GP1:\n\tUF : 0, UT : 1,";
    if (!filtered) {
      pos += "\n";
      for (int j = 0; j < 6; ++j) {
        const std::string lab = "J" + std::to_string(j + 1);
        pos += std::string(j % 3 == 0 ? "\t" : ",\t") + value(lab.c_str(), t[i].q_deg[j], "deg");
        if (j == 2) pos += ",\n";
      }
      pos += "\n};\n";
    } else {
      pos += "\t\tCONFIG : '" + t[i].fanuc_config + "',\n";
      pos += "\t" + value("X ", t[i].pose.xyz[0], " mm") + ",\t" + value("Y ", t[i].pose.xyz[1], " mm") + ",\t" +
             value("Z ", t[i].pose.xyz[2], " mm") + ",\n";
      pos += "\t" + value("W ", t[i].pose.abc[2], "deg") + ",\t" + value("P ", t[i].pose.abc[1], "deg") + ",\t" +
             value("R ", t[i].pose.abc[0], "deg") + "\n};\n";
    }
  }
  return {path, attr(name, e - b) + mn + "/POS\n" + pos + "/END\n"};
}

}  // namespace

std::vector<OutputFile> write_fanuc_ls(const std::string& out, const std::vector<ControllerTarget>& t,
                                       const WriterOptions& o, const std::string& name) {
  const auto ranges = parts(t.size(), o.max_targets_per_file > 0 ? o.max_targets_per_file : controller_max_targets(o.format));
  if (ranges.size() == 1) return {program(out, name, t, 0, t.size(), o, true)};
  check_name(name + "_" + std::to_string(ranges.size()), 36, "FANUC LS");
  std::vector<OutputFile> files(1);
  std::string mn;
  for (size_t p = 0; p < ranges.size(); ++p) {
    const std::string part = name + "_" + std::to_string(p + 1);
    mn += line_no(p + 1) + "CALL " + part + "    ;\n";
    files.push_back(program(dir_of(out) + part + ".ls", part, t, ranges[p].first, ranges[p].second, o,
                            p + 1 == ranges.size()));
  }
  files[0] = {out, attr(name, ranges.size()) + mn + "/POS\n/END\n"};
  return files;
}

}  // namespace kincal::ctl
