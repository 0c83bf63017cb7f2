#pragma once
// ROS wrapper of the simulator: the topics a real driver exposes, /clock, and test-only services.
#include <ros/ros.h>
#include <rascal_msgs/CaptureArchival.h>
#include <rascal_msgs/GetGroundTruth.h>
#include <rascal_msgs/InjectFault.h>
#include <rascal_msgs/SpawnScenario.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>

#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/SimParameters.hpp"
#include "rascal_sim/Simulator.hpp"

namespace rascal_sim {

class SimNode {
 public:
  /// Reads and checks the parameters (throws rascal_workcell::ParameterError naming the key),
  /// then advertises.
  explicit SimNode(ros::NodeHandle& nh);
  /// Steps the world until shutdown, publishing clock, joint states, images and scale readings.
  void run();

 private:
  void readParameters();
  /// base_link → archival_camera_optical_frame and → scale_link, where the stations stand now.
  void sendStaticFrames();
  void onArmTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg);
  void onGripperCommand(const trajectory_msgs::JointTrajectory::ConstPtr& msg);
  bool onTare(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onCapture(rascal_msgs::CaptureArchival::Request& req, rascal_msgs::CaptureArchival::Response& res);
  bool onGroundTruth(rascal_msgs::GetGroundTruth::Request& req, rascal_msgs::GetGroundTruth::Response& res);
  bool onSpawn(rascal_msgs::SpawnScenario::Request& req, rascal_msgs::SpawnScenario::Response& res);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onInjectFault(rascal_msgs::InjectFault::Request& req, rascal_msgs::InjectFault::Response& res);
  /// Blocks the calling service thread until sim time reaches t (or shutdown); `lock` held on return.
  bool waitUntil(std::unique_lock<std::mutex>& lock, double t);
  bool cameraWanted() const;
  void publishWristFrame(const WristFrame& frame);

  // parameters
  SimParameters config_;
  std::string scenario_path_, workspace_, spool_dir_;  ///< resolved against the workspace root

  std::unique_ptr<MunsellTable> munsell_;
  std::unique_ptr<Simulator> sim_;
  std::mutex mutex_;
  std::condition_variable stepped_;

  ros::Publisher clock_pub_, joint_pub_, scale_pub_, colour_pub_, depth_pub_, colour_info_pub_,
      depth_info_pub_, cloud_pub_, exposed_pub_;
  ros::Subscriber arm_sub_, gripper_sub_;
  ros::ServiceServer tare_srv_, capture_srv_, truth_srv_, spawn_srv_, reset_srv_, fault_srv_;
  tf2_ros::StaticTransformBroadcaster static_tf_;
};

}  // namespace rascal_sim
