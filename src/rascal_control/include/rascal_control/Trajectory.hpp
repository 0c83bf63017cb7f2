// A timed joint trajectory: a geometric path q(s) followed with a time scaling s(t).
#pragma once

#include <vector>

#include "rascal_control/JointPath.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/TimeScaling.hpp"

namespace rascal_control {

class Trajectory {
 public:
  struct Sample {
    double t = 0.0;    // [s] from the start
    JointVector q{};   // [rad]
    JointVector qd{};  // [rad/s]
    JointVector qdd{}; // [rad/s^2]
  };

  Trajectory() = default;
  Trajectory(JointPath path, TimeScaling timing);

  double duration() const { return timing_.duration(); }
  Sample sample(double t) const;
  // Samples every `dt` from 0, plus the end point.
  std::vector<Sample> sampled(double dt) const;
  const JointPath& path() const { return path_; }
  const TimeScaling& timing() const { return timing_; }
  JointVector start() const { return path_.at(0.0); }
  JointVector goal() const { return path_.at(1.0); }

 private:
  JointPath path_;
  TimeScaling timing_;
};

}  // namespace rascal_control
