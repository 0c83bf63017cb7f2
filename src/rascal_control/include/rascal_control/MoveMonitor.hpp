// Watches one arm move after its trajectory was sent: arrived, still moving, late or the driver
// silent, decided from plain joint samples (the node feeds it /joint_states). No ROS.
#pragma once

#include <string>

#include "rascal_control/KinematicModel.hpp"

namespace rascal_control {

// The arm as the driver last reported it, timed from the moment the trajectory was sent.
struct ArmSample {
  double elapsed = 0.0;    // [s] ROS time since the trajectory was sent (sim time under use_sim_time)
  double wall = 0.0;       // [s] wall time since the trajectory was sent
  double state_age = 0.0;  // [s] wall time since the last /joint_states message
  JointVector q{};         // [rad]
  JointVector velocity{};  // [rad/s]; 0 for a joint the driver reports no velocity of
};

class MoveMonitor {
 public:
  struct Settings {
    double goal_tolerance = 0.002;  // [rad] every joint this close to the goal ...
    double settle_timeout = 2.0;    // [s] ... within this long after the planned duration
  };
  static constexpr double kAtRest = 0.02;        // [rad/s] joint speed counted as at rest
  static constexpr double kStateSilence = 2.0;   // [s] wall time without /joint_states = silent

  enum class Status { Moving, Arrived, Timeout, DriverSilent };
  struct Decision {
    Status status = Status::Moving;
    std::string reason;  // "arrived", or why it timed out (which joint is how far off)
    bool done() const { return status != Status::Moving; }
  };

  // `goal` [rad]: the trajectory's last point; `duration` [s]: its planned duration.
  MoveMonitor(const JointVector& goal, double duration, const Settings& settings);

  // Arrived: the planned duration is over and every joint is within goal_tolerance and at rest.
  // Timeout: not arrived settle_timeout after the planned duration, in ROS time and also in wall
  // time (a simulator running many times faster than real time must not turn message latency
  // into a TIMEOUT). DriverSilent: no /joint_states for kStateSilence of wall time.
  Decision update(const ArmSample& sample) const;
  // Share of the planned duration elapsed, 0..1.
  double progress(double elapsed) const;

  const JointVector& goal() const { return goal_; }
  double duration() const { return duration_; }

 private:
  JointVector goal_;
  double duration_;
  Settings settings_;
};

}  // namespace rascal_control
