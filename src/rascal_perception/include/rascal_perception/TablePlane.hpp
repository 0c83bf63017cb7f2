#pragma once
// The station surface as a plane fitted by RANSAC (PCL) to 3D points of the background.
#include <Eigen/Core>
#include <vector>

namespace rascal_perception {

struct PlaneFit {
  bool ok = false;
  Eigen::Vector4d plane = Eigen::Vector4d(0, 0, 1, 0);  ///< n.p + d = 0, |n| = 1, n.z > 0
  int inliers = 0;
};

class TablePlane {
 public:
  /// Fits a plane to `points` (any frame); `tolerance` [m] is the inlier distance. Deterministic.
  static PlaneFit fit(const std::vector<Eigen::Vector3f>& points, double tolerance, int min_inliers = 50);
};

}  // namespace rascal_perception
