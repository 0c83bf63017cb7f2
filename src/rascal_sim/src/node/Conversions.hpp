#pragma once
// Stateless conversions between the core's types and ROS messages (one place for all of them):
// images through cv_bridge, poses and transforms through tf2_eigen; what has no library
// equivalent (camera info of the pinhole model, the xyz + rgb cloud, ground truth, trajectories)
// is written here.
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <rascal_msgs/SherdTruth.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <string>
#include <vector>

#include "rascal_sim/CameraModel.hpp"
#include "rascal_sim/ServoModel.hpp"
#include "rascal_sim/World.hpp"

namespace rascal_sim {
namespace conversions {

geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& t, const std::string& parent,
                                            const std::string& child, const ros::Time& stamp);
/// `encoding` is a sensor_msgs::image_encodings name matching the matrix ("rgb8", "16UC1").
sensor_msgs::ImagePtr toImage(const cv::Mat& image, const std::string& encoding, const std::string& frame,
                              const ros::Time& stamp);
sensor_msgs::CameraInfo toCameraInfo(const CameraModel& cam, const std::string& frame, const ros::Time& stamp);
/// Unordered xyz + rgb cloud of every valid depth pixel, in the optical frame.
sensor_msgs::PointCloud2 toPointCloud(const cv::Mat& depth_mm, const cv::Mat& rgb, const CameraModel& cam,
                                      const std::string& frame, const ros::Time& stamp);
rascal_msgs::SherdTruth toTruth(const SherdState& s);
/// Arm joints of a trajectory message; false (with `why`) when it names no arm joint or is malformed.
bool fromTrajectory(const trajectory_msgs::JointTrajectory& msg, std::vector<TrajectoryPoint>& points,
                    std::array<bool, kArmJoints>& mask, std::string& why);

}  // namespace conversions
}  // namespace rascal_sim
