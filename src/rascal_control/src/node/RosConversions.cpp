#include "RosConversions.hpp"

#include <cmath>

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
  frame = KDL::Frame(KDL::Rotation::Quaternion(o.x / norm, o.y / norm, o.z / norm, o.w / norm),
                     KDL::Vector(p.x, p.y, p.z));
  return true;
}

geometry_msgs::Pose frameToPose(const KDL::Frame& frame) {
  geometry_msgs::Pose pose;
  pose.position.x = frame.p.x();
  pose.position.y = frame.p.y();
  pose.position.z = frame.p.z();
  frame.M.GetQuaternion(pose.orientation.x, pose.orientation.y, pose.orientation.z,
                        pose.orientation.w);
  return pose;
}

geometry_msgs::TransformStamped toTransform(const LinkTransform& transform, const ros::Time& stamp) {
  geometry_msgs::TransformStamped out;
  out.header.stamp = stamp;
  out.header.frame_id = transform.parent;
  out.child_frame_id = transform.child;
  out.transform.translation.x = transform.pose.p.x();
  out.transform.translation.y = transform.pose.p.y();
  out.transform.translation.z = transform.pose.p.z();
  transform.pose.M.GetQuaternion(out.transform.rotation.x, out.transform.rotation.y,
                                 out.transform.rotation.z, out.transform.rotation.w);
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

}  // namespace rascal_control
