// kincal: the measurement CSV reader and writer (the columns in measurements.hpp).
#include "kincal/model/joint_convention.hpp"
#include "kincal/io/measurements.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kincal {

namespace {

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// The code of a text value (a config or setup name): its index in names, appended when new.
int code_of(const std::string& value, std::vector<std::string>& names) {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == value) return static_cast<int>(i);
  names.push_back(value);
  return static_cast<int>(names.size()) - 1;
}

/// A non-empty text cell of a column (config, setup).
const std::string& text_cell(const CsvTable& t, size_t r, int c) {
  const std::string& v = t.cells[r][static_cast<size_t>(c)];
  if (v.empty()) throw InputError(t.where(r) + ": column '" + t.header[c] + "': empty value");
  return v;
}

MeasurementSet measurements_from_table(const CsvTable& t, int dof) {
  const std::string& source = t.source;
  MeasurementSet m;
  m.source = source;
  const int cpose = t.require("pose");
  std::vector<int> cq;
  for (int j = 0; j < dof; ++j) cq.push_back(t.require("q" + std::to_string(j + 1)));
  if (t.find("q" + std::to_string(dof + 1)) >= 0)
    throw InputError(source + ":1: column q" + std::to_string(dof + 1) + " but the robot has " +
                     std::to_string(dof) + " joints");
  const int cx = t.require("x"), cy = t.require("y"), cz = t.require("z");
  const int ca = t.find("a"), cb = t.find("b"), cc = t.find("c");
  const bool abc = ca >= 0 && cb >= 0 && cc >= 0;
  if (!abc && (ca >= 0 || cb >= 0 || cc >= 0))
    throw InputError(source + ":1: an orientation needs all three columns a, b, c");
  const int ctarget = t.find("target"), cpay = t.find("payload_kg"), ctemp = t.find("temperature_c");
  const int ctime = t.find("time_s"), cconfig = t.find("config"), csetup = t.find("setup");
  std::vector<int> cdir;
  for (int j = 0; j < dof; ++j) cdir.push_back(t.find("dir" + std::to_string(j + 1)));
  const bool have_dir = std::all_of(cdir.begin(), cdir.end(), [](int c) { return c >= 0; });
  int max_target = 0;
  for (size_t r = 0; r < t.cells.size(); ++r) {
    Measurement row;
    const double pid = t.number(r, cpose);
    if (pid != std::floor(pid)) throw InputError(t.where(r) + ": column 'pose': not an integer");
    row.pose = static_cast<int>(pid);
    row.q_deg.resize(dof);
    for (int j = 0; j < dof; ++j) row.q_deg[j] = t.number(r, cq[j]);
    row.xyz = Vec3(t.number(r, cx), t.number(r, cy), t.number(r, cz));
    if (abc) {
      // a reflector row in a file of 6-D rows leaves a, b, c empty (a point, its offset in the tool frame)
      const int empty = static_cast<int>(t.cells[r][static_cast<size_t>(ca)].empty()) +
                        static_cast<int>(t.cells[r][static_cast<size_t>(cb)].empty()) +
                        static_cast<int>(t.cells[r][static_cast<size_t>(cc)].empty());
      if (empty == 0) {
        row.has_abc = true;
        row.abc = Vec3(t.number(r, ca), t.number(r, cb), t.number(r, cc));
        m.orientation = true;
      } else if (empty < 3) {
        throw InputError(t.where(r) + ": an orientation needs all three of a, b, c (a point leaves all three empty)");
      }
    }
    if (ctarget >= 0) {
      const double tv = t.number(r, ctarget);
      if (tv < 0 || tv != std::floor(tv) || tv > 99)
        throw InputError(t.where(r) + ": column 'target': expected an integer 0..99");
      row.target = static_cast<int>(tv);
      max_target = std::max(max_target, row.target);
    }
    if (cpay >= 0) {
      row.payload_kg = t.number(r, cpay);
      if (row.payload_kg < 0) throw InputError(t.where(r) + ": column 'payload_kg': negative mass");
    }
    if (ctemp >= 0) row.temperature_c = t.number(r, ctemp);
    if (ctime >= 0) row.time_s = t.number(r, ctime);
    if (cconfig >= 0) row.config = code_of(text_cell(t, r, cconfig), m.config_names);
    if (csetup >= 0) row.setup = code_of(text_cell(t, r, csetup), m.setup_names);
    if (have_dir) {
      row.dir.resize(dof);
      for (int j = 0; j < dof; ++j) {
        row.dir[j] = t.number(r, cdir[j]);
        if (row.dir[j] != 1 && row.dir[j] != -1)
          throw InputError(t.where(r) + ": column 'dir" + std::to_string(j + 1) + "': expected +1 or -1");
      }
    }
    row.line = t.line[r];
    m.rows.push_back(row);
  }
  if (m.rows.empty()) throw InputError(source + ": no measurements");
  m.n_targets = max_target + 1;
  return m;
}

}  // namespace

MeasurementSet parse_measurements(const std::string& text, const std::string& source, int dof) {
  return measurements_from_table(parse_csv(text, source), dof);
}

MeasurementSet read_measurements(const std::string& path, int dof) {
  return measurements_from_table(read_csv(path), dof);
}

std::string format_measurements(const MeasurementSet& m, int dof) {
  std::string s = "pose";
  for (int j = 0; j < dof; ++j) s += ",q" + std::to_string(j + 1);
  s += m.orientation ? ",x,y,z,a,b,c,target" : ",x,y,z,target";
  bool pay = false;
  for (const auto& r : m.rows) pay = pay || !std::isnan(r.payload_kg);
  if (pay) s += ",payload_kg";
  const bool dir = !m.rows.empty() && m.rows[0].dir.size() == dof;
  const bool temp = !m.rows.empty() && !std::isnan(m.rows[0].temperature_c);
  if (temp) s += ",temperature_c";
  const bool time = m.has_time(), config = !m.config_names.empty(), setup = !m.setup_names.empty();
  if (time) s += ",time_s";
  if (config) s += ",config";
  if (setup) s += ",setup";
  if (dir)
    for (int j = 0; j < dof; ++j) s += ",dir" + std::to_string(j + 1);
  s += "\n";
  for (const auto& r : m.rows) {
    s += std::to_string(r.pose);
    for (int j = 0; j < dof; ++j) s += "," + fmt(r.q_deg[j]);
    for (int k = 0; k < 3; ++k) s += "," + fmt(r.xyz[k]);
    if (m.orientation)
      for (int k = 0; k < 3; ++k) s += r.has_abc ? "," + fmt(r.abc[k]) : ",";
    s += "," + std::to_string(r.target);
    if (pay) s += "," + fmt(r.payload_kg);
    if (temp) s += "," + fmt(r.temperature_c);
    if (time) s += "," + fmt(r.time_s);
    if (config) s += "," + m.config_names.at(static_cast<size_t>(r.config));
    if (setup) s += "," + m.setup_names.at(static_cast<size_t>(r.setup));
    if (dir)
      for (int j = 0; j < dof; ++j) s += r.dir[j] > 0 ? ",1" : ",-1";
    s += "\n";
  }
  return s;
}

void measurements_from_controller(MeasurementSet& m, const ModelSpec& spec) {
  if (spec.joint_convention.empty()) return;
  for (Measurement& r : m.rows) joints_from_controller(spec, r.q_deg.data(), static_cast<int>(r.q_deg.size()));
}

}  // namespace kincal
