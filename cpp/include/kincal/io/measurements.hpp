// kincal: a measurement campaign (the commanded joint angles of every row and the point, or the
// full pose, of a target measured in the instrument's frame) and its CSV file: pose, q1..qN, x, y,
// z, optional a, b, c (the tool frame's orientation), target, payload_kg, temperature_c, dir1..dirN.
#pragma once

#include "kincal/core/types.hpp"

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
};

struct MeasurementSet {
  std::string source;
  std::vector<Measurement> rows;
  int n_targets = 1;
  bool orientation = false;  ///< every row carries a measured orientation (a, b, c columns)
};

/// Read the measurement CSV of the contract (pose, q1..qN, x, y, z, optional target, payload_kg).
MeasurementSet read_measurements(const std::string& path, int dof);
MeasurementSet parse_measurements(const std::string& text, const std::string& source, int dof);
std::string format_measurements(const MeasurementSet& m, int dof);

}  // namespace kincal
