// The arm_controller node's wrapper: parameters -> core objects -> actions, services, topics.
// Callbacks convert messages, call rascal_control_core and convert back.
#pragma once

#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <actionlib/server/simple_action_server.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <rascal_msgs/ComputeFK.h>
#include <rascal_msgs/ComputeIK.h>
#include <rascal_msgs/GripperAction.h>
#include <rascal_msgs/MoveArmAction.h>

#include "rascal_control/CollisionChecker.hpp"
#include "rascal_control/IkSolver.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/TrajectoryPlanner.hpp"

namespace rascal_control {

class ArmController {
 public:
  // Reads and checks every parameter; throws std::runtime_error naming the key on a bad one.
  explicit ArmController(ros::NodeHandle& private_nh);

 private:
  struct Settings {
    std::map<std::string, JointVector> named_poses;
    double speed_scale = 1.0;
    double acceleration_share = 0.95;
    double command_period = 0.02;
    double goal_tolerance = 0.002;
    double settle_timeout = 2.0;
    double state_timeout = 1.0;
    double gripper_timeout = 3.0;
    double gripper_stroke_time = 0.5;
    double held_margin = 0.002;
    bool publish_tf = true;
  };

  std::string loadUrdf() const;
  void readSettings();
  void readFixtures();

  void jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg);
  void onJointState(const sensor_msgs::JointState& msg);
  // Latest arm joints; waits up to the state timeout (wall time) for the first message.
  bool currentJoints(JointVector& q, double wait);
  // Waits up to the state timeout (wall time) until the driver subscribes to `publisher`.
  bool driverListening(const ros::Publisher& publisher) const;

  void executeMove(const rascal_msgs::MoveArmGoalConstPtr& goal);
  rascal_msgs::MoveArmResult runMove(const rascal_msgs::MoveArmGoal& goal);
  PlanResult plan(const rascal_msgs::MoveArmGoal& goal, const JointVector& start);
  void executeGripper(const rascal_msgs::GripperGoalConstPtr& goal);
  rascal_msgs::GripperResult runGripper(const rascal_msgs::GripperGoal& goal);

  bool computeIk(rascal_msgs::ComputeIK::Request& req, rascal_msgs::ComputeIK::Response& res);
  bool computeFk(rascal_msgs::ComputeFK::Request& req, rascal_msgs::ComputeFK::Response& res);
  bool solveIk(rascal_msgs::ComputeIK::Request& req, rascal_msgs::ComputeIK::Response& res);
  bool solveFk(rascal_msgs::ComputeFK::Request& req, rascal_msgs::ComputeFK::Response& res);

  ros::NodeHandle nh_;
  Settings settings_;
  std::unique_ptr<KinematicModel> model_;
  std::unique_ptr<IkSolver> ik_;
  std::unique_ptr<CollisionChecker> collisions_;
  std::unique_ptr<TrajectoryPlanner> planner_;
  std::mutex core_mutex_;  // IkSolver and CollisionChecker are not thread-safe

  std::mutex state_mutex_;
  std::condition_variable state_cv_;
  std::map<std::string, double> positions_;
  std::map<std::string, double> velocities_;
  ros::WallTime last_state_wall_;
  struct FingerSample {
    double t;         // [s] the message's stamp (arrival time if it has none)
    double position;  // [m] left_finger
    double velocity;  // [m/s] left_finger, NaN when the driver sends none
  };
  std::deque<FingerSample> finger_history_;
  bool have_state_ = false;

  ros::Subscriber joint_state_sub_;
  ros::Publisher arm_command_pub_;
  ros::Publisher gripper_command_pub_;
  ros::ServiceServer ik_service_;
  ros::ServiceServer fk_service_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  std::unique_ptr<actionlib::SimpleActionServer<rascal_msgs::MoveArmAction>> move_server_;
  std::unique_ptr<actionlib::SimpleActionServer<rascal_msgs::GripperAction>> gripper_server_;
};

}  // namespace rascal_control
