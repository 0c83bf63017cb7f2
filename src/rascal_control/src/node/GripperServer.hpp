// /rascal/gripper (action rascal_msgs/Gripper), /gripper/command to the driver and
// /rascal/gripper/state: the wrapper around GripperMonitor, which decides everything.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>

#include <actionlib/server/simple_action_server.h>
#include <ros/ros.h>

#include <rascal_msgs/GripperAction.h>

#include "JointStates.hpp"
#include "rascal_control/GripperMonitor.hpp"

namespace rascal_control {

class GripperServer {
 public:
  // `states` must outlive the server. Starts the action server.
  GripperServer(ros::NodeHandle& root, JointStates& states, const rascal_workcell::GripperGeometry& gripper,
                const GripperMonitor::Settings& settings, double state_timeout);

  // Every /joint_states message with the fingers: feeds the monitor, publishes the gripper state.
  void onFinger(const FingerSample& sample);

 private:
  void execute(const rascal_msgs::GripperGoalConstPtr& goal);
  rascal_msgs::GripperResult run(const rascal_msgs::GripperGoal& goal);
  void command(double finger, double seconds);

  JointStates& states_;
  double state_timeout_;
  std::mutex mutex_;  // guards monitor_
  std::condition_variable sampled_;
  GripperMonitor monitor_;
  ros::Publisher command_pub_;
  ros::Publisher state_pub_;
  std::unique_ptr<actionlib::SimpleActionServer<rascal_msgs::GripperAction>> server_;
};

}  // namespace rascal_control
