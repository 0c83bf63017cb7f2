#include "rascal_sim/GripperModel.hpp"

#include <algorithm>
#include <cmath>

#include "rascal_sim/ArmKinematics.hpp"

namespace rascal_sim {

namespace {
constexpr double kSpeed = (ArmKinematics::kFingerMax - ArmKinematics::kFingerMin) / GripperModel::kStrokeTime;

double clampFinger(double p) {
  return std::min(ArmKinematics::kFingerMax, std::max(ArmKinematics::kFingerMin, p));
}
}  // namespace

GripperModel::GripperModel(double initial) : q_(clampFinger(initial)), target_(q_) {}

void GripperModel::setTarget(double finger_position) { target_ = clampFinger(finger_position); }

void GripperModel::reset(double position) {
  q_ = clampFinger(position);
  target_ = q_;
  v_ = 0.0;
}

void GripperModel::step(double dt, bool blocked) {
  const double err = target_ - q_;
  if (std::abs(err) < 1e-9 || (blocked && err < 0)) {
    v_ = 0.0;
    return;
  }
  const double move = std::copysign(std::min(std::abs(err), kSpeed * dt), err);
  q_ += move;
  v_ = move / dt;
}

}  // namespace rascal_sim
