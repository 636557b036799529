// kincal: the closed sets of words of the identification's options, as enums (the robust loss, where
// the compliances' gravity torques come from) with their words on the command line and in files.
#pragma once

#include <string>

namespace kincal {

/// The robust loss of the fit on a row's residual norm.
enum class Loss { none, huber, cauchy };
/// Where the compliances' gravity torques come from: the model's link masses, mass moments identified
/// with the compliances (fit), or fit when the model has no masses (automatic).
enum class GravityTorques { automatic, masses, fit };
/// The words of the command line and the files ("none", "huber", "cauchy"; "auto", "masses", "fit")
/// and back; InputError naming the known words otherwise.
Loss parse_loss(const std::string& word);
std::string loss_word(Loss loss);
GravityTorques parse_gravity(const std::string& word);
std::string gravity_word(GravityTorques gravity);

}  // namespace kincal
