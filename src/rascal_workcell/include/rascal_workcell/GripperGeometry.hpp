#pragma once
// The gripper's limits and finger geometry, read from the URDF (rascal_description) so that no
// node writes them down again: finger travel from the left_finger joint limits, fingertip position
// from the finger link's collision box and the ee_gripper_link frame.
#include <array>
#include <string>
#include <vector>

namespace rascal_workcell {

/// A collision box of the hand as axis-aligned bounds [m] in ee_gripper_link's frame (x along
/// the fingers, towards their tips; y the closing direction, the left finger at +y).
struct HandBox {
  std::array<double, 3> lo{}, hi{};
};

struct GripperGeometry {
  double finger_min = 0.0;  ///< [m] left finger from the centreline, closed (joint lower limit)
  double finger_max = 0.0;  ///< [m] fully open (joint upper limit)
  double fingertip_offset = 0.0;  ///< [m] fingertips below ee_gripper_link when pointing down
  /// [m] pads fitted inside each finger (a site's choice, config arm.gripper.fingertip_pads; 0:
  /// the stock fingers): the opening between the fingers is the joints' gap less two pads.
  double pad = 0.0;
  /// The collision boxes of the links fixed to ee_gripper_link (the gripper, its bar, the wrist
  /// camera: what comes down with the fingers above them), the fingers themselves not among them.
  std::vector<HandBox> hand;

  double minOpening() const { return 2.0 * (finger_min - pad); }  ///< [m] between the fingers, closed
  double maxOpening() const { return 2.0 * (finger_max - pad); }  ///< [m] fully open
  /// [m] the left finger's joint position for an opening of `width` between the fingers
  double fingerFor(double width) const { return width / 2.0 + pad; }
  /// [m] the opening between the fingers at a gap of `joint_gap` between their joints
  double openingAt(double joint_gap) const { return joint_gap - 2.0 * pad; }
  /// A copy with pads of `pad` [m]; throws std::invalid_argument when they would meet before the
  /// fingers close (pad >= finger_min) or are negative.
  GripperGeometry withPads(double pad) const;

  /// Parses URDF XML; throws std::invalid_argument naming what is missing.
  static GripperGeometry fromUrdf(const std::string& urdf_xml);
  /// rascal_description's urdf/wx250s.urdf, found at build time (tests, tools, simulator).
  static GripperGeometry fromPackageUrdf();
  static std::string packageUrdfPath();
};

}  // namespace rascal_workcell
