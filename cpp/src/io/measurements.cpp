// kincal: the measurement CSV reader and writer (the columns in measurements.hpp).
#include "kincal/model/joint_convention.hpp"
#include "kincal/io/measurements.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kincal {

const char* to_string(MeasureKind kind) {
  switch (kind) {
    case MeasureKind::point: return "point";
    case MeasureKind::pose: return "pose";
    case MeasureKind::sphere: return "sphere";
    case MeasureKind::plane: return "plane";
    case MeasureKind::distance: return "distance";
  }
  return "?";
}

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

/// The kind of a row from its kind cell (empty: point, or pose with a, b, c).
MeasureKind kind_of(const CsvTable& t, size_t r, int ckind, bool has_abc) {
  const std::string v = ckind >= 0 ? t.cells[r][static_cast<size_t>(ckind)] : std::string();
  if (v.empty()) return has_abc ? MeasureKind::pose : MeasureKind::point;
  for (MeasureKind k : {MeasureKind::point, MeasureKind::pose, MeasureKind::sphere, MeasureKind::plane,
                        MeasureKind::distance})
    if (v == to_string(k)) {
      if (k == MeasureKind::pose && !has_abc) throw InputError(t.where(r) + ": kind 'pose' needs a, b, c");
      if (k == MeasureKind::point && has_abc) throw InputError(t.where(r) + ": kind 'point' with a, b, c (a pose?)");
      if (is_probe(k) && has_abc) throw InputError(t.where(r) + ": a " + v + " row has no a, b, c");
      return k;
    }
  throw InputError(t.where(r) + ": column 'kind': '" + v + "' is none of point, pose, sphere, plane, distance");
}

/// Whether every cell of the columns (those present) of row r is empty.
bool cells_empty(const CsvTable& t, size_t r, std::initializer_list<int> cols) {
  for (int c : cols)
    if (c >= 0 && !t.cells[r][static_cast<size_t>(c)].empty()) return false;
  return true;
}

