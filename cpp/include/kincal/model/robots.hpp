// kincal: the built-in robots (kr500, ur10) by name, and simulated manufacturing errors of a model
// (perturbed_spec) for simulations and tests. Sources of the built-in data in robots.cpp.
#pragma once

#include "kincal/model/model.hpp"

#include <string>
#include <vector>

namespace kincal {

/// The built-in KUKA KR 500 R2830-class robot with a tape-laying head (sources in robots.cpp).
ModelSpec kr500_spec();
/// The built-in Universal Robots UR10 (UR's published DH parameters; sources in robots.cpp).
ModelSpec ur10_spec();
/// Names of the built-in robots.
std::vector<std::string> builtin_names();
/// A built-in robot by name; throws InputError naming the unknown robot.
ModelSpec builtin_spec(const std::string& name);

/// Realistic manufacturing errors for simulations and tests: every axis tilted by about sigma_deg
/// and moved by about sigma_mm normal to itself, the tool moved and turned by the same amounts;
/// with_compliance sets a joint compliance on every gravity-loaded joint (deg per kN m, about
/// `compliance` each). Deterministic for a seed. The compliances are drawn between the joints'
/// geometric draws, with compliance 0 as well (then dropped), so one seed with and without a compliance
/// gives one geometry (before the thirty-first session a spec without compliance skipped those draws,
/// and was another robot).
ModelSpec perturbed_spec(const ModelSpec& spec, unsigned seed, double sigma_mm = 1.0, double sigma_deg = 0.05,
                         double compliance = 0.0);

}  // namespace kincal
