#pragma once
// A top-down grasp per sherd and a score; the gripper's fingers close across the minor axis.
//
// ee_gripper_link target: the sherd's centre, orientation R = Rz(yaw) * Ry(pi/2) (x down, fingers
// closing along R*y = across the major axis), at
//   z = surface + max(grasp_height_fraction * height, grasp_tip_clearance) + gripper.fingertip_offset,
// i.e. the fingertips close at 60 % of the measured top height but never lower than 2.5 mm above
// the station surface; opening = width + grasp_margin clamped to the gripper's opening limits
// (the URDF's finger limits: 30 .. 74 mm on the wx250s).
#include <vector>

#include "rascal_perception/Types.hpp"

namespace rascal_perception {

class GraspPlanner {
 public:
  static constexpr double kFingerWidth = 0.020;  ///< [m] gap that lets a finger in (score saturates)

  /// Throws std::invalid_argument when config.gripper has no finger limits (not read from a URDF).
  explicit GraspPlanner(const PerceptionConfig& config);
  /// Fills grasp and grasp_width of one sherd.
  void plan(SherdDetection& sherd) const;
  /// Fills clearance (gap to the nearest other outline) and score of every sherd.
  void score(std::vector<SherdDetection>& sherds) const;
  double minOpening() const { return config_.gripper.minOpening(); }  ///< [m]
  double maxOpening() const { return config_.gripper.maxOpening(); }  ///< [m]

 private:
  PerceptionConfig config_;
};

}  // namespace rascal_perception
