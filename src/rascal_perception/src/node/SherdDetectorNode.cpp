#include "SherdDetectorNode.hpp"

#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "Conversions.hpp"
#include "rascal_perception/Annotator.hpp"
#include "rascal_workcell/ParameterServer.hpp"

namespace rascal_perception {

namespace {
constexpr const char* kOpticalFrame = "camera_color_optical_frame";
constexpr size_t kBuffer = 15;  ///< frames kept per stream (0.5 s at 30 Hz)
constexpr double kPairSlop = 0.015;  ///< [s] colour and depth stamps closer than this are one frame
constexpr double kTfWait = 0.5;  ///< [s] of wall and of ROS time for the camera's transform at a frame's stamp
/// [s] a kept background older than this is not restored at start-up: the light of another day
constexpr double kRestoreWithin = 8 * 3600.0;

/// Wall-clock seconds since the epoch: kept backgrounds outlive the simulator's clock.
double wallNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

/// $ROS_HOME/rascal/backgrounds (ROS_HOME defaults to ~/.ros), where backgrounds are kept.
std::string defaultBackgroundDir() {
  const char* home = std::getenv("ROS_HOME");
  if (home && *home) return std::string(home) + "/rascal/backgrounds";
  const char* user = std::getenv("HOME");
  return std::string(user && *user ? user : ".") + "/.ros/rascal/backgrounds";
}

/// What a station's kept background depends on: where the station and its fixtures are (a
/// background learnt before `rascal calibrate` moved the station masks the wrong places).
std::string layoutKey(const rascal_workcell::Station& s) {
  std::ostringstream k;
  k.precision(5);
  k << std::fixed << static_cast<int>(s.type) << " " << s.surface_z << " " << s.wall_height << " " << s.stand_height;
  for (const rascal_workcell::TableRect* r : {&s.area, &s.colour_chart, &s.scale_bar, &s.stand}) {
    k << " " << r->centre.x() << " " << r->centre.y() << " " << r->size.x() << " " << r->size.y();
  }
  k << " " << s.place_at.x() << " " << s.place_at.y();
  if (s.area.yaw != 0.0) k << " yaw " << s.area.yaw;  // keys of square stations as before
  return k.str();
}

/// The gripper from the URDF the rig runs (/robot_description), else rascal_description's.
rascal_workcell::GripperGeometry gripperGeometry() {
  std::string xml;
  if (!ros::param::get("/robot_description", xml)) return rascal_workcell::GripperGeometry::fromPackageUrdf();
  try {
    return rascal_workcell::GripperGeometry::fromUrdf(xml);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("/robot_description: ") + e.what());
  }
}
}  // namespace

SherdDetectorNode::SherdDetectorNode(ros::NodeHandle& root, ros::NodeHandle& private_nh) : tf_listener_(tf_buffer_) {
  readParameters();
  detector_ = std::make_unique<SherdDetector>(params_.config);
  // a restarted detector picks up the backgrounds it had learnt (see BackgroundStore)
  store_ = std::make_unique<BackgroundStore>(private_nh.param("background_dir", defaultBackgroundDir()));
  const double restore_within = private_nh.param("restore_within", kRestoreWithin);
  for (const rascal_workcell::Station& st : params_.workcell.stations()) {
    std::string message;
    const bool restored = store_->restore(*detector_, st.name, layoutKey(st), wallNow(), restore_within, message);
    if (restored) ROS_INFO_STREAM("sherd_detector: " << message);
    else if (!message.empty()) ROS_WARN_STREAM("sherd_detector: " << message);
  }
  colour_sub_ = root.subscribe("/camera/color/image_raw", 2, &SherdDetectorNode::onColour, this);
  depth_sub_ = root.subscribe("/camera/aligned_depth_to_color/image_raw", 2, &SherdDetectorNode::onDepth, this);
  info_sub_ = root.subscribe("/camera/color/camera_info", 1, &SherdDetectorNode::onInfo, this);
  detect_srv_ = root.advertiseService("/rascal/perception/detect", &SherdDetectorNode::onDetect, this);
  calibrate_srv_ =
      root.advertiseService("/rascal/perception/calibrate_background", &SherdDetectorNode::onCalibrate, this);
  markers_pub_ = root.advertise<visualization_msgs::MarkerArray>("/rascal/detections", 1, true);
  annotated_pub_ = root.advertise<sensor_msgs::Image>("/rascal/perception/annotated", 1, true);
  std::ostringstream s;
  for (const rascal_workcell::Station& st : params_.workcell.stations()) s << " " << st.name << "@" << st.surface_z;
  const PerceptionConfig& c = params_.config;
  ROS_INFO_STREAM("sherd_detector: started; stations" << s.str() << ", " << c.background_clusters
                                                      << " background clusters, gripper " << c.gripper.minOpening()
                                                      << ".." << c.gripper.maxOpening() << " m, fingertips "
                                                      << c.gripper.fingertip_offset << " m below ee_gripper_link");
}

