#pragma once
// ROS wrapper of the perception core: parameters, camera subscriptions, TF, the detect and
// calibrate_background services, markers and the annotated image.
#include <ros/ros.h>
#include <rascal_msgs/CalibrateBackground.h>
#include <rascal_msgs/Detect.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "rascal_perception/BackgroundStore.hpp"
#include "rascal_perception/DetectorParameters.hpp"
#include "rascal_perception/SherdDetector.hpp"

namespace rascal_perception {

class SherdDetectorNode {
 public:
  /// Reads and checks every parameter through the schema (throws rascal_workcell::ParameterError
  /// naming the key, std::runtime_error naming /robot_description), then subscribes, serves and
  /// advertises.
  SherdDetectorNode(ros::NodeHandle& root, ros::NodeHandle& private_nh);

 private:
  struct Frame {
    sensor_msgs::ImageConstPtr colour, depth;
  };
  void readParameters();
  void onColour(const sensor_msgs::ImageConstPtr& msg);
  void onDepth(const sensor_msgs::ImageConstPtr& msg);
  void onInfo(const sensor_msgs::CameraInfoConstPtr& msg);
  bool onDetect(rascal_msgs::Detect::Request& req, rascal_msgs::Detect::Response& res);
  bool onCalibrate(rascal_msgs::CalibrateBackground::Request& req, rascal_msgs::CalibrateBackground::Response& res);
  /// The first colour + depth pair stamped at or after `since` (waits up to frame_wait of ROS time).
  bool waitForFrame(const ros::Time& since, Frame& frame, std::string& why);
  /// Images, intrinsics and base_link <- optical frame of a pair.
  bool prepare(const Frame& frame, cv::Mat& rgb, cv::Mat& depth, CameraView& view, std::string& why);

  /// The workcell station a request names; nullptr (and `why`) when there is none of that name.
  const rascal_workcell::Station* findStation(const std::string& name, std::string& why) const;

  DetectorParameters params_;  ///< perception config, workcell, frame_wait, refresh_period
  std::map<std::string, ros::Time> refreshed_;  ///< last calibration or refresh per station
  std::string base_frame_ = "base_link";

  std::mutex mutex_;  ///< guards the frame buffers and camera info
  std::deque<sensor_msgs::ImageConstPtr> colours_, depths_;
  sensor_msgs::CameraInfoConstPtr info_;
  std::mutex detector_mutex_;  ///< one service call at a time uses the detector
  std::unique_ptr<SherdDetector> detector_;
  std::unique_ptr<BackgroundStore> store_;  ///< each station's background on disk
  /// Gives the store the station's background just learnt (a failure only warns: the model in
  /// memory serves this run). Called with detector_mutex_ held.
  void keep(const rascal_workcell::Station& station);

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Subscriber colour_sub_, depth_sub_, info_sub_;
  ros::ServiceServer detect_srv_, calibrate_srv_;
  ros::Publisher markers_pub_, annotated_pub_;
};

}  // namespace rascal_perception
