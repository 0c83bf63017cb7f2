// The arm_controller node's wrapper: parameters -> core objects -> actions, services, topics.
// Callbacks convert messages, call rascal_control_core and convert back; the move and gripper
// actions are MoveServer and GripperServer, the decisions MoveMonitor and GripperMonitor.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <rascal_msgs/ComputeFK.h>
#include <rascal_msgs/ComputeIK.h>

#include "GripperServer.hpp"
#include "JointStates.hpp"
#include "MoveServer.hpp"
#include "rascal_control/CollisionChecker.hpp"
#include "rascal_control/ControllerParameters.hpp"
#include "rascal_control/IkSolver.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/TrajectoryPlanner.hpp"
#include "rascal_workcell/GripperGeometry.hpp"

namespace rascal_control {

class ArmController {
 public:
  // Reads and checks every parameter; throws (rascal_workcell::ParameterError or
  // std::runtime_error) with one line naming the key on a bad one.
  explicit ArmController(ros::NodeHandle& private_nh);

 private:
  static std::string loadUrdf();

  void jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg);
  bool computeIk(rascal_msgs::ComputeIK::Request& req, rascal_msgs::ComputeIK::Response& res);
  bool computeFk(rascal_msgs::ComputeFK::Request& req, rascal_msgs::ComputeFK::Response& res);
  bool solveIk(rascal_msgs::ComputeIK::Request& req, rascal_msgs::ComputeIK::Response& res);
  bool solveFk(rascal_msgs::ComputeFK::Request& req, rascal_msgs::ComputeFK::Response& res);
  // Every 50 ms of wall time: ROS time and the driver's subscriptions into the DriverMonitor.
  void watchDriver(const ros::WallTimerEvent& event);
  bool acknowledgeRestart(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);

  ros::NodeHandle nh_;
  std::unique_ptr<KinematicModel> model_;
  rascal_workcell::GripperGeometry gripper_;
  ControllerParameters params_;
  std::unique_ptr<IkSolver> ik_;
  std::unique_ptr<CollisionChecker> collisions_;
  std::unique_ptr<TrajectoryPlanner> planner_;
  std::mutex core_mutex_;  // IkSolver and CollisionChecker are not thread-safe
  JointStates states_;

  ros::Subscriber joint_state_sub_;
  ros::ServiceServer ik_service_;
  ros::ServiceServer fk_service_;
  ros::ServiceServer acknowledge_service_;
  ros::WallTimer driver_timer_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  std::unique_ptr<MoveServer> move_server_;
  std::unique_ptr<GripperServer> gripper_server_;
};

}  // namespace rascal_control
