#include "SimNode.hpp"

#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>
#include <rascal_msgs/ScaleReading.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Header.h>

#include <malloc.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "Conversions.hpp"
#include "rascal_sim/ScenarioLoader.hpp"
#include "rascal_workcell/GripperGeometry.hpp"
#include "rascal_workcell/ParameterServer.hpp"

namespace rascal_sim {

namespace fs = std::filesystem;

namespace {
const char* const kOpticalFrame = "camera_color_optical_frame";

std::string resolve(const std::string& root, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  const fs::path in_root = fs::path(root) / path;
  if (fs::exists(in_root) || !fs::exists(path)) return in_root.string();
  return fs::absolute(path).string();
}
}  // namespace

SimNode::SimNode(ros::NodeHandle&) {
  // image buffers are allocated every frame: keep them on the heap instead of fresh mmap pages
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  readParameters();
  munsell_ = std::make_unique<MunsellTable>(config_.layout.data_dir + "/munsell_soil_hues_grid_renotation.csv");
  ScenarioLoader loader(config_.layout, *munsell_);
  Scenario scenario;
  try {
    scenario = loader.load(scenario_path_);
  } catch (const std::exception& e) {
    throw rascal_workcell::ParameterError("simulator.scenario: " + std::string(e.what()));
  }
  sim_ = std::make_unique<Simulator>(config_.layout, config_.options);
  sim_->load(scenario);

  ros::NodeHandle root;
  clock_pub_ = root.advertise<rosgraph_msgs::Clock>("/clock", 10);
  joint_pub_ = root.advertise<sensor_msgs::JointState>("/joint_states", 10);
  scale_pub_ = root.advertise<rascal_msgs::ScaleReading>("/scale/mass", 10);
  colour_pub_ = root.advertise<sensor_msgs::Image>("/camera/color/image_raw", 2);
  depth_pub_ = root.advertise<sensor_msgs::Image>("/camera/aligned_depth_to_color/image_raw", 2);
  colour_info_pub_ = root.advertise<sensor_msgs::CameraInfo>("/camera/color/camera_info", 2);
  depth_info_pub_ = root.advertise<sensor_msgs::CameraInfo>("/camera/aligned_depth_to_color/camera_info", 2);
  cloud_pub_ = root.advertise<sensor_msgs::PointCloud2>("/camera/depth/color/points", 2);
  // the shutter has closed: the arm may come back over the sherd during the transfer
  exposed_pub_ = root.advertise<std_msgs::Header>("/archival_camera/exposed", 4);
  arm_sub_ = root.subscribe("/arm/joint_trajectory", 10, &SimNode::onArmTrajectory, this);
  gripper_sub_ = root.subscribe("/gripper/command", 10, &SimNode::onGripperCommand, this);
  tare_srv_ = root.advertiseService("/scale/tare", &SimNode::onTare, this);
  capture_srv_ = root.advertiseService("/archival_camera/capture", &SimNode::onCapture, this);
  truth_srv_ = root.advertiseService("/sim/ground_truth", &SimNode::onGroundTruth, this);
  spawn_srv_ = root.advertiseService("/sim/spawn", &SimNode::onSpawn, this);
  reset_srv_ = root.advertiseService("/sim/reset", &SimNode::onReset, this);
  fault_srv_ = root.advertiseService("/sim/inject_fault", &SimNode::onInjectFault, this);

  sendStaticFrames();
  ROS_INFO_STREAM("sim: started with scenario " << scenario.name << " (" << scenario.sherds.size()
                  << " sherds), real_time_factor " << config_.real_time_factor << ", wrist camera "
                  << (config_.options.wrist_camera ? "on" : "off"));
}

void SimNode::sendStaticFrames() {
  // where the scenario has the stations really stand (its station_offsets), as a rig's would be
  const Station& station = sim_->world().layout().station(StationType::Scale);
  Eigen::Isometry3d scale = Eigen::Isometry3d::Identity();
  scale.translation() = Eigen::Vector3d(station.area.centre.x(), station.area.centre.y(), station.surface_z);
  scale.linear() = Eigen::AngleAxisd(station.area.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  static_tf_.sendTransform({conversions::toTransform(sim_->archival().pose(), "base_link",
                                                     "archival_camera_optical_frame", ros::Time(0)),
                            conversions::toTransform(scale, "base_link", "scale_link", ros::Time(0))});
}

void SimNode::readParameters() {
  const std::string pkg = ros::package::getPath("rascal_sim");
  workspace_ = fs::path(pkg).parent_path().parent_path().string();
  config_ = SimParameters::read(rascal_workcell::parametersFromServer("sim"),
                                rascal_workcell::GripperGeometry::fromPackageUrdf(), pkg + "/data");
  scenario_path_ = resolve(workspace_, config_.scenario);
  spool_dir_ = resolve(workspace_, config_.spool_dir);
}

bool SimNode::cameraWanted() const {
  return colour_pub_.getNumSubscribers() + depth_pub_.getNumSubscribers() + cloud_pub_.getNumSubscribers() +
             colour_info_pub_.getNumSubscribers() + depth_info_pub_.getNumSubscribers() > 0;
}

void SimNode::run() {
  ros::AsyncSpinner spinner(3);
  spinner.start();
  const ros::WallTime wall0 = ros::WallTime::now();
  double sim0 = 0.0, next_clock = 0.0, next_joints = 0.0;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    sim0 = sim_->time();
  }
  const auto& names = ArmKinematics::jointNames();
  while (ros::ok()) {
    double t = 0.0;
    bool clock = false, joints = false, scale = false, frame_ready = false;
    sensor_msgs::JointState js;
    ScaleReading reading;
    WristFrame frame;
    {
      std::lock_guard<std::mutex> lk(mutex_);
      sim_->step();
      t = sim_->time();
      if (t >= next_clock - 1e-9) {
        clock = true;
        while (next_clock <= t + 1e-9) next_clock += config_.clock_period;
      }
      if (t >= next_joints - 1e-9) {
        joints = true;
        while (next_joints <= t + 1e-9) next_joints += config_.joint_state_period;
        js.header.stamp = ros::Time(t);
        js.name.assign(names.begin(), names.end());
        js.name.push_back("left_finger");
        js.name.push_back("right_finger");
        const auto& q = sim_->jointPositions();
        const auto& v = sim_->jointVelocities();
        js.position.assign(q.begin(), q.end());
        js.velocity.assign(v.begin(), v.end());
        js.position.push_back(sim_->fingerPosition());
        js.position.push_back(-sim_->fingerPosition());
        js.velocity.push_back(sim_->fingerVelocity());
        js.velocity.push_back(-sim_->fingerVelocity());
      }
      scale = sim_->takeScaleReading(reading);
      for (const std::string& line : sim_->takeLogLines()) {  // each close and bump, for benches
        ROS_INFO_STREAM("sim: " << line);
        std::fflush(stdout);  // block-buffered into a file: a bench reads it while this runs
      }
      if (sim_->wristFrameDue()) {
        if (cameraWanted()) {
          frame = sim_->renderWristFrame();
          frame_ready = true;
        } else {
          sim_->skipWristFrame();
        }
      }
    }
    stepped_.notify_all();
    if (clock) {
      rosgraph_msgs::Clock c;
      c.clock = ros::Time(t);
      clock_pub_.publish(c);
    }
    if (joints) joint_pub_.publish(js);
    if (scale) {
      rascal_msgs::ScaleReading m;
      m.header.stamp = ros::Time(reading.stamp);
      m.header.frame_id = "scale_link";
      m.mass = reading.mass;
      m.stable = reading.stable;
      scale_pub_.publish(m);
    }
    if (frame_ready) publishWristFrame(frame);
    if (config_.real_time_factor > 0.0) {
      const ros::WallTime due = wall0 + ros::WallDuration((t - sim0) / config_.real_time_factor);
      const ros::WallDuration ahead = due - ros::WallTime::now();
      if (ahead.toSec() > 0.001) ahead.sleep();
    }
  }
  stepped_.notify_all();
  spinner.stop();
}

void SimNode::publishWristFrame(const WristFrame& f) {
  const ros::Time stamp(f.stamp);
  const CameraModel& cam = sim_->wristModel();
  colour_pub_.publish(conversions::toImage(f.rgb, "rgb8", kOpticalFrame, stamp));
  depth_pub_.publish(conversions::toImage(f.depth_mm, "16UC1", kOpticalFrame, stamp));
  const sensor_msgs::CameraInfo info = conversions::toCameraInfo(cam, kOpticalFrame, stamp);
  colour_info_pub_.publish(info);
  depth_info_pub_.publish(info);
  if (config_.point_cloud && cloud_pub_.getNumSubscribers() > 0) {
    cloud_pub_.publish(conversions::toPointCloud(f.depth_mm, f.rgb, cam, kOpticalFrame, stamp));
  }
}

void SimNode::onArmTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
  std::vector<TrajectoryPoint> points;
  std::array<bool, kArmJoints> mask;
  std::string why;
  if (!conversions::fromTrajectory(*msg, points, mask, why)) {
    ROS_WARN_STREAM("sim: /arm/joint_trajectory ignored: " << why);
    return;
  }
  std::lock_guard<std::mutex> lk(mutex_);
  const double start = msg->header.stamp.isZero() ? sim_->time() : msg->header.stamp.toSec();
  sim_->commandArm(start, points, mask);
}

