#include "SherdDetectorNode.hpp"

#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "Conversions.hpp"
#include "rascal_perception/Annotator.hpp"

namespace rascal_perception {

namespace {
constexpr const char* kOpticalFrame = "camera_color_optical_frame";
constexpr size_t kBuffer = 15;  ///< frames kept per stream (0.5 s at 30 Hz)
constexpr double kPairSlop = 0.015;  ///< [s] colour and depth stamps closer than this are one frame

[[noreturn]] void fail(const std::string& key, const std::string& why) {
  throw std::runtime_error("parameter " + key + ": " + why);
}

double number(const ros::NodeHandle& nh, const std::string& key, double lo, double hi, const double* def = nullptr) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(key, v)) {
    if (def) return *def;
    fail(key, "missing (load config/rascal.yaml with rosparam load)");
  }
  double x;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    x = static_cast<double>(v);
  } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    x = static_cast<int>(v);
  } else {
    fail(key, "not a number");
  }
  if (!(x >= lo && x <= hi)) {
    std::ostringstream s;
    s << x << " outside [" << lo << ", " << hi << "]";
    fail(key, s.str());
  }
  return x;
}

double optional(const ros::NodeHandle& nh, const std::string& key, double def, double lo, double hi) {
  return number(nh, key, lo, hi, &def);
}

int integer(const ros::NodeHandle& nh, const std::string& key, int lo, int hi) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(key, v)) fail(key, "missing (load config/rascal.yaml with rosparam load)");
  if (v.getType() != XmlRpc::XmlRpcValue::TypeInt) fail(key, "not an integer");
  const int x = static_cast<int>(v);
  if (x < lo || x > hi) fail(key, std::to_string(x) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}
}  // namespace

SherdDetectorNode::SherdDetectorNode(ros::NodeHandle& root, ros::NodeHandle& private_nh) : tf_listener_(tf_buffer_) {
  (void)private_nh;
  readParameters(root);
  detector_ = std::make_unique<SherdDetector>(config_);
  colour_sub_ = root.subscribe("/camera/color/image_raw", 2, &SherdDetectorNode::onColour, this);
  depth_sub_ = root.subscribe("/camera/aligned_depth_to_color/image_raw", 2, &SherdDetectorNode::onDepth, this);
  info_sub_ = root.subscribe("/camera/color/camera_info", 1, &SherdDetectorNode::onInfo, this);
  detect_srv_ = root.advertiseService("/rascal/perception/detect", &SherdDetectorNode::onDetect, this);
  calibrate_srv_ =
      root.advertiseService("/rascal/perception/calibrate_background", &SherdDetectorNode::onCalibrate, this);
  markers_pub_ = root.advertise<visualization_msgs::MarkerArray>("/rascal/detections", 1, true);
  annotated_pub_ = root.advertise<sensor_msgs::Image>("/rascal/perception/annotated", 1, true);
  std::ostringstream s;
  for (const auto& [name, z] : surfaces_) s << " " << name << "@" << z;
  ROS_INFO_STREAM("sherd_detector: started; stations" << s.str() << ", " << config_.background_clusters
                                                      << " background clusters");
}

