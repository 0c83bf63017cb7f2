#include "JointStates.hpp"

#include <cmath>
#include <limits>

#include "RosConversions.hpp"

namespace rascal_control {

std::string restartMessage(const std::string& reason) {
  return "arm driver restarted (" + reason + "): the arm may not be where it was and every command was lost; "
         "goals are refused until the task acknowledges on /rascal/arm/acknowledge_restart: re-run `rascal run` "
         "to re-calibrate";
}

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
    ++updates_;
    last_stamp_ = (msg.header.stamp.isZero() ? now : msg.header.stamp).toSec();
    if (armJoints(positions, q)) {  // this message has the whole arm
      driver_.addJointState(last_stamp_, q);
    }
    driver_.addClock(ros::Time::now().toSec());  // read under the lock: fed in the order read
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

bool JointStates::nextArm(JointVector& q, double wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  const std::uint64_t seen = updates_;
  updated_.wait_for(lock, std::chrono::duration<double>(wait), [&] { return updates_ != seen && have_arm_; });
  return updates_ != seen && have_arm_ && armJoints(positions_, q);
}

bool JointStates::armAtRest(JointVector& q, double at_rest, double wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto resting = [&] {
    for (const std::string& name : KinematicModel::armJointNames()) {
      const auto v = velocities_.find(name);
      if (v != velocities_.end() && !(std::fabs(v->second) < at_rest)) {
        return false;
      }
    }
    return true;
  };
  const bool rest = updated_.wait_for(lock, std::chrono::duration<double>(wait), resting);
  armJoints(positions_, q);
  return rest;
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
  s.measured = last_stamp_;
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

void JointStates::checkClock() {
  std::lock_guard<std::mutex> lock(mutex_);
  driver_.addClock(ros::Time::now().toSec());  // read under the lock: fed in the order read
}

void JointStates::checkSubscribers(int count) {
  std::lock_guard<std::mutex> lock(mutex_);
  driver_.addSubscribers(count);
}

std::string JointStates::restart() {
  std::lock_guard<std::mutex> lock(mutex_);
  return driver_.restarted() ? driver_.reason() : std::string();
}

bool JointStates::restartNoticed() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!driver_.restarted() || restart_logged_) {
    return false;
  }
  restart_logged_ = true;
  return true;
}

std::string JointStates::acknowledgeRestart() {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string reason = driver_.reason();
  driver_.acknowledge();
  restart_logged_ = false;
  return reason;
}

}  // namespace rascal_control
