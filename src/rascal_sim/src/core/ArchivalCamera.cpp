#include "rascal_sim/ArchivalCamera.hpp"

#include <Eigen/Geometry>
#include <algorithm>

namespace rascal_sim {

ArchivalCamera::ArchivalCamera(const WorldLayout& layout, int width, int height) {
  model_.width = width;
  model_.height = height;
  const Station& station = layout.station(StationType::ArchivalCamera);
  const double h = station.camera_height;
  // the field of view covers the station rectangle (the archival camera station's size)
  const double f = std::min(width * h / station.area.size.x(), height * h / station.area.size.y());
  model_.fx = model_.fy = f;
  model_.cx = width / 2.0;
  model_.cy = height / 2.0;
  model_.near = 0.02;
  model_.far = 2.0;
  // straight down: image x = the station's +x, image y = its -y (the camera turns with its stand)
  world_T_camera_ = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  world_T_camera_.linear() = Eigen::AngleAxisd(station.area.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * r;
  world_T_camera_.translation() = Eigen::Vector3d(station.area.centre.x(), station.area.centre.y(), h);
}

bool ArchivalCamera::trigger(double now, bool camera_fault, double fault_until, std::string& why) {
  if (state_ != State::kIdle) {
    why = "archival camera busy: a capture is already in progress";
    return false;
  }
  shutter_time_ = now;
  if (camera_fault) {
    state_ = State::kFailed;
    message_ = "archival camera did not answer (camera timeout)";
    ready_time_ = fault_until;
    return true;
  }
  state_ = State::kShutter;
  message_.clear();
  return true;
}

bool ArchivalCamera::update(double now, const std::array<Eigen::Isometry3d, kArmLinkCount>& arm) {
  if (state_ == State::kShutter) {
    const std::string link = armInView(arm);
    if (!link.empty()) {
      state_ = State::kFailed;
      message_ = "arm in view: " + link + " over the frame during the shutter; move to standby";
      ready_time_ = now;
      return false;
    }
    return now >= shutter_time_ + kShutter - 1e-9;
  }
  if (state_ == State::kTransfer && now >= ready_time_ - 1e-9) state_ = State::kDone;
  return false;
}

void ArchivalCamera::deliver(double now, const cv::Mat& image) {
  image_ = image;
  state_ = State::kTransfer;
  ready_time_ = now + kTransfer;
}

void ArchivalCamera::acknowledge() {
  state_ = State::kIdle;
  image_.release();
  message_.clear();
}

std::string ArchivalCamera::armInView(const std::array<Eigen::Isometry3d, kArmLinkCount>& arm) const {
  const Eigen::Isometry3d camera_T_world = world_T_camera_.inverse();
  for (const LinkBox& b : ArmKinematics::linkBoxes()) {
    if (b.link == kBaseLink || b.link == kShoulderLink) continue;
    const Eigen::Isometry3d T = camera_T_world * arm[b.link] * b.offset;
    for (int i = -1; i <= 1; ++i) {
      for (int j = -1; j <= 1; ++j) {
        for (int k = -1; k <= 1; ++k) {
          const Eigen::Vector3d p = T * Eigen::Vector3d(i * b.size.x() / 2, j * b.size.y() / 2, k * b.size.z() / 2);
          if (p.z() < model_.near) continue;
          const Eigen::Vector2d uv = model_.project(p);
          if (uv.x() >= 0 && uv.x() < model_.width && uv.y() >= 0 && uv.y() < model_.height) {
            return ArmKinematics::linkName(b.link);
          }
        }
      }
    }
  }
  return "";
}

}  // namespace rascal_sim
