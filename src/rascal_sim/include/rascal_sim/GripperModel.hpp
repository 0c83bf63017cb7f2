#pragma once
// The gripper servo as seen at the fingers: symmetric fingers within the URDF's finger limits,
// full stroke in no less than 0.5 s, stopped while both fingers press on an object.
#include "rascal_workcell/GripperGeometry.hpp"

namespace rascal_sim {

class GripperModel {
 public:
  static constexpr double kStrokeTime = 0.5;   ///< [s] closed -> fully open, timing.md
  /// `gripper`: finger limits from the URDF; `initial` is clamped to them.
  GripperModel(const rascal_workcell::GripperGeometry& gripper, double initial);
  void setTarget(double finger_position);      ///< clamped to finger_min .. finger_max
  /// Moves towards the target; `blocked` = closing is stopped by an object between the fingers.
  void step(double dt, bool blocked);
  void reset(double position);
  double position() const { return q_; }
  double velocity() const { return v_; }
  double target() const { return target_; }
  double fingerMin() const { return min_; }
  double fingerMax() const { return max_; }
  bool closing() const { return target_ < q_ - 1e-6; }
  bool opening() const { return target_ > q_ + 1e-6; }

 private:
  double clamp(double p) const;

  double min_, max_, speed_;
  double q_, v_ = 0.0, target_;
};

}  // namespace rascal_sim
