#pragma once
// The gripper's limits and finger geometry, read from the URDF (rascal_description) so that no
// node writes them down again: finger travel from the left_finger joint limits, fingertip position
// from the finger link's collision box and the ee_gripper_link frame.
#include <string>

namespace rascal_workcell {

struct GripperGeometry {
  double finger_min = 0.0;  ///< [m] left finger from the centreline, closed (joint lower limit)
  double finger_max = 0.0;  ///< [m] fully open (joint upper limit)
  double fingertip_offset = 0.0;  ///< [m] fingertips below ee_gripper_link when pointing down

  double minOpening() const { return 2.0 * finger_min; }  ///< [m] between the fingers, closed
  double maxOpening() const { return 2.0 * finger_max; }  ///< [m] fully open

  /// Parses URDF XML; throws std::invalid_argument naming what is missing.
  static GripperGeometry fromUrdf(const std::string& urdf_xml);
  /// rascal_description's urdf/wx250s.urdf, found at build time (tests, tools, simulator).
  static GripperGeometry fromPackageUrdf();
  static std::string packageUrdfPath();
};

}  // namespace rascal_workcell
