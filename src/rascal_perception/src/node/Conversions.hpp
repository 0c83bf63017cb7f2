#pragma once
// Stateless conversions between ROS messages and the perception core's types (one place):
// images through cv_bridge, poses and transforms through tf2_eigen; what no library has (the
// camera intrinsics, the Sherd message, the markers) written here.
#include <rascal_msgs/Leftover.h>
#include <rascal_msgs/Sherd.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rascal_perception/Types.hpp"

namespace rascal_perception {
namespace conversions {

/// rgb8 / bgr8 -> CV_8UC3 RGB (a copy); throws std::invalid_argument naming the encoding or
/// the malformed image.
cv::Mat colourImage(const sensor_msgs::Image& msg);
/// 16UC1 (or mono16) [mm] -> CV_16UC1 [mm], a copy; 32FC1 [m] -> CV_16UC1 [mm] (rounded; NaN and
/// values <= 0 become 0 = no depth, beyond 65.535 m saturate). Throws std::invalid_argument
/// naming the encoding or the malformed image.
cv::Mat depthImage(const sensor_msgs::Image& msg);
/// CV_8UC3 RGB -> rgb8.
sensor_msgs::Image toImage(const cv::Mat& rgb, const std_msgs::Header& header);
/// K of the colour stream; throws std::invalid_argument without a focal length.
CameraIntrinsics intrinsics(const sensor_msgs::CameraInfo& info);
rascal_msgs::Sherd toSherd(const SherdDetection& d, const std_msgs::Header& header, uint32_t id);
rascal_msgs::Leftover toLeftover(const Leftover& l);
/// Oriented boxes, grasp arrows and labels (namespace per kind), after a DELETEALL; leftovers as
/// flat yellow discs labelled with why they are not offered.
visualization_msgs::MarkerArray markers(const std::vector<SherdDetection>& sherds, const std_msgs::Header& header,
                                        const std::vector<Leftover>& leftovers = {});

}  // namespace conversions
}  // namespace rascal_perception
