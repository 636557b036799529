// kincal: a probe station as identified (measurements without a tracker, measurements.hpp) and a
// probe row's error along its constraint: the one definition that the identification's residual
// (point_model.hpp) and the evaluation of a calibration on rows (point_errors) share.
#pragma once

#include "kincal/io/measurements.hpp"

#include <string>
#include <vector>

namespace kincal {

/// A station in the instrument frame of its rows' setup: a point (a sphere's centre, a ballbar's
/// pivot) or a plane n . y = offset (n unit, towards the flange: the side of the ball's centre).
struct StationValue {
  std::string name;
  MeasureKind kind = MeasureKind::sphere;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  double offset = 0;
};

/// The residual of a probe row whose ball centre is at y (instrument frame) against its station:
/// a sphere row's y minus the station's point (3 components), a plane row's distance of y from the
/// plane minus the ball's radius, a ballbar row's distance of y from the pivot minus its length (1
/// component). Returns the number of components written to r.
int probe_residual(const StationValue& s, const Measurement& m, const Vec3& y, double* r);

/// The station of a row by its name among the values (nullptr when it is not among them).
const StationValue* station_of(const std::vector<StationValue>& values, const MeasurementSet& data,
                               const Measurement& m);

}  // namespace kincal
