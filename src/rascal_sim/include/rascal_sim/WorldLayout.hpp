#pragma once
// Station layout of the simulated table, filled from config/rascal.yaml (stations.*, simulator.*)
// by the node, or built directly by tests.
#include <Eigen/Geometry>
#include <array>
#include <string>

namespace rascal_sim {

/// A rectangle on the table: centre and size [along x, along y] in base_link, metres.
struct TableRect {
  Eigen::Vector2d position{0.0, 0.0};
  Eigen::Vector2d size{0.0, 0.0};
};

struct WorldLayout {
  TableRect pickup;
  TableRect scale;                 ///< weighing platform
  double scale_surface_z = 0.025;  ///< platform top above the table
  TableRect camera;                ///< archival camera's field of view on the table
  Eigen::Vector2d camera_place_at{0.28, -0.30};
  double camera_height = 0.55;     ///< lens above the camera station surface
  TableRect colour_chart;
  TableRect scale_bar;
  TableRect stand;                 ///< the archival camera's post (collision fixture)
  double stand_height = 0.60;
  TableRect discard;
  double discard_wall_height = 0.04;
  Eigen::Vector3d table_colour{0.55, 0.50, 0.42};  ///< sRGB [0, 1]
  Eigen::Vector3d mat_colour{0.10, 0.22, 0.55};
  std::array<Eigen::Vector3d, 2> scale_colours{Eigen::Vector3d(0.85, 0.85, 0.85),
                                               Eigen::Vector3d(0.25, 0.25, 0.25)};
  std::string data_dir;            ///< folder with the colour chart CSV, Munsell CSV, fragment STL

  /// The values of config/rascal.yaml as shipped (for tests and tools).
  static WorldLayout defaults(const std::string& data_dir);
};

}  // namespace rascal_sim