void SherdDetectorNode::readParameters(ros::NodeHandle& nh) {
  PerceptionConfig& c = config_;
  c.background_clusters = integer(nh, "/perception/background_clusters", 1, 8);
  c.hue_tolerance = number(nh, "/perception/hue_tolerance", 0.001, 0.5);
  c.saturation_tolerance = number(nh, "/perception/saturation_tolerance", 0.001, 1.0);
  c.min_value = number(nh, "/perception/min_value", 0.0, 0.99);
  c.fixture_dilation = number(nh, "/perception/fixture_dilation", 0.0, 0.1);
  c.min_sherd_size = number(nh, "/perception/min_sherd_size", 0.001, 0.5);
  c.max_sherd_size = number(nh, "/perception/max_sherd_size", c.min_sherd_size, 1.0);
  c.border_margin = integer(nh, "/perception/border_margin", 0, 100);
  std::string policy;
  if (!nh.getParam("/perception/selection_policy", policy)) {
    fail("/perception/selection_policy", "missing or not a string (nearest | largest | most_isolated)");
  }
  try {
    c.selection_policy = parseSelectionPolicy(policy);
  } catch (const std::invalid_argument& e) {
    fail("/perception/selection_policy", e.what());
  }
  c.depth_min = number(nh, "/perception/depth_min", 0.0, 10.0);
  c.depth_max = number(nh, "/perception/depth_max", c.depth_min, 65.0);
  c.grasp_height_fraction = optional(nh, "/perception/grasp_height_fraction", c.grasp_height_fraction, 0.1, 1.0);
  c.grasp_tip_clearance = optional(nh, "/perception/grasp_tip_clearance", c.grasp_tip_clearance, 0.0, 0.05);
  c.fingertip_offset = optional(nh, "/perception/fingertip_offset", c.fingertip_offset, -0.05, 0.05);
  c.split_min_neck = optional(nh, "/perception/split_min_neck", c.split_min_neck, 0.1, 1.0);
  c.min_sherd_height = optional(nh, "/perception/min_sherd_height", c.min_sherd_height, 0.0005, 0.05);
  wait_s_ = optional(nh, "/perception/frame_wait", wait_s_, 0.05, 10.0);
  refresh_period_ = optional(nh, "/perception/refresh_period", refresh_period_, 0.0, 86400.0);
  c.grasp_margin = number(nh, "/arm/grasp_margin", 0.0, 0.05);

  XmlRpc::XmlRpcValue stations;
  if (!nh.getParam("/stations", stations) || stations.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    fail("/stations", "missing or not a map of stations");
  }
  for (auto it = stations.begin(); it != stations.end(); ++it) {
    surfaces_[it->first] = number(nh, "/stations/" + it->first + "/surface_z", -1.0, 1.0);
  }
  if (surfaces_.empty()) fail("/stations", "no stations");
}

void SherdDetectorNode::onColour(const sensor_msgs::ImageConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  colours_.push_back(msg);
  while (colours_.size() > kBuffer) colours_.pop_front();
}

void SherdDetectorNode::onDepth(const sensor_msgs::ImageConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  depths_.push_back(msg);
  while (depths_.size() > kBuffer) depths_.pop_front();
}

void SherdDetectorNode::onInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  info_ = msg;
}

bool SherdDetectorNode::waitForFrame(const ros::Time& since, Frame& frame, std::string& why) {
  const ros::WallTime wall_start = ros::WallTime::now();
  while (ros::ok()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // the newest colour image at or after `since` with a depth image within kPairSlop of it
      // (the simulator stamps both alike; a real aligned depth may be a few ms off)
      for (auto c = colours_.rbegin(); c != colours_.rend(); ++c) {
        if ((*c)->header.stamp < since) break;
        double best = kPairSlop;
        for (const auto& d : depths_) {
          const double dt = std::fabs(((*c)->header.stamp - d->header.stamp).toSec());
          if (dt <= best) {
            best = dt;
            frame.colour = *c;
            frame.depth = d;
          }
        }
        if (frame.colour) return true;
      }
    }
    if ((ros::Time::now() - since).toSec() > wait_s_ || (ros::WallTime::now() - wall_start).toSec() > 5.0 * wait_s_ + 2.0) {
      std::lock_guard<std::mutex> lock(mutex_);
      why = colours_.empty() ? "no image on /camera/color/image_raw"
                             : (depths_.empty() ? "no image on /camera/aligned_depth_to_color/image_raw"
                                                : "no colour + depth pair stamped after the request within " +
                                                      std::to_string(wait_s_) + " s");
      return false;
    }
    ros::WallDuration(0.005).sleep();
  }
  why = "shutting down";
  return false;
}

bool SherdDetectorNode::prepare(const Frame& frame, cv::Mat& rgb, cv::Mat& depth, CameraView& view, std::string& why) {
  sensor_msgs::CameraInfoConstPtr info;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    info = info_;
  }
  if (!info) {
    why = "no camera info on /camera/color/camera_info";
    return false;
  }
  try {
    rgb = conversions::colourImage(*frame.colour);
    depth = conversions::depthImage(*frame.depth);
    view.intrinsics = conversions::intrinsics(*info);
  } catch (const std::exception& e) {
    why = std::string("/camera images: ") + e.what();
    return false;
  }
  if (depth.size() != rgb.size() || view.intrinsics.width != rgb.cols || view.intrinsics.height != rgb.rows) {
    why = "colour, depth and camera_info sizes differ";
    return false;
  }
  const std::string& frame_id = frame.colour->header.frame_id.empty() ? kOpticalFrame : frame.colour->header.frame_id;
  try {
    const auto t = tf_buffer_.lookupTransform(base_frame_, frame_id, frame.colour->header.stamp, ros::Duration(0.5));
    view.base_T_camera = conversions::toEigen(t.transform);
  } catch (const tf2::TransformException& e) {
    why = "TF " + base_frame_ + " <- " + frame_id + ": " + e.what();
    return false;
  }
  return true;
}

