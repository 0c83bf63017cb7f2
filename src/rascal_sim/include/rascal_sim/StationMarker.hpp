#pragma once
// An ArUco marker stuck on the table at a station (`stations.<name>.marker_ids` and
// `marker_positions`): what `rascal calibrate` looks for with the wrist camera to find where the
// station really stands.
#include <Eigen/Core>
#include <array>
#include <string>

#include "rascal_sim/Mesh.hpp"

namespace rascal_sim {

struct StationMarker {
  static constexpr double kSide = 0.040;  ///< [m] printed side: black border and 4 x 4 bits
  static constexpr double kZ = 0.0006;    ///< [m] lying on the table, above the mats (0.0004)

  std::string station;
  int id = 0;                       ///< in OpenCV's DICT_4X4_50
  Eigen::Vector2d centre{0.0, 0.0};  ///< [m] in base_link, where it lies
  double yaw = 0.0;                  ///< [rad] about +z: its station's frame against base_link

  /// [m] base_link corners in OpenCV's order: top-left, top-right, bottom-right, bottom-left of
  /// the picture cv::aruco::drawMarker draws, its columns along the station's +x and its rows
  /// along the station's −y (the calibrator relies on exactly this).
  std::array<Eigen::Vector2d, 4> corners() const;
  /// Adds the marker's cells (6 x 6) and a white quiet margin one cell wide, flat at kZ.
  void draw(Mesh& mesh) const;
};

}  // namespace rascal_sim