/// A probe row's station, radius and length into row (m: the set's stations by code and kind).
void read_probe(const CsvTable& t, size_t r, int cstation, int cradius, int clength, Measurement& row,
                MeasurementSet& m) {
  const std::string kind = to_string(row.kind);
  if (cstation < 0) throw InputError(t.where(r) + ": a " + kind + " row needs the column 'station'");
  row.station = code_of(text_cell(t, r, cstation), m.station_names);
  if (m.station_kinds.size() < m.station_names.size()) m.station_kinds.push_back(row.kind);
  if (m.station_kinds[static_cast<size_t>(row.station)] != row.kind)
    throw InputError(t.where(r) + ": station '" + m.station_names[static_cast<size_t>(row.station)] + "' is a " +
                     to_string(m.station_kinds[static_cast<size_t>(row.station)]) + " station, this row a " + kind);
  if (cradius >= 0 && !t.cells[r][static_cast<size_t>(cradius)].empty()) {
    if (row.kind != MeasureKind::plane) throw InputError(t.where(r) + ": a radius on a " + kind + " row (planes only)");
    row.radius_mm = t.number(r, cradius);
    if (row.radius_mm < 0) throw InputError(t.where(r) + ": column 'radius': negative");
  }
  const bool has_length = clength >= 0 && !t.cells[r][static_cast<size_t>(clength)].empty();
  if (row.kind == MeasureKind::distance) {
    if (!has_length) throw InputError(t.where(r) + ": a distance row needs its 'length' (mm)");
    row.length_mm = t.number(r, clength);
    if (row.length_mm <= 0) throw InputError(t.where(r) + ": column 'length': not positive");
  } else if (has_length) {
    throw InputError(t.where(r) + ": a length on a " + kind + " row (distance rows only)");
  }
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
  const int ckind = t.find("kind"), cstation = t.find("station"), cradius = t.find("radius"), clength = t.find("length");
  // probe rows have no x, y, z: the columns are needed only by a file with points or poses
  const int cx = t.find("x"), cy = t.find("y"), cz = t.find("z");
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
    const bool row_abc = abc && !cells_empty(t, r, {ca, cb, cc});
    row.kind = kind_of(t, r, ckind, row_abc);
    if (is_probe(row.kind)) {
      if (!cells_empty(t, r, {cx, cy, cz}))
        throw InputError(t.where(r) + ": a " + std::string(to_string(row.kind)) + " row has no x, y, z (leave them empty)");
      read_probe(t, r, cstation, cradius, clength, row, m);
    } else {
      for (const char* c : {"x", "y", "z"}) t.require(c);
      row.xyz = Vec3(t.number(r, cx), t.number(r, cy), t.number(r, cz));
      if (cstation >= 0 && !t.cells[r][static_cast<size_t>(cstation)].empty())
        throw InputError(t.where(r) + ": a station on a " + std::string(to_string(row.kind)) + " row (probe rows only)");
    }
    if (abc && !is_probe(row.kind)) {
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
  const bool probe = m.has_probe();
  if (probe) s += ",kind,station,radius,length";
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
    for (int k = 0; k < 3; ++k) s += is_probe(r.kind) ? "," : "," + fmt(r.xyz[k]);
    if (m.orientation)
      for (int k = 0; k < 3; ++k) s += r.has_abc ? "," + fmt(r.abc[k]) : ",";
    s += "," + std::to_string(r.target);
    if (probe) {
      s += std::string(",") + to_string(r.kind) + ",";
      if (r.station >= 0) s += m.station_names.at(static_cast<size_t>(r.station));
      s += r.kind == MeasureKind::plane ? "," + fmt(r.radius_mm) : ",";
      s += r.kind == MeasureKind::distance ? "," + fmt(r.length_mm) : ",";
    }
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

void parse_artifact(const std::string& text, const std::string& source, MeasurementSet& m) {
  const CsvTable t = parse_csv(text, source);
  const int ca = t.require("a"), cb = t.require("b"), cd = t.find("distance_mm"), cg = t.find("angle_deg");
  if (cd < 0 && cg < 0) throw InputError(source + ":1: an artifact needs the column distance_mm or angle_deg");
  std::vector<ArtifactTerm> terms;
  for (size_t r = 0; r < t.cells.size(); ++r) {
    ArtifactTerm a;
    a.where = t.where(r);
    int codes[2];
    for (int k = 0; k < 2; ++k) {
      const std::string& name = text_cell(t, r, k == 0 ? ca : cb);
      const auto it = std::find(m.station_names.begin(), m.station_names.end(), name);
      if (it == m.station_names.end())
        throw InputError(a.where + ": station '" + name + "' is in no row of " + (m.source.empty() ? "the data" : m.source));
      codes[k] = static_cast<int>(it - m.station_names.begin());
    }
    a.a = codes[0];
    a.b = codes[1];
    if (a.a == a.b) throw InputError(a.where + ": a station with itself");
    const bool d = cd >= 0 && !t.cells[r][static_cast<size_t>(cd)].empty();
    const bool g = cg >= 0 && !t.cells[r][static_cast<size_t>(cg)].empty();
    if (d == g) throw InputError(a.where + ": give one of distance_mm and angle_deg, the other empty");
    const MeasureKind ka = m.station_kinds[static_cast<size_t>(a.a)], kb = m.station_kinds[static_cast<size_t>(a.b)];
    if (d) {
      a.distance_mm = t.number(r, cd);
      if (a.distance_mm <= 0) throw InputError(a.where + ": distance_mm: not positive");
      // between two points (sphere centres, ballbar pivots) or two planes
      if ((ka == MeasureKind::plane) != (kb == MeasureKind::plane))
        throw InputError(a.where + ": a distance between a " + to_string(ka) + " and a " + to_string(kb) + " station");
    } else {
      a.angle_deg = t.number(r, cg);
      if (a.angle_deg < 0 || a.angle_deg > 90) throw InputError(a.where + ": angle_deg: expected 0 to 90");
      if (ka != MeasureKind::plane || kb != MeasureKind::plane) throw InputError(a.where + ": an angle between stations that are not both planes");
    }
    terms.push_back(a);
  }
  m.artifact = std::move(terms);
}

void read_artifact(const std::string& path, MeasurementSet& m) { parse_artifact(read_text_file(path), path, m); }

MeasurementSet without_rows(const MeasurementSet& m) {
  MeasurementSet out;
  out.source = m.source;
  out.n_targets = m.n_targets;
  out.orientation = m.orientation;
  out.config_names = m.config_names;
  out.setup_names = m.setup_names;
  out.station_names = m.station_names;
  out.station_kinds = m.station_kinds;
  out.artifact = m.artifact;
  return out;
}

MeasurementSet subset(const MeasurementSet& m, const std::vector<size_t>& rows) {
  MeasurementSet out = without_rows(m);
  out.n_targets = 1;
  out.orientation = false;
  out.rows.reserve(rows.size());
  for (size_t i : rows) {
    const Measurement& r = m.rows.at(i);
    out.rows.push_back(r);
    out.n_targets = std::max(out.n_targets, r.target + 1);
    out.orientation = out.orientation || r.has_abc;
  }
  return out;
}

std::string format_artifact(const MeasurementSet& m) {
  std::string s = "a,b,distance_mm,angle_deg\n";
  for (const ArtifactTerm& a : m.artifact) {
    s += m.station_names.at(static_cast<size_t>(a.a)) + "," + m.station_names.at(static_cast<size_t>(a.b)) + ",";
    s += std::isnan(a.distance_mm) ? "," + fmt(a.angle_deg) : fmt(a.distance_mm) + ",";
    s += "\n";
  }
  return s;
}

void measurements_from_controller(MeasurementSet& m, const ModelSpec& spec) {
  if (spec.joint_convention.empty()) return;
  for (Measurement& r : m.rows) joints_from_controller(spec, r.q_deg.data(), static_cast<int>(r.q_deg.size()));
}

}  // namespace kincal
