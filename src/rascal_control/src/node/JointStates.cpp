#include "JointStates.hpp"

#include <limits>

#include "RosConversions.hpp"

namespace rascal_control {

std::map<std::string, double> JointStates::update(const sensor_msgs::JointState& msg, const ros::Time& now,
                                                  std::optional<FingerSample>& finger) {
  std::map<std::string, double> positions, velocities;
  jointStateToMaps(msg, positions, velocities);
  std::map<std::string, double> all;  // with the joints this message lacks
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& p : positions) positions_[p.first] = p.second;
    for (const auto& v : velocities) velocities_[v.first] = v.second;
    JointVector q{};
    have_arm_ = armJoints(positions_, q);
    last_wall_ = ros::WallTime::now();
    all = positions_;
  }
  updated_.notify_all();
  const auto left = all.find("left_finger");
  if (left != all.end()) {
    const auto right = all.find("right_finger");
    const auto v = velocities.find("left_finger");
    // The driver's stamp, not the arrival time: under load messages arrive in bursts.
    finger = FingerSample{(msg.header.stamp.isZero() ? now : msg.header.stamp).toSec(), left->second,
                          v != velocities.end() ? v->second : std::numeric_limits<double>::quiet_NaN(),
                          right != all.end() ? left->second - right->second : 2.0 * left->second};
  }
  return positions;
}

bool JointStates::arm(JointVector& q, double wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  updated_.wait_for(lock, std::chrono::duration<double>(wait), [this] { return have_arm_; });
  return have_arm_ && armJoints(positions_, q);
}

ArmSample JointStates::armSample(std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  updated_.wait_for(lock, wait);
  ArmSample s;
  armJoints(positions_, s.q);
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    const auto v = velocities_.find(KinematicModel::armJointNames()[j]);
    s.velocity[j] = v != velocities_.end() ? v->second : 0.0;  // none reported: only the position counts
  }
  s.state_age = (ros::WallTime::now() - last_wall_).toSec();
  return s;
}

std::optional<double> JointStates::leftFinger() {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto l = positions_.find("left_finger");
  return l != positions_.end() ? std::optional<double>(l->second) : std::nullopt;
}

bool JointStates::waitForFinger(double wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  return updated_.wait_for(lock, std::chrono::duration<double>(wait),
                           [this] { return positions_.count("left_finger") > 0; });
}

void JointStates::waitForUpdate(std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  updated_.wait_for(lock, wait);
}

}  // namespace rascal_control
