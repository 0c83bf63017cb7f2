#pragma once
// The arm's six position servos: follow a time-stamped joint trajectory with lag, never faster
// than the velocity and acceleration limits of timing.md, never outside the joint limits.
#include <vector>

#include "rascal_sim/ArmKinematics.hpp"

namespace rascal_sim {

struct TrajectoryPoint {
  JointVector positions{};
  JointVector velocities{};
  bool has_velocities = false;
  double time_from_start = 0.0;  ///< [s]
};

class ServoModel {
 public:
  explicit ServoModel(const JointVector& initial);
  /// Replaces the current command. `mask[j]` false keeps joint j on its present target.
  /// An empty point list stops every joint as fast as the acceleration limit allows.
  void setTrajectory(double now, double start_time, const std::vector<TrajectoryPoint>& points,
                     const std::array<bool, kArmJoints>& mask);
  void stop(double now);
  /// Advances the servos by dt at time `now` (the time at the start of the step).
  void step(double now, double dt);
  void reset(const JointVector& q);
  const JointVector& positions() const { return q_; }
  const JointVector& velocities() const { return v_; }
  double maxSpeed() const;
  /// Every joint within `tolerance` of its final target and slower than 1e-3 rad/s.
  bool settled(double tolerance = 0.01) const;

 private:
  void reference(double t, JointVector& q_ref, JointVector& v_ref) const;

  JointVector q_{}, v_{};
  double start_time_ = 0.0;
  std::vector<TrajectoryPoint> points_;  ///< points_[0] is the state when the command arrived
};

}  // namespace rascal_sim
