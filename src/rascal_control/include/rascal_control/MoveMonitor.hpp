// Watches one arm move after its trajectory was sent: arrived, still moving, off its path, behind
// it, or the driver silent, decided from plain joint samples (the node feeds it /joint_states)
// against the planned trajectory. No ROS.
#pragma once

#include <string>
#include <vector>

#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/Trajectory.hpp"

namespace rascal_control {

// The arm as the driver last reported it, timed from the moment the trajectory was sent.
struct ArmSample {
  double elapsed = 0.0;    // [s] ROS time since the trajectory was sent (sim time under use_sim_time)
  double measured = 0.0;   // [s] when the driver measured q (its stamp), after the trajectory was sent
  double wall = 0.0;       // [s] wall time since the trajectory was sent
  double state_age = 0.0;  // [s] wall time since the last /joint_states message
  JointVector q{};         // [rad]
  JointVector velocity{};  // [rad/s]; 0 for a joint the driver reports no velocity of
};

// One point of the planned trajectory.
struct PathPoint {
  double t = 0.0;  // [s] from the start
  JointVector q{};  // [rad]
};

class MoveMonitor {
 public:
  struct Settings {
    double goal_tolerance = 0.002;     // [rad] every joint this close to the goal ...
    double settle_timeout = 2.0;       // [s] ... within this long after the planned duration
    double tracking_tolerance = 0.1;   // [rad] farthest a joint may be from the planned path
  };
  static constexpr double kAtRest = 0.02;        // [rad/s] joint speed counted as at rest
  static constexpr double kStateSilence = 2.0;   // [s] wall time without /joint_states = silent
  static constexpr double kReferenceStep = 0.005;  // [s] between the points of reference()

  enum class Status { Moving, Arrived, Timeout, DriverSilent, OffPath };
  struct Decision {
    Status status = Status::Moving;
    std::string reason;  // "arrived", or why not (which joint is how far off)
    bool done() const { return status != Status::Moving; }
  };

  // `path`: the planned trajectory's positions from its start (t = 0) to its goal (the last
  // point, t = the planned duration), in time order; at least one point.
  MoveMonitor(std::vector<PathPoint> path, const Settings& settings);
  // The points of `trajectory` every kReferenceStep, and its goal.
  static std::vector<PathPoint> reference(const Trajectory& trajectory);

  // Arrived: a sample the driver measured after the planned duration has every joint within
  // goal_tolerance and at rest (a sample measured before the trajectory was sent, e.g. the last
  // one of a driver that has since restarted, never counts: a zero-length move is not "arrived"
  // on the strength of an old message).
  // OffPath: the arm is more than tracking_tolerance (any joint) from every point of the planned
  // path (blocked, pushed, or the driver is not following it). Timeout: the arm is more than
  // settle_timeout behind the planned trajectory (its nearest path point is planned that much
  // earlier than now: not started, stalled, or not at the goal settle_timeout after the planned
  // duration), in ROS time and also in wall time (a simulator running many times faster than
  // real time must not turn message latency into a TIMEOUT). DriverSilent: no /joint_states for
  // kStateSilence of wall time.
  Decision update(const ArmSample& sample) const;
  // Share of the planned duration elapsed, 0..1.
  double progress(double elapsed) const;

  const JointVector& goal() const { return path_.back().q; }
  double duration() const { return path_.back().t; }

 private:
  std::vector<PathPoint> path_;
  Settings settings_;
};

}  // namespace rascal_control
