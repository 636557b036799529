// Robot: its models and the nominal model's IK solver, built once here.
#include "kincal/ik/ik.hpp"
#include "kincal/model/model.hpp"

namespace kincal {

Robot::Robot(ModelPtr nominal_model, ModelPtr calibrated_model, Campaign campaign)
    : nominal_(std::move(nominal_model)),
      calibrated_(std::move(calibrated_model)),
      campaign_(std::make_shared<const Campaign>(std::move(campaign))),
      ik_(nominal_ ? std::make_shared<const IkSolver>(*nominal_) : nullptr) {
  if (calibrated_) campaign_->check(calibrated_->dof(), "robot '" + calibrated_->spec().name + "': ");
}

}  // namespace kincal
