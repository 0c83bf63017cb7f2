#pragma once
// The archival DSLR looking straight down at the camera station: a triggered capture with a
// 0.2 s shutter (the arm must stay out of view) and a 1.5 s transfer (timing.md).
#include <Eigen/Geometry>
#include <array>
#include <opencv2/core.hpp>
#include <string>

#include "rascal_sim/ArmKinematics.hpp"
#include "rascal_sim/CameraModel.hpp"
#include "rascal_sim/WorldLayout.hpp"

namespace rascal_sim {

class ArchivalCamera {
 public:
  static constexpr double kShutter = 0.2;   ///< [s]
  static constexpr double kTransfer = 1.5;  ///< [s] after the shutter closes

  enum class State { kIdle, kShutter, kTransfer, kDone, kFailed };

  ArchivalCamera(const WorldLayout& layout, int width, int height);
  const CameraModel& model() const { return model_; }
  const Eigen::Isometry3d& pose() const { return world_T_camera_; }

  /// Starts a capture at `now`. False (with `why`) if one is running.
  bool trigger(double now, bool camera_fault, double fault_until, std::string& why);
  /// Called every physics step; returns true when the shutter closes and the image must be rendered.
  bool update(double now, const std::array<Eigen::Isometry3d, kArmLinkCount>& arm);
  /// Hands the rendered image over; the transfer starts.
  void deliver(double now, const cv::Mat& image);
  State state() const { return state_; }
  const std::string& message() const { return message_; }
  double shutterTime() const { return shutter_time_; }
  /// Sim time at which the answer is due (transfer end, or the end of a camera fault).
  double readyTime() const { return ready_time_; }
  const cv::Mat& image() const { return image_; }
  /// Back to idle once the caller has taken the result.
  void acknowledge();

  /// Name of the first arm link whose box is inside the view, or "" if none.
  std::string armInView(const std::array<Eigen::Isometry3d, kArmLinkCount>& arm) const;

 private:
  CameraModel model_;
  Eigen::Isometry3d world_T_camera_;
  State state_ = State::kIdle;
  std::string message_;
  double shutter_time_ = 0.0, ready_time_ = 0.0;
  cv::Mat image_;
};

}  // namespace rascal_sim