void SimNode::onGripperCommand(const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
  int idx = -1;
  for (size_t i = 0; i < msg->joint_names.size(); ++i) {
    if (msg->joint_names[i] == "left_finger") idx = static_cast<int>(i);
  }
  std::lock_guard<std::mutex> lk(mutex_);
  if (msg->points.empty()) {
    sim_->stopGripper();  // stop where the fingers are (a held sherd stays held)
    return;
  }
  if (idx < 0 || msg->points.back().positions.size() <= static_cast<size_t>(idx)) {
    ROS_WARN("sim: /gripper/command ignored: needs joint left_finger with one position [m]");
    return;
  }
  sim_->commandGripper(msg->points.back().positions[idx]);
}

bool SimNode::onTare(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lk(mutex_);
  sim_->tareScale();
  res.success = true;
  res.message = "scale tared";
  return true;
}

bool SimNode::waitUntil(std::unique_lock<std::mutex>& lock, double t) {
  while (sim_->time() < t - 1e-9) {
    if (!ros::ok()) return false;
    stepped_.wait_for(lock, std::chrono::milliseconds(50));
  }
  return true;
}

bool SimNode::onCapture(rascal_msgs::CaptureArchival::Request& req, rascal_msgs::CaptureArchival::Response& res) {
  try {
    if (!req.path.empty() && !fs::path(req.path).is_absolute()) {
      res.success = false;
      res.message = "path must be absolute: " + req.path;
      return true;
    }
    std::unique_lock<std::mutex> lk(mutex_);
    std::string why;
    if (!sim_->triggerCapture(why, req.exposure_ev)) {
      res.success = false;
      res.message = why;
      return true;
    }
    ArchivalCamera& cam = sim_->archival();
    res.stamp = ros::Time(cam.shutterTime());
    res.width = static_cast<uint32_t>(cam.model().width);
    res.height = static_cast<uint32_t>(cam.model().height);
    while (cam.state() == ArchivalCamera::State::kShutter && ros::ok()) {
      stepped_.wait_for(lk, std::chrono::milliseconds(50));
    }
    if (cam.state() == ArchivalCamera::State::kFailed || cam.state() == ArchivalCamera::State::kShutter) {
      waitUntil(lk, cam.readyTime());
      res.success = false;
      res.message = cam.state() == ArchivalCamera::State::kFailed ? cam.message() : "shut down during capture";
      cam.acknowledge();
      return true;
    }
    std_msgs::Header exposed;
    exposed.stamp = res.stamp;
    exposed.frame_id = "archival_camera_optical_frame";
    exposed_pub_.publish(exposed);
    const cv::Mat image = cam.image();
    const double ready = cam.readyTime();
    std::string path = req.path;
    if (path.empty()) {
      char name[64];
      std::snprintf(name, sizeof name, "archival_%.3f.png", cam.shutterTime());
      path = (fs::path(spool_dir_) / name).string();
    }
    lk.unlock();
    bool written = false;
    std::string error;
    try {
      fs::create_directories(fs::path(path).parent_path());
      cv::Mat bgr;
      cv::cvtColor(image, bgr, cv::COLOR_RGB2BGR);
      written = cv::imwrite(path, bgr, {cv::IMWRITE_PNG_COMPRESSION, 1});
    } catch (const std::exception& e) {
      error = e.what();
    }
    lk.lock();
    waitUntil(lk, ready);  // the transfer takes 1.5 s of sim time after the shutter
    cam.acknowledge();
    res.success = written;
    res.path = written ? path : "";
    res.message = written ? "stored " + path : "cannot write " + path + (error.empty() ? "" : ": " + error);
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM("sim: /archival_camera/capture failed: " << e.what());
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool SimNode::onGroundTruth(rascal_msgs::GetGroundTruth::Request&, rascal_msgs::GetGroundTruth::Response& res) {
  std::lock_guard<std::mutex> lk(mutex_);
  for (const SherdState& s : sim_->groundTruth()) res.sherds.push_back(conversions::toTruth(s));
  return true;
}

bool SimNode::onSpawn(rascal_msgs::SpawnScenario::Request& req, rascal_msgs::SpawnScenario::Response& res) {
  try {
    ScenarioLoader loader(config_.layout, *munsell_);
    const Scenario s = req.scenario_file.empty() ? loader.parse(req.scenario_yaml)
                                                 : loader.load(resolve(workspace_, req.scenario_file));
    std::lock_guard<std::mutex> lk(mutex_);
    sim_->load(s);
    sendStaticFrames();  // the scenario may have moved the stations
    res.success = true;
    res.count = static_cast<uint32_t>(s.sherds.size());
    res.message = "spawned " + std::to_string(res.count) + " sherds of scenario " + s.name;
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool SimNode::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lk(mutex_);
  sim_->reset();
  res.success = true;
  res.message = "sherds re-spawned, arm at its initial pose";
  return true;
}

bool SimNode::onInjectFault(rascal_msgs::InjectFault::Request& req, rascal_msgs::InjectFault::Response& res) {
  std::lock_guard<std::mutex> lk(mutex_);
  std::string message;
  res.success = sim_->injectFault(req.fault, req.duration, message);
  res.message = message;
  return true;
}

}  // namespace rascal_sim