void SherdDetectorNode::readParameters() {
  const rascal_workcell::Parameters config = rascal_workcell::parametersFromServer("sherd_detector");
  params_ = DetectorParameters::read(config, gripperGeometry());
}

const rascal_workcell::Station* SherdDetectorNode::findStation(const std::string& name, std::string& why) const {
  const rascal_workcell::Station* s = params_.workcell.find(name);
  if (!s) why = "unknown station '" + name + "' (not a station under stations in config/rascal.yaml)";
  return s;
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
    if ((ros::Time::now() - since).toSec() > params_.frame_wait || (ros::WallTime::now() - wall_start).toSec() > 5.0 * params_.frame_wait + 2.0) {
      std::lock_guard<std::mutex> lock(mutex_);
      why = colours_.empty() ? "no image on /camera/color/image_raw"
                             : (depths_.empty() ? "no image on /camera/aligned_depth_to_color/image_raw"
                                                : "no colour + depth pair stamped after the request within " +
                                                      std::to_string(params_.frame_wait) + " s");
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
    // waited for in wall time and in ROS time, whichever lasts longer: the transform's lag is
    // the publisher's (robot_state_publisher behind on busy cores), and with the simulator as
    // fast as it runs half a second of ROS time went by in a few milliseconds (stale
    // wrist-camera TF stopped a batch: e2e); slower than real time, ROS time lasts longer
    const ros::Time stamp = frame.colour->header.stamp;
    const ros::WallTime wall_deadline = ros::WallTime::now() + ros::WallDuration(kTfWait);
    const ros::Time ros_deadline = ros::Time::now() + ros::Duration(kTfWait);
    while (ros::ok() && (ros::WallTime::now() < wall_deadline || ros::Time::now() < ros_deadline) &&
           !tf_buffer_.canTransform(base_frame_, frame_id, stamp)) {
      ros::WallDuration(0.005).sleep();
    }
    const auto t = tf_buffer_.lookupTransform(base_frame_, frame_id, stamp);
    view.base_T_camera = tf2::transformToEigen(t);
  } catch (const tf2::TransformException& e) {
    why = "TF " + base_frame_ + " <- " + frame_id + ": " + e.what();
    return false;
  }
  return true;
}

void SherdDetectorNode::keep(const rascal_workcell::Station& station) {
  try {
    store_->save(*detector_, station.name, layoutKey(station), wallNow());
  } catch (const std::exception& e) {
    ROS_WARN_STREAM("sherd_detector: background of " << station.name << " not kept on disk (a restarted "
                                                     << "detector must calibrate it again): " << e.what());
  }
}

bool SherdDetectorNode::onCalibrate(rascal_msgs::CalibrateBackground::Request& req,
                                    rascal_msgs::CalibrateBackground::Response& res) {
  try {
    const ros::Time since = ros::Time::now();
    std::string why;
    const rascal_workcell::Station* station = findStation(req.station, why);
    if (!station) {
      res.message = why;
      return true;
    }
    Frame frame;
    cv::Mat rgb, depth;
    CameraView view;
    if (!waitForFrame(since, frame, why) || !prepare(frame, rgb, depth, view, why)) {
      res.message = "station " + req.station + ": " + why;
      return true;
    }
    std::lock_guard<std::mutex> lock(detector_mutex_);
    const CalibrationResult r = detector_->calibrate(req.station, rgb, depth, view, station->surface_z);
    if (r.success) {
      refreshed_[req.station] = frame.colour->header.stamp;
      keep(*station);
    }
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
    std::string why;
    const rascal_workcell::Station* station = findStation(req.station, why);
    if (!station) {
      res.message = why;
      return true;
    }
    Frame frame;
    cv::Mat rgb, depth;
    CameraView view;
    if (!waitForFrame(since, frame, why) || !prepare(frame, rgb, depth, view, why)) {
      res.message = "station " + req.station + ": " + why;
      return true;
    }
    DetectionResult r;
    {
      std::lock_guard<std::mutex> lock(detector_mutex_);
      r = detector_->detect(req.station, rgb, depth, view, station->surface_z);
      // the paper refreshes its colour masks now and then: light drifts during a batch
      const ros::Time stamp = frame.colour->header.stamp;
      if (r.success && params_.refresh_period > 0 && (stamp - refreshed_[req.station]).toSec() >= params_.refresh_period) {
        const CalibrationResult f = detector_->refresh(req.station, rgb, depth, view, station->surface_z);
        if (f.success) {
          refreshed_[req.station] = stamp;
          keep(*station);
        }
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
    for (const Leftover& l : r.leftovers) res.leftovers.push_back(conversions::toLeftover(l));
    markers_pub_.publish(conversions::markers(r.sherds, header, r.leftovers));
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
