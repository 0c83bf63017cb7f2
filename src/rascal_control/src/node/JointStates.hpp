// The latest /joint_states of the arm and fingers, shared by the node's callbacks and its two
// action servers (which wait on it from their own threads).
#pragma once

#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include <ros/time.h>
#include <sensor_msgs/JointState.h>

#include "rascal_control/GripperMonitor.hpp"
#include "rascal_control/MoveMonitor.hpp"

namespace rascal_control {

class JointStates {
 public:
  // Merges one message (joints it lacks keep their last value); returns the message's positions.
  // `finger` is set to the fingers' sample when left_finger is known (stamped with the message's
  // stamp, or `now` without one).
  std::map<std::string, double> update(const sensor_msgs::JointState& msg, const ros::Time& now,
                                       std::optional<FingerSample>& finger);

  // The six arm joints; waits up to `wait` [s] (wall time) for the first complete message.
  bool arm(JointVector& q, double wait);
  // Waits up to `wait` for the next message, then the arm as the move monitor needs it (elapsed
  // and wall left at 0 for the caller to fill in).
  ArmSample armSample(std::chrono::milliseconds wait);
  // The left finger position [m]; nullopt before the first message with it.
  std::optional<double> leftFinger();
  // Waits up to `wait` [s] (wall time) for the first message with left_finger.
  bool waitForFinger(double wait);
  // Waits up to `wait` for the next message.
  void waitForUpdate(std::chrono::milliseconds wait);

 private:
  std::mutex mutex_;
  std::condition_variable updated_;
  std::map<std::string, double> positions_;
  std::map<std::string, double> velocities_;
  ros::WallTime last_wall_;
  bool have_arm_ = false;
};

}  // namespace rascal_control
