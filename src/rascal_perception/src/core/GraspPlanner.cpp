#include "rascal_perception/GraspPlanner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rascal_perception {

namespace {
/// Distance from point p to segment ab in the xy plane.
double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double outlineGap(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& p : a) {
    for (size_t i = 0; i < b.size(); ++i) {
      best = std::min(best, segmentDistance(p.head<2>(), b[i].head<2>(), b[(i + 1) % b.size()].head<2>()));
    }
  }
  return best;
}
}  // namespace

GraspPlanner::GraspPlanner(const PerceptionConfig& config) : config_(config) {
  const rascal_workcell::GripperGeometry& g = config_.gripper;
  if (!(g.minOpening() > 0.0 && g.maxOpening() > g.minOpening())) {
    throw std::invalid_argument(
        "GraspPlanner: PerceptionConfig::gripper has no finger limits; fill it from the URDF "
        "(rascal_workcell::GripperGeometry::fromUrdf or fromPackageUrdf)");
  }
}

void GraspPlanner::plan(SherdDetection& s) const {
  // from what the sherd rests on (the station, or the sherd under it in a heap: closing lower
  // would take that one too)
  const double own = std::max(s.height - s.support, 0.0);
  const double tip = s.support + std::max(config_.grasp_height_fraction * own, config_.grasp_tip_clearance);
  s.grasp = Eigen::Isometry3d::Identity();
  s.grasp.linear() = (Eigen::AngleAxisd(s.yaw, Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY())).toRotationMatrix();
  s.grasp.translation() = Eigen::Vector3d(s.centre.x(), s.centre.y(), s.surface + tip + config_.gripper.fingertip_offset);
  s.grasp_width = std::clamp(s.width + config_.grasp_margin, minOpening(), maxOpening());
}

void GraspPlanner::score(std::vector<SherdDetection>& sherds) const {
  for (size_t i = 0; i < sherds.size(); ++i) {
    double gap = 1.0;
    for (size_t j = 0; j < sherds.size(); ++j) {
      if (i == j || sherds[i].outline.empty() || sherds[j].outline.empty()) continue;
      gap = std::min({gap, outlineGap(sherds[i].outline, sherds[j].outline),
                      outlineGap(sherds[j].outline, sherds[i].outline)});
    }
    SherdDetection& s = sherds[i];
    s.clearance = gap;
    const double isolation = std::clamp(gap / kFingerWidth, 0.0, 1.0);
    const double fit = s.width + config_.grasp_margin <= maxOpening() ? 1.0 : 0.3;
    const double depth = s.depth_valid ? 1.0 : 0.5;
    s.score = fit * depth * (0.5 + 0.5 * isolation);
  }
}

}  // namespace rascal_perception
