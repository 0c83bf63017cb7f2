#pragma once
// Turns a SherdSpec into a closed shell mesh, its collision box and its mass.
#include <Eigen/Geometry>
#include <vector>

#include "rascal_sim/Mesh.hpp"
#include "rascal_sim/Scenario.hpp"

namespace rascal_sim {

struct SherdGeometry {
  Mesh mesh;                      ///< vertices in the sherd body frame (centre of the box)
  Eigen::Vector3d box_size;       ///< [m] collision box, centred on the body frame
  double volume = 0.0;            ///< [m^3]
  double mass = 0.0;              ///< [kg]
  double length = 0.0, width = 0.0;
  std::vector<Eigen::Vector2d> outline;  ///< in the body frame
};

class SherdMeshBuilder {
 public:
  /// Throws std::runtime_error if the outline has fewer than 3 points or the STL is unreadable.
  static SherdGeometry build(const SherdSpec& spec);
};

}  // namespace rascal_sim
