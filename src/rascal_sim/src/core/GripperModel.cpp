#include "rascal_sim/GripperModel.hpp"

#include <algorithm>
#include <cmath>

namespace rascal_sim {

GripperModel::GripperModel(const rascal_workcell::GripperGeometry& gripper, double initial)
    : min_(gripper.finger_min),
      max_(gripper.finger_max),
      speed_((gripper.finger_max - gripper.finger_min) / kStrokeTime),
      q_(clamp(initial)),
      target_(q_) {}

double GripperModel::clamp(double p) const { return std::min(max_, std::max(min_, p)); }

void GripperModel::setTarget(double finger_position) { target_ = clamp(finger_position); }

void GripperModel::reset(double position) {
  q_ = clamp(position);
  target_ = q_;
  v_ = 0.0;
}

void GripperModel::step(double dt, bool blocked) {
  const double err = target_ - q_;
  if (std::abs(err) < 1e-9 || (blocked && err < 0)) {
    v_ = 0.0;
    return;
  }
  const double move = std::copysign(std::min(std::abs(err), speed_ * dt), err);
  q_ += move;
  v_ = move / dt;
}

}  // namespace rascal_sim
