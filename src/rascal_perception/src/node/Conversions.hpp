#pragma once
// Stateless conversions between ROS messages and the perception core's types (one place).
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <rascal_msgs/Sherd.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rascal_perception/Types.hpp"

namespace rascal_perception {
namespace conversions {

/// rgb8 / bgr8 -> CV_8UC3 RGB; throws std::invalid_argument naming the encoding.
cv::Mat colourImage(const sensor_msgs::Image& msg);
/// 16UC1 [mm] (or 32FC1 [m]) -> CV_16UC1 [mm].
cv::Mat depthImage(const sensor_msgs::Image& msg);
sensor_msgs::Image toImage(const cv::Mat& rgb, const std_msgs::Header& header);
CameraIntrinsics intrinsics(const sensor_msgs::CameraInfo& info);
Eigen::Isometry3d toEigen(const geometry_msgs::Transform& t);
geometry_msgs::Pose toPose(const Eigen::Isometry3d& pose);
rascal_msgs::Sherd toSherd(const SherdDetection& d, const std_msgs::Header& header, uint32_t id);
/// Oriented boxes, grasp arrows and labels (namespace per kind), after a DELETEALL.
visualization_msgs::MarkerArray markers(const std::vector<SherdDetection>& sherds, const std_msgs::Header& header);

}  // namespace conversions
}  // namespace rascal_perception
