// The latest /joint_states of the arm and fingers, shared by the node's callbacks and its two
// action servers (which wait on it from their own threads), and whether the driver behind them
// restarted (DriverMonitor: fed with every message, ROS time and the driver's subscriptions).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include <ros/time.h>
#include <sensor_msgs/JointState.h>

#include "rascal_control/DriverMonitor.hpp"
#include "rascal_control/GripperMonitor.hpp"
#include "rascal_control/MoveMonitor.hpp"

namespace rascal_control {

// The one line every goal gets while a driver restart is not acknowledged.
std::string restartMessage(const std::string& reason);

class JointStates {
 public:
  explicit JointStates(const DriverMonitor::Settings& driver = {}) : driver_(driver) {}
  // Before the first message: the arm's speed limit for the jump rule.
  void configureDriver(const DriverMonitor::Settings& driver) { driver_ = DriverMonitor(driver); }

  // Merges one message (joints it lacks keep their last value); returns the message's positions.
  // `finger` is set to the fingers' sample when left_finger is known (stamped with the message's
  // stamp, or `now` without one).
  std::map<std::string, double> update(const sensor_msgs::JointState& msg, const ros::Time& now,
                                       std::optional<FingerSample>& finger);

  // The six arm joints; waits up to `wait` [s] (wall time) for the first complete message.
  bool arm(JointVector& q, double wait);
  // The six arm joints from a message that arrives after this call (never a stale position,
  // e.g. the last one of a driver that has since died); waits up to `wait` [s] (wall time).
  bool nextArm(JointVector& q, double wait);
  // Waits up to `wait` [s] (wall time) until the latest message has every arm joint slower than
  // `at_rest` [rad/s] (a cancelled move still braking); `q` is the latest position either way.
  // Returns whether the arm is at rest.
  bool armAtRest(JointVector& q, double at_rest, double wait);
  // Waits up to `wait` for the next message, then the arm as the move monitor needs it (elapsed
  // and wall left at 0 for the caller to fill in; `measured` is the message's absolute stamp).
  ArmSample armSample(std::chrono::milliseconds wait);
  // The left finger position [m]; nullopt before the first message with it.
  std::optional<double> leftFinger();
  // Waits up to `wait` [s] (wall time) for the first message with left_finger.
  bool waitForFinger(double wait);
  // Waits up to `wait` for the next message.
  void waitForUpdate(std::chrono::milliseconds wait);

  // ROS time now and the subscribers of the driver's command topic (DriverMonitor's rules).
  void checkClock();
  void checkSubscribers(int count);
  // Empty while goals may run; else why the driver counts as restarted (not yet acknowledged).
  std::string restart();
  // True once per restart: the first call after it was noticed (for the node's one log line).
  bool restartNoticed();
  // The task knows: goals are accepted again. Returns the reason that was cleared (empty: none).
  std::string acknowledgeRestart();

 private:
  std::mutex mutex_;
  std::condition_variable updated_;
  std::map<std::string, double> positions_;
  std::map<std::string, double> velocities_;
  ros::WallTime last_wall_;
  bool have_arm_ = false;
  std::uint64_t updates_ = 0;  // messages so far
  double last_stamp_ = 0.0;    // [s] the latest message's stamp (its arrival time without one)
  DriverMonitor driver_;
  bool restart_logged_ = false;
};

}  // namespace rascal_control