bool SherdDetectorNode::onCalibrate(rascal_msgs::CalibrateBackground::Request& req,
                                    rascal_msgs::CalibrateBackground::Response& res) {
  try {
    const ros::Time since = ros::Time::now();
    auto station = surfaces_.find(req.station);
    if (station == surfaces_.end()) {
      res.message = "unknown station '" + req.station + "' (not a key under /stations)";
      return true;
    }
    Frame frame;
    cv::Mat rgb, depth;
    CameraView view;
    std::string why;
    if (!waitForFrame(since, frame, why) || !prepare(frame, rgb, depth, view, why)) {
      res.message = "station " + req.station + ": " + why;
      return true;
    }
    std::lock_guard<std::mutex> lock(detector_mutex_);
    const CalibrationResult r = detector_->calibrate(req.station, rgb, depth, view, station->second);
    if (r.success) refreshed_[req.station] = frame.colour->header.stamp;
    res.success = r.success;
    res.message = r.message;
    res.clusters = r.clusters;
    res.fixture_fraction = r.fixture_fraction;
    ROS_INFO_STREAM("sherd_detector: " << r.message);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = std::string("calibrate_background failed: ") + e.what();
    ROS_ERROR_STREAM("sherd_detector: /rascal/perception/calibrate_background: " << e.what());
  }
  return true;
}

bool SherdDetectorNode::onDetect(rascal_msgs::Detect::Request& req, rascal_msgs::Detect::Response& res) {
  try {
    const ros::Time since = ros::Time::now();
    res.detections.station = req.station;
    res.detections.header.frame_id = base_frame_;
    auto station = surfaces_.find(req.station);
    if (station == surfaces_.end()) {
      res.message = "unknown station '" + req.station + "' (not a key under /stations)";
      return true;
    }
    Frame frame;
    cv::Mat rgb, depth;
    CameraView view;
    std::string why;
    if (!waitForFrame(since, frame, why) || !prepare(frame, rgb, depth, view, why)) {
      res.message = "station " + req.station + ": " + why;
      return true;
    }
    DetectionResult r;
    {
      std::lock_guard<std::mutex> lock(detector_mutex_);
      r = detector_->detect(req.station, rgb, depth, view, station->second);
      // the paper refreshes its colour masks now and then: light drifts during a batch
      const ros::Time stamp = frame.colour->header.stamp;
      if (r.success && refresh_period_ > 0 && (stamp - refreshed_[req.station]).toSec() >= refresh_period_) {
        const CalibrationResult f = detector_->refresh(req.station, rgb, depth, view, station->second);
        if (f.success) refreshed_[req.station] = stamp;
        ROS_INFO_STREAM("sherd_detector: " << f.message);
      }
    }
    res.success = r.success;
    res.message = r.message;
    std_msgs::Header header;
    header.frame_id = base_frame_;
    header.stamp = frame.colour->header.stamp;
    res.detections.header = header;
    for (size_t i = 0; i < r.sherds.size(); ++i) {
      res.detections.sherds.push_back(conversions::toSherd(r.sherds[i], header, static_cast<uint32_t>(i)));
    }
    markers_pub_.publish(conversions::markers(r.sherds, header));
    if (annotated_pub_.getNumSubscribers() > 0 || annotated_pub_.isLatched()) {
      std_msgs::Header image_header = frame.colour->header;
      annotated_pub_.publish(conversions::toImage(Annotator::draw(rgb, r.sherds, cv::Mat(), &view), image_header));
    }
  } catch (const std::exception& e) {
    res.success = false;
    res.message = std::string("detect failed: ") + e.what();
    ROS_ERROR_STREAM("sherd_detector: /rascal/perception/detect: " << e.what());
  }
  return true;
}

}  // namespace rascal_perception
