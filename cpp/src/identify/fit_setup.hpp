// kincal (private): what a fit asks of the data and the effects before Ceres runs: the rows' checks,
// the effects to identify and the columns they read, the reference temperature and time, the start
// of the effects a model carries, and the free parameters (identify.cpp runs the fit).
#pragma once

#include "kincal/identify/identify.hpp"

#include <string>
#include <vector>

namespace kincal::fit_setup {

/// "source:line" of a measured row.
std::string where(const MeasurementSet& data, const Measurement& r);
/// InputError unless every row has the robot's number of joint angles.
void check_rows(const Model& nominal, const MeasurementSet& data);
/// The data, or in copy the data without the artifact's terms that name a station none of its rows
/// touch (a fold of a campaign): those stations' unknowns are held (fix_unobservable).
const MeasurementSet& measured_artifact(const MeasurementSet& data, MeasurementSet& copy);
/// The extra effects: those asked for, then those the starting model carries (held at their values),
/// but its drift: a property of the campaign it was measured on, not of the robot.
std::vector<Effect> effects_to_identify(const Model& nominal, const IdentifyOptions& opt);
/// The reference temperature of thermal expansion: the starting model's, or the mean of the data's
/// when the effect is new to the model.
double reference_temperature(const Model& nominal, const MeasurementSet& data, const std::vector<Effect>& effects);
/// The drift's reference time: the data's mean time (the placements are those of that moment).
double reference_time(const MeasurementSet& data, const std::vector<Effect>& effects);
/// Effects the starting model carries start from its values; those not asked for are held there.
void start_carried_effects(const Model& nominal, const IdentifyOptions& opt, IdentifyResult& res);
/// The free parameters; InputError when the data give no more equations than them or, with priors,
/// fewer measured points than there are free parameters without a prior.
std::vector<int> free_parameters(const MeasurementSet& data, const IdentifyResult& res, const std::vector<double>& sd);

}  // namespace kincal::fit_setup
