#include "rascal_control/MoveMonitor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rascal_control {

MoveMonitor::MoveMonitor(const JointVector& goal, double duration, const Settings& settings)
    : goal_(goal), duration_(duration), settings_(settings) {}

MoveMonitor::Decision MoveMonitor::update(const ArmSample& s) const {
  double worst = 0.0;
  std::size_t worst_joint = 0;
  bool resting = true;
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    const double error = std::fabs(s.q[j] - goal_[j]);
    if (error > worst) {
      worst = error;
      worst_joint = j;
    }
    resting = resting && std::fabs(s.velocity[j]) < kAtRest;  // false for NaN
  }
  if (s.elapsed >= duration_ && worst <= settings_.goal_tolerance && resting) {
    return {Status::Arrived, "arrived"};
  }
  const bool late = s.elapsed > duration_ + settings_.settle_timeout && s.wall > settings_.settle_timeout;
  const bool silent = s.state_age > kStateSilence;
  if (!late && !silent) {
    return {};
  }
  char text[200];
  std::snprintf(text, sizeof(text), "%s: arm not at the goal %.1f s after the planned %.2f s (%s off by %.4f rad)",
                silent ? "driver silent" : "timeout", s.elapsed, duration_,
                KinematicModel::armJointNames()[worst_joint].c_str(), worst);
  return {silent ? Status::DriverSilent : Status::Timeout, text};
}

double MoveMonitor::progress(double elapsed) const {
  return duration_ > 0.0 ? std::min(1.0, elapsed / duration_) : 1.0;
}

}  // namespace rascal_control
