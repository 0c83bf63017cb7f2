// Stateless conversions between ROS messages and rascal_control_core types (the node's only
// place for them). KDL <-> geometry_msgs through tf2_kdl; what follows has no library equivalent.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <kdl/frames.hpp>
#include <ros/publisher.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/Trajectory.hpp"

namespace rascal_control {

// False (with `why`) for a non-finite position or a quaternion far from unit length; a nearly
// unit quaternion is normalised (tf2::fromMsg would build a skewed rotation from it).
bool poseToFrame(const geometry_msgs::Pose& pose, KDL::Frame& frame, std::string& why);
geometry_msgs::Pose frameToPose(const KDL::Frame& frame);
geometry_msgs::TransformStamped toTransform(const LinkTransform& transform, const ros::Time& stamp);

// Points every `period` seconds (positions, velocities, accelerations), stamped `start`.
trajectory_msgs::JointTrajectory toJointTrajectory(const Trajectory& trajectory, double period,
                                                   const ros::Time& start);
// A trajectory with no points: the driver stops at once.
trajectory_msgs::JointTrajectory stopTrajectory(const ros::Time& stamp);
// The gripper driver's command: joint left_finger to `finger` [m] in `seconds`.
trajectory_msgs::JointTrajectory fingerCommand(double finger, double seconds, const ros::Time& stamp);

// Every named position of a JointState message (velocities where given).
void jointStateToMaps(const sensor_msgs::JointState& msg, std::map<std::string, double>& positions,
                      std::map<std::string, double>& velocities);
// The six arm joints out of a name -> value map; false if one is missing.
bool armJoints(const std::map<std::string, double>& values, JointVector& q);
JointVector toJointVector(const std::vector<double>& values);
std::vector<double> toStdVector(const JointVector& q);

// Waits up to `wait` [s] (wall time) until the driver subscribes to `publisher`: a message
// published before its subscription is connected would be lost.
bool driverListening(const ros::Publisher& publisher, double wait);

}  // namespace rascal_control
