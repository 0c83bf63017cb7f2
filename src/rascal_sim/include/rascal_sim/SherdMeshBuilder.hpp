#pragma once
// Turns a SherdSpec into a closed shell mesh, its collision shape and its mass.
#include <Eigen/Geometry>
#include <vector>

#include "rascal_sim/Mesh.hpp"
#include "rascal_sim/Scenario.hpp"

namespace rascal_sim {

/// One box of a sherd's collision shape, in the sherd body frame.
struct CollisionBox {
  Eigen::Vector3d centre;         ///< [m]
  Eigen::Vector3d size;           ///< [m]
};

struct SherdGeometry {
  Mesh mesh;                      ///< vertices in the sherd body frame (centre of the box)
  Eigen::Vector3d box_size;       ///< [m] bounding box, centred on the body frame
  /// Strips across the top-view convex hull, each the full box height. One bounding box would
  /// put matter where the sherd has none (its corners): a near-square sherd grasped at 45°
  /// would then be wider than the open gripper although the real one fits.
  std::vector<CollisionBox> collision;
  double volume = 0.0;            ///< [m^3]
  double mass = 0.0;              ///< [kg]
  double length = 0.0, width = 0.0;
  std::vector<Eigen::Vector2d> outline;  ///< in the body frame; for a scanned mesh its top-view hull
};

/// A top-view outline's principal axes (area second moments), in its own frame.
struct OutlineAxes {
  Eigen::Vector2d major{1.0, 0.0};  ///< unit direction of the major axis
  double length = 0.0, width = 0.0; ///< [m] extents along and across it
};

class SherdMeshBuilder {
 public:
  /// Throws std::runtime_error if the outline has fewer than 3 points or the STL is unreadable.
  static SherdGeometry build(const SherdSpec& spec);
  /// `strips` boxes along x covering the convex hull of `outline`, `height` tall, centred on z = 0.
  static std::vector<CollisionBox> collisionStrips(const std::vector<Eigen::Vector2d>& outline,
                                                   double height, int strips);
  /// The generator's length x width box is not this: it scales a random polygon into the box,
  /// so its axes can be 30° off the outline's own (the ones a person or the detector sees).
  static OutlineAxes principalAxes(const std::vector<Eigen::Vector2d>& outline);
  /// Convex hull, counter-clockwise (Andrew's monotone chain).
  static std::vector<Eigen::Vector2d> convexHull(std::vector<Eigen::Vector2d> points);
};

}  // namespace rascal_sim
