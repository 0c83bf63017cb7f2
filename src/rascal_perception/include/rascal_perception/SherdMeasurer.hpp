#pragma once
// Metric measurement of blobs from the aligned depth (16UC1 mm, colour optical frame): the table
// plane (RANSAC on background pixels near the station surface), each sherd's top height above it,
// its top-view footprint (oriented box: centre, yaw, length, width), area, colour and outline,
// all in base_link.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>

#include "rascal_perception/TablePlane.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

struct CameraView {
  CameraIntrinsics intrinsics;
  Eigen::Isometry3d base_T_camera = Eigen::Isometry3d::Identity();  ///< base_link <- optical frame
};

class SherdMeasurer {
 public:
  explicit SherdMeasurer(const PerceptionConfig& config) : config_(config) {}
  /// Plane of the station surface from depth pixels where `usable` is 255, keeping points within
  /// 15 mm of `surface_z`. Falls back to z = surface_z (ok = false) with too few points.
  PlaneFit fitPlane(const cv::Mat& depth_mm, const cv::Mat& usable, const CameraView& view, double surface_z) const;
  /// Measures one blob. Returns false with `why` when it is not a sherd by the metric size limits.
  bool measure(const Blob& blob, const cv::Mat& rgb, const cv::Mat& depth_mm, const CameraView& view,
               const Eigen::Vector4d& plane, SherdDetection& out, std::string& why) const;
  /// Where the ray through pixel (u, v) meets the plane raised by `height` (false: it does not).
  static bool intersect(const CameraView& view, const Eigen::Vector4d& plane, double height, double u, double v,
                        Eigen::Vector3d& point);
  /// Per pixel, the base_link z component of the pixel's ray (z = 1 in the optical frame);
  /// height of a pixel at depth Z is camera_z + map * Z.
  static cv::Mat rayZMap(const CameraView& view);

 private:
  PerceptionConfig config_;
};

}  // namespace rascal_perception
