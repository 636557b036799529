// kincal (private): what the periodic joint-angle effects share (transmission_error, joint_map):
// sine and cosine amplitudes of harmonic orders of the joint angle.
#pragma once

#include "kincal/effects/effects.hpp"

#include <string>
#include <vector>

namespace kincal::harmonic {

/// sin(k q), cos(k q) of each order k (in b, in pairs) and their derivatives (in db when not null).
void basis(const std::vector<int>& orders, double q, double* b, double* db);
/// prefix + sin/cos + order for each order, e.g. te_sin1, te_cos1.
std::vector<std::string> names(const std::string& prefix, const std::vector<int>& orders);
/// "rad" for every amplitude.
std::vector<std::string> units(const Effect& e);

}  // namespace kincal::harmonic
