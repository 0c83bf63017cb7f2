#pragma once
// Value types shared by the perception core: camera intrinsics, the configuration (perception.*
// of config/rascal.yaml, the gripper from the URDF), segmented blobs and measured sherds. No ROS.
#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rascal_workcell/GripperGeometry.hpp"

namespace rascal_perception {

/// Pinhole intrinsics of the colour stream (the aligned depth shares them).
/// An axis's direction [rad] in (-pi/2, pi/2]: a and a + pi are one axis (a sherd's long side,
/// the two alike fingers' closing line).
inline double wrapHalfPi(double a) {
  while (a > M_PI / 2) a -= M_PI;
  while (a <= -M_PI / 2) a += M_PI;
  return a;
}

struct CameraIntrinsics {
  int width = 640, height = 480;
  double fx = 615.0, fy = 615.0, cx = 320.0, cy = 240.0;
  /// Direction of pixel (u, v) in the optical frame with z = 1.
  Eigen::Vector3d ray(double u, double v) const { return {(u - cx) / fx, (v - cy) / fy, 1.0}; }
  Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
};

/// perception.* of config/rascal.yaml (+ arm.grasp_margin, arm.gripper.held_margin; DetectorParameters::read fills it
/// through the parameter schema) and the gripper from the URDF. Lengths in metres.
struct PerceptionConfig {
  int background_clusters = 3;
  double hue_tolerance = 0.15;         ///< half-width of a cluster's hue band, fraction of the hue circle
  double saturation_tolerance = 0.35;  ///< half-width of a cluster's saturation band, S in [0, 1]
  double min_value = 0.07;             ///< darker pixels (V in [0, 1]) are not trusted for hue
  double fixture_dilation = 0.01;      ///< [m] growth of the fixture mask
  double min_sherd_size = 0.015;       ///< [m] shortest side of the smallest sherd
  double max_sherd_size = 0.12;        ///< [m] longest side of the largest sherd
  int border_margin = 3;               ///< [px] blobs this close to the border are cut off
  double depth_min = 0.15, depth_max = 1.0;  ///< [m] depth outside is ignored
  double grasp_margin = 0.012;         ///< [m] arm.grasp_margin: opening beyond the measured width
  /// [m] arm.gripper.held_margin: the gripper says it holds only a sherd that stops the fingers
  /// this much wider than they close
  double held_margin = 0.002;
  double grasp_height_fraction = 0.6;  ///< fingertips close at this fraction of the measured height
  double grasp_tip_clearance = 0.0025; ///< [m] fingertips never lower than this above the surface (facts: the paper's clearance)
  /// Finger limits (the opening clamp) and fingertip offset below ee_gripper_link, from the URDF
  /// (rascal_workcell::GripperGeometry); GraspPlanner refuses it unset.
  rascal_workcell::GripperGeometry gripper;
  double split_min_neck = 0.75;        ///< touching sherds split where the neck < this x the smaller peak
  double plane_tolerance = 0.003;      ///< [m] RANSAC inlier distance of the table plane
  double min_sherd_height = 0.0025;    ///< [m] depth this far above the surface is sherd, whatever its colour
};

/// A segmented region of the colour image (one sherd candidate).
struct Blob {
  std::vector<cv::Point> contour;  ///< outer contour in image pixels
  cv::RotatedRect box;             ///< minAreaRect of the contour
  cv::Rect bounds;                 ///< bounding rectangle
  cv::Mat mask;                    ///< CV_8U 255 inside, size of `bounds`
  int pixels = 0;
};

/// One measured sherd (all poses in base_link).
struct SherdDetection {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< [m] top-surface centre
  double yaw = 0.0;            ///< [rad] major axis about +z, in (-pi/2, pi/2]
  double length = 0.0, width = 0.0, height = 0.0, area = 0.0;  ///< [m], [m^2]
  double surface = 0.0;        ///< [m] z of the station surface (fitted plane) under the centre
  double thickness = 0.0;      ///< [m] wall thickness (ShellFit); 0 = not measured, see thickness_why
  std::string thickness_why;   ///< why there is no thickness
  double diameter = 0.0;       ///< [m] vessel's outer diameter (ShellFit); 0 = not told, see diameter_why
  double diameter_sigma = 0.0; ///< [m] its 1-sigma uncertainty
  std::string diameter_why;
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();  ///< mean sRGB [0, 1]
  Eigen::Isometry3d grasp = Eigen::Isometry3d::Identity();  ///< ee_gripper_link target
  double grasp_width = 0.0;    ///< [m] opening before closing, within the gripper's (30 .. 74 mm)
  double score = 0.0;          ///< [1] in [0, 1]
  double clearance = 1.0;      ///< [m] gap to the nearest other sherd (1 = alone)
  double covered = 0.0;        ///< [1] share of its edge under another sherd lying on it (StackSplitter)
  double support = 0.0;        ///< [m] height above `surface` of what it rests on (0: the station)
  double finger_clearance = 1.0;  ///< [m] fingertips above what lies beside it (GraspPlanner; 1: not checked)
  bool grasp_clear = true;     ///< false: no grasp direction found whose fingers clear the neighbours
  bool depth_valid = false;    ///< false: measured without depth (height unknown = 0)
  float image_box[5] = {0, 0, 0, 0, 0};  ///< u, v, length, width [px], angle [rad]
  std::vector<Eigen::Vector3d> outline;  ///< [m] top-view outline, z = station surface
  std::vector<cv::Point> contour;        ///< image contour (for drawing)
};

/// Something on the station that is not offered as a sherd to pick: too small or too large by
/// perception.min/max_sherd_size, not measurable, or only partly in view. Said to the task layer so a batch that
/// leaves it on the mat says so instead of finishing as if the mat were empty.
struct Leftover {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m] centre of its outline, on the surface
  double length = 0.0, width = 0.0;                   ///< [m] its image box on the surface (about)
  double yaw = 0.0;     ///< [rad] its long side's direction about base_link z, in (-pi/2, pi/2]
  double height = 0.0;  ///< [m] its top above the surface (0: no depth there)
  /// taller than wide and at least perception.min_sherd_size tall: a sherd standing on its edge
  /// (leaning in a heap); pushed over, it lies flat
  bool on_edge = false;
  /// only part of it in view: the image border cuts it (position and size are the part's); a
  /// view centred on it sees it whole
  bool cut_by_border = false;
  std::string why;  ///< one line naming the rule
};

/// Result of a detection: the sherds by score, best first (ties in segmentation order), or why
/// there are none. Which sherd is picked is the task layer's choice (perception.selection_policy).
struct DetectionResult {
  bool success = false;
  std::string message;
  std::vector<SherdDetection> sherds;
  Eigen::Vector4d plane = Eigen::Vector4d(0, 0, 1, 0);  ///< table plane in base_link, n.p + d = 0
  int plane_inliers = 0;
  int rejected_border = 0, rejected_size = 0, splits = 0;
  std::vector<Leftover> leftovers;  ///< with depth only: what was seen but not offered
};

}  // namespace rascal_perception
