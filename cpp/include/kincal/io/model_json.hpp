// kincal: the model JSON file (contract: "format": "kincal-model", "version" 1 to 3; written as
// version 3: the robot's sections "nominal" and "calibrated", the campaign's in "campaign"; versions 1
// and 2 carry the campaign inside the model's section) of a Robot, and load_robot (a built-in name
// or a model JSON path).
#pragma once

#include "kincal/model/model.hpp"

#include <string>

namespace kincal {

/// Model JSON (contract: "format": "kincal-model", "version"). Exact round trip.
std::string robot_to_json(const Robot& robot);
Robot robot_from_json(const std::string& text, const std::string& source);
/// A built-in name or a model JSON file path (URDF files are read by the Python layer).
Robot load_robot(const std::string& name_or_path);
/// The robot loaded from `source` (a built-in name, a URDF or a model JSON) numbered as its controller
/// numbers the joints (`convention`: "fanuc", or "" for the model's own angles). A model JSON carries
/// its own convention: giving one for it is an InputError naming the file.
Robot with_joint_convention(const Robot& robot, const std::string& source, const std::string& convention);
std::string spec_to_json(const ModelSpec& spec);
/// The one warning line for a model whose TCP the identification could not place ("tcp": "nominal":
/// reflectors only, no --tool-targets), naming source (the model file); "" for any other model (the
/// TCP measured or placed, or not recorded: older files, built-in robots, URDFs).
std::string tcp_warning(const Robot& robot, const std::string& source);

}  // namespace kincal
