// /rascal/arm/move (action rascal_msgs/MoveArm) and /arm/joint_trajectory to the driver: goal ->
// plan (TrajectoryPlanner) -> trajectory sent -> MoveMonitor decides when it is over.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include <actionlib/server/simple_action_server.h>
#include <ros/ros.h>

#include <rascal_msgs/MoveArmAction.h>

#include "JointStates.hpp"
#include "rascal_control/ControllerParameters.hpp"
#include "rascal_control/TrajectoryPlanner.hpp"

namespace rascal_control {

class MoveServer {
 public:
  // Everything passed must outlive the server; `core_mutex` guards the planner (and the IK solver
  // and collision checker it uses, shared with the node's services). Starts the action server.
  MoveServer(ros::NodeHandle& root, JointStates& states, const KinematicModel& model, TrajectoryPlanner& planner,
             std::mutex& core_mutex, const ControllerParameters& params);

  // Subscribers of /arm/joint_trajectory (the driver's; DriverMonitor's rule).
  int driverSubscribers() const;

 private:
  void execute(const rascal_msgs::MoveArmGoalConstPtr& goal);
  rascal_msgs::MoveArmResult run(const rascal_msgs::MoveArmGoal& goal);
  PlanResult plan(const rascal_msgs::MoveArmGoal& goal, const JointVector& start);
  // A goal with then_poses: `first` (the goal's pose) and the rest, as one chain (core mutex held).
  PlanResult planChain(const rascal_msgs::MoveArmGoal& goal, const KDL::Frame& first, bool linear,
                       const JointVector& start, double scale);

  JointStates& states_;
  const KinematicModel& model_;
  TrajectoryPlanner& planner_;
  std::mutex& core_mutex_;
  const ControllerParameters& params_;
  ros::Publisher command_pub_;
  std::unique_ptr<actionlib::SimpleActionServer<rascal_msgs::MoveArmAction>> server_;
};

}  // namespace rascal_control
