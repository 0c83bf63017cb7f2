#include "rascal_control/MoveMonitor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace rascal_control {

namespace {

// Largest joint difference [rad] and which joint it is.
double farthest(const JointVector& a, const JointVector& b, std::size_t& joint) {
  double worst = -1.0;
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    const double d = std::fabs(a[j] - b[j]);
    if (!(d <= worst)) {  // NaN counts as farthest
      worst = std::isnan(d) ? std::numeric_limits<double>::infinity() : d;
      joint = j;
    }
  }
  return worst;
}

}  // namespace

MoveMonitor::MoveMonitor(std::vector<PathPoint> path, const Settings& settings)
    : path_(std::move(path)), settings_(settings) {
  if (path_.empty()) {
    throw std::invalid_argument("MoveMonitor: the planned path has no points");
  }
}

std::vector<PathPoint> MoveMonitor::reference(const Trajectory& trajectory) {
  std::vector<PathPoint> path;
  for (const Trajectory::Sample& s : trajectory.sampled(kReferenceStep)) {
    path.push_back({s.t, s.q});
  }
  return path;
}

MoveMonitor::Decision MoveMonitor::update(const ArmSample& s) const {
  std::size_t goal_joint = 0;
  const double goal_error = farthest(s.q, goal(), goal_joint);
  bool resting = true;
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    resting = resting && std::fabs(s.velocity[j]) < kAtRest;  // false for NaN
  }
  if (s.measured >= duration() && goal_error <= settings_.goal_tolerance && resting) {
    return {Status::Arrived, "arrived"};
  }
  char text[240];
  if (s.state_age > kStateSilence) {
    std::snprintf(text, sizeof(text), "driver silent: no /joint_states for %.1f s; arm not at the goal %.1f s after the start "
                  "(planned %.2f s; %s off by %.4f rad)",
                  s.state_age, s.elapsed, duration(), KinematicModel::armJointNames()[goal_joint].c_str(), goal_error);
    return {Status::DriverSilent, text};
  }
  // The nearest point of the planned path: how far off it the arm is, and how far behind.
  std::size_t nearest = 0, path_joint = 0;
  double deviation = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < path_.size(); ++k) {
    std::size_t joint = 0;
    const double d = farthest(s.q, path_[k].q, joint);
    if (d <= deviation) {  // ties: the later point (an arm at rest at the goal is not behind)
      deviation = d;
      nearest = k;
      path_joint = joint;
    }
  }
  const double done = duration() > 0.0 ? path_[nearest].t / duration() : 1.0;
  if (deviation > settings_.tracking_tolerance) {
    std::snprintf(text, sizeof(text), "off its path: %s %.3f rad from the planned path %.1f s after the start "
                  "(planned %.2f s, nearest at %.0f %%); blocked, or the driver is not following",
                  KinematicModel::armJointNames()[path_joint].c_str(), deviation, s.elapsed, duration(), 100.0 * done);
    return {Status::OffPath, text};
  }
  const double lag = s.elapsed - path_[nearest].t;
  if (!(lag > settings_.settle_timeout && s.wall > settings_.settle_timeout)) {
    return {};
  }
  if (s.elapsed > duration()) {
    std::snprintf(text, sizeof(text), "timeout: arm not at the goal %.1f s after the planned %.2f s (%s off by %.4f rad)",
                  s.elapsed, duration(), KinematicModel::armJointNames()[goal_joint].c_str(), goal_error);
  } else {
    std::snprintf(text, sizeof(text), "timeout: arm %.1f s behind its trajectory (at %.0f %% of the path %.1f s after "
                  "the start, planned %.2f s); stalled or not started",
                  lag, 100.0 * done, s.elapsed, duration());
  }
  return {Status::Timeout, text};
}

double MoveMonitor::progress(double elapsed) const {
  return duration() > 0.0 ? std::min(1.0, elapsed / duration()) : 1.0;
}

}  // namespace rascal_control
