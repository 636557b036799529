// Robot: its models and the nominal model's IK solver, built once here.
#include "kincal/ik/ik.hpp"
#include "kincal/model/model.hpp"

namespace kincal {

Robot::Robot(ModelPtr nominal_model, ModelPtr calibrated_model)
    : nominal(std::move(nominal_model)),
      calibrated(std::move(calibrated_model)),
      ik_(nominal ? std::make_shared<const IkSolver>(*nominal) : nullptr) {}

}  // namespace kincal
