// kincal: a measurement campaign (the commanded joint angles of every row and the point, or the
// full pose, of a target measured in the instrument's frame) and its CSV file: pose, q1..qN, x, y,
// z, optional a, b, c (the tool frame's orientation), target, payload_kg, temperature_c, dir1..dirN,
// time_s (when the point was measured), config (rows repeating one configuration share its value)
// and setup (one instrument placement per value). config and setup are any text; a row carries the
// code of its value (codes in order of first appearance, the names in the set).
#pragma once

#include "kincal/core/types.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace kincal {

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
  /// Number of instrument placements (1 without a setup column).
  int n_setups() const { return setup_names.empty() ? 1 : static_cast<int>(setup_names.size()); }
  /// Whether the rows carry the time they were measured (a time_s column).
  bool has_time() const { return !rows.empty() && !std::isnan(rows[0].time_s); }
};

/// Read the measurement CSV of the contract (pose, q1..qN, x, y, z and the optional columns above).
MeasurementSet read_measurements(const std::string& path, int dof);
MeasurementSet parse_measurements(const std::string& text, const std::string& source, int dof);
std::string format_measurements(const MeasurementSet& m, int dof);

struct ModelSpec;
/// The rows' joint angles, read as the controller numbers them, turned into the model's (its joint
/// convention: kincal/model/joint_convention.hpp); nothing for a model with its own convention.
void measurements_from_controller(MeasurementSet& m, const ModelSpec& spec);

}  // namespace kincal
