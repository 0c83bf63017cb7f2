#pragma once
// A pinhole camera without distortion (REP 103 optical frame: z forward, x right, y down).
#include <Eigen/Geometry>

namespace rascal_sim {

struct CameraModel {
  int width = 640;
  int height = 480;
  double fx = 615.0, fy = 615.0, cx = 320.0, cy = 240.0;  ///< facts §4.3 simulator defaults
  double near = 0.01, far = 10.0;                         ///< [m]

  Eigen::Vector2d project(const Eigen::Vector3d& p_cam) const {
    return {fx * p_cam.x() / p_cam.z() + cx, fy * p_cam.y() / p_cam.z() + cy};
  }
  /// The wrist D435 colour stream at 640 x 480.
  static CameraModel wristD435() { return CameraModel(); }
};

}  // namespace rascal_sim
