// kincal: a measurement campaign (the commanded joint angles of every row and the point, or the
// full pose, of a target measured in the instrument's frame) and its CSV file: pose, q1..qN, x, y,
// z, optional a, b, c (the tool frame's orientation), target, payload_kg, temperature_c, dir1..dirN,
// time_s (when the point was measured), config (rows repeating one configuration share its value)
// and setup (one instrument placement per value). config and setup are any text; a row carries the
// code of its value (codes in order of first appearance, the names in the set).
// Measurements without a tracker (the contract's "kind" column): a probe row names its station and
// has no x, y, z: `sphere` (the probe's ball centre was at the station's unknown fixed point),
// `plane` (the ball touched the station's unknown plane; `radius`: the ball centre is that far off
// the plane on the flange's side), `distance` (a ballbar: the ball centre was `length` mm from the
// station's unknown pivot). A station is of one kind.
#pragma once

#include "kincal/core/types.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace kincal {

/// What a row measured: a point (x, y, z), a pose (and a, b, c), or a probe's contact at a station.
enum class MeasureKind { point, pose, sphere, plane, distance };

/// The word of a kind in the CSV's kind column ("point", "pose", "sphere", "plane", "distance").
const char* to_string(MeasureKind kind);
/// Whether a kind is a probe's (sphere, plane, distance): its row names a station, has no x, y, z.
constexpr bool is_probe(MeasureKind kind) { return kind >= MeasureKind::sphere; }

struct Measurement {
  int pose = 0;
  VecQ q_deg;
  VecQ dir;                  ///< sign of the last motion of each joint (empty: unknown)
  double temperature_c = std::numeric_limits<double>::quiet_NaN();
  Vec3 xyz = Vec3::Zero();   ///< measured point, instrument frame (mm)
  bool has_abc = false;      ///< a full 6-D pose: the tool frame's orientation was measured too
  Vec3 abc = Vec3::Zero();   ///< measured orientation of the tool frame, instrument frame (KUKA ABC, deg)
  int target = 0;
  double payload_kg = std::numeric_limits<double>::quiet_NaN();  ///< NaN: the model's payload
  int line = 0;              ///< line in the source file (0: simulated)
  double time_s = std::numeric_limits<double>::quiet_NaN();  ///< when it was measured (NaN: unknown)
  int config = -1;           ///< code of its config value (-1: no config column)
  int setup = 0;             ///< code of its instrument placement (0 without a setup column)
  MeasureKind kind = MeasureKind::point;  ///< pose when has_abc; a probe's kind with a station
  int station = -1;          ///< code of its station (probe rows; -1 for the others)
  double radius_mm = 0;      ///< plane: the ball's radius (its centre that far off the plane)
  double length_mm = std::numeric_limits<double>::quiet_NaN();  ///< distance: the ballbar's length
};

/// Known geometry between two stations (the --artifact file): the distance between two sphere or
/// pivot stations' points, or between two parallel planes; or the angle between two planes.
struct ArtifactTerm {
  int a = -1, b = -1;  ///< station codes
  double distance_mm = std::numeric_limits<double>::quiet_NaN();
  double angle_deg = std::numeric_limits<double>::quiet_NaN();
  std::string where;   ///< file:line of the term
};

struct MeasurementSet {
  std::string source;
  std::vector<Measurement> rows;
  int n_targets = 1;
  /// some row carries a measured orientation (a, b, c columns; a reflector row among 6-D rows leaves
  /// them empty: has_abc false)
  bool orientation = false;
  std::vector<std::string> config_names;  ///< the config values by code (empty: no config column)
  std::vector<std::string> setup_names;   ///< the setup values by code (empty: no setup column)
  std::vector<std::string> station_names; ///< the probe stations by code (empty: no probe rows)
  std::vector<MeasureKind> station_kinds; ///< the kind of every station
  std::vector<ArtifactTerm> artifact;     ///< known lengths and angles between stations
  /// Some row is a probe's.
  bool has_probe() const { return !station_names.empty(); }
  /// Number of instrument placements (1 without a setup column).
  int n_setups() const { return setup_names.empty() ? 1 : static_cast<int>(setup_names.size()); }
  /// Whether the rows carry the time they were measured (a time_s column).
  bool has_time() const { return !rows.empty() && !std::isnan(rows[0].time_s); }
};

/// Read the measurement CSV of the contract (pose, q1..qN, x, y, z and the optional columns above).
MeasurementSet read_measurements(const std::string& path, int dof);
MeasurementSet parse_measurements(const std::string& text, const std::string& source, int dof);
std::string format_measurements(const MeasurementSet& m, int dof);
/// Read an artifact file (a, b, distance_mm, angle_deg: one of the last two per row) into m.artifact:
/// InputError (file:line) for a station m lacks, a distance between stations of different kinds or
/// an angle between stations that are not planes, a distance or an angle out of range.
void read_artifact(const std::string& path, MeasurementSet& m);
void parse_artifact(const std::string& text, const std::string& source, MeasurementSet& m);
std::string format_artifact(const MeasurementSet& m);

/// A set's source, names, stations and artifact without its rows: what a subset of it, or a made-up
/// campaign of its kind, starts from.
MeasurementSet without_rows(const MeasurementSet& m);
/// The rows `rows` of a set (indices, in that order) with its names, stations and artifact; its
/// targets (one at least) and orientation those of the rows kept.
MeasurementSet subset(const MeasurementSet& m, const std::vector<size_t>& rows);

struct ModelSpec;
/// The rows' joint angles, read as the controller numbers them, turned into the model's (its joint
/// convention: kincal/model/joint_convention.hpp); nothing for a model with its own convention.
void measurements_from_controller(MeasurementSet& m, const ModelSpec& spec);

}  // namespace kincal
