// Robot: its models and the nominal model's IK solver, built once here.
#include "kincal/ik/ik.hpp"
#include "kincal/model/model.hpp"

namespace kincal {

Robot::Robot(ModelPtr nominal_model, ModelPtr calibrated_model)
    : nominal_(std::move(nominal_model)),
      calibrated_(std::move(calibrated_model)),
      ik_(nominal_ ? std::make_shared<const IkSolver>(*nominal_) : nullptr) {}

}  // namespace kincal
