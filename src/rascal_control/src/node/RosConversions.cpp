#include "RosConversions.hpp"

#include <cmath>

#include <ros/ros.h>
#include <tf2_kdl/tf2_kdl.h>

namespace rascal_control {

bool poseToFrame(const geometry_msgs::Pose& pose, KDL::Frame& frame, std::string& why) {
  const auto& p = pose.position;
  const auto& o = pose.orientation;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    why = "position is not finite";
    return false;
  }
  const double norm = std::sqrt(o.x * o.x + o.y * o.y + o.z * o.z + o.w * o.w);
  if (!std::isfinite(norm) || std::fabs(norm - 1.0) > 0.01) {
    why = "orientation quaternion has length " + std::to_string(norm) + ", expected 1";
    return false;
  }
  geometry_msgs::Pose unit = pose;
  unit.orientation.x /= norm;
  unit.orientation.y /= norm;
  unit.orientation.z /= norm;
  unit.orientation.w /= norm;
  tf2::fromMsg(unit, frame);
  return true;
}

geometry_msgs::Pose frameToPose(const KDL::Frame& frame) { return tf2::toMsg(frame); }

geometry_msgs::TransformStamped toTransform(const LinkTransform& transform, const ros::Time& stamp) {
  geometry_msgs::TransformStamped out = tf2::kdlToTransform(transform.pose);
  out.header.stamp = stamp;
  out.header.frame_id = transform.parent;
  out.child_frame_id = transform.child;
  return out;
}

trajectory_msgs::JointTrajectory toJointTrajectory(const Trajectory& trajectory, double period,
                                                   const ros::Time& start) {
  trajectory_msgs::JointTrajectory msg;
  msg.header.stamp = start;
  msg.joint_names.assign(KinematicModel::armJointNames().begin(), KinematicModel::armJointNames().end());
  for (const Trajectory::Sample& s : trajectory.sampled(period)) {
    trajectory_msgs::JointTrajectoryPoint point;
    point.positions = toStdVector(s.q);
    point.velocities = toStdVector(s.qd);
    point.accelerations = toStdVector(s.qdd);
    point.time_from_start = ros::Duration(s.t);
    msg.points.push_back(point);
  }
  return msg;
}

trajectory_msgs::JointTrajectory stopTrajectory(const ros::Time& stamp) {
  trajectory_msgs::JointTrajectory msg;
  msg.header.stamp = stamp;
  msg.joint_names.assign(KinematicModel::armJointNames().begin(), KinematicModel::armJointNames().end());
  return msg;
}

trajectory_msgs::JointTrajectory fingerCommand(double finger, double seconds, const ros::Time& stamp) {
  trajectory_msgs::JointTrajectory msg;
  msg.header.stamp = stamp;
  msg.joint_names = {"left_finger"};
  trajectory_msgs::JointTrajectoryPoint point;
  point.positions = {finger};
  point.time_from_start = ros::Duration(seconds);
  msg.points.push_back(point);
  return msg;
}

void jointStateToMaps(const sensor_msgs::JointState& msg, std::map<std::string, double>& positions,
                      std::map<std::string, double>& velocities) {
  for (std::size_t i = 0; i < msg.name.size(); ++i) {
    if (i < msg.position.size()) {
      positions[msg.name[i]] = msg.position[i];
    }
    if (i < msg.velocity.size()) {
      velocities[msg.name[i]] = msg.velocity[i];
    }
  }
}

bool armJoints(const std::map<std::string, double>& values, JointVector& q) {
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    const auto it = values.find(KinematicModel::armJointNames()[j]);
    if (it == values.end()) {
      return false;
    }
    q[j] = it->second;
  }
  return true;
}

JointVector toJointVector(const std::vector<double>& values) {
  JointVector q{};
  for (std::size_t j = 0; j < kArmJoints && j < values.size(); ++j) {
    q[j] = values[j];
  }
  return q;
}

std::vector<double> toStdVector(const JointVector& q) { return std::vector<double>(q.begin(), q.end()); }

bool driverListening(const ros::Publisher& publisher, double wait) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(wait);
  while (publisher.getNumSubscribers() == 0 && ros::ok() && ros::WallTime::now() < deadline) {
    ros::WallDuration(0.005).sleep();
  }
  return publisher.getNumSubscribers() > 0;
}

}  // namespace rascal_control
