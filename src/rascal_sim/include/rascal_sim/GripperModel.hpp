#pragma once
// The gripper servo as seen at the fingers: symmetric fingers, full stroke in no less than 0.5 s,
// stopped while both fingers press on an object.
namespace rascal_sim {

class GripperModel {
 public:
  static constexpr double kStrokeTime = 0.5;   ///< [s] 30 -> 74 mm opening, timing.md
  explicit GripperModel(double initial);
  void setTarget(double finger_position);      ///< clamped to 0.015 .. 0.037 m
  /// Moves towards the target; `blocked` = closing is stopped by an object between the fingers.
  void step(double dt, bool blocked);
  void reset(double position);
  double position() const { return q_; }
  double velocity() const { return v_; }
  double target() const { return target_; }
  bool closing() const { return target_ < q_ - 1e-6; }
  bool opening() const { return target_ > q_ + 1e-6; }

 private:
  double q_, v_ = 0.0, target_;
};

}  // namespace rascal_sim
