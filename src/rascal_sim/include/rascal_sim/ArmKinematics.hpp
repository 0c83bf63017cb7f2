#pragma once
// Forward kinematics of the wx250s with the joint origins of the URDF (facts §1.1), the wrist
// D435 mount, and the boxes that stand for each link in collisions and images.
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

namespace rascal_sim {

constexpr int kArmJoints = 6;
using JointVector = std::array<double, kArmJoints>;

enum ArmLink {
  kBaseLink, kShoulderLink, kUpperArmLink, kUpperForearmLink, kLowerForearmLink, kWristLink,
  kGripperLink, kFingersLink, kLeftFingerLink, kRightFingerLink, kEeGripperLink, kCameraLink,
  kCameraColorOpticalFrame, kArmLinkCount
};

/// A box fixed to a link: pose of its centre in the link frame and its size.
struct LinkBox {
  ArmLink link;
  Eigen::Isometry3d offset;
  Eigen::Vector3d size;
  Eigen::Vector3d srgb;
};

class ArmKinematics {
 public:
  static const std::array<std::string, kArmJoints>& jointNames();
  static const JointVector& lowerLimits();
  static const JointVector& upperLimits();
  static const char* linkName(ArmLink link);
  static constexpr double kMaxVelocity = 3.141592653589793;  ///< [rad/s] timing.md
  static constexpr double kMaxAcceleration = 5.0;            ///< [rad/s^2] timing.md

  /// Poses of every link in base_link for joints q and left finger position `finger` [m] (its
  /// limits are the URDF's: rascal_workcell::GripperGeometry).
  static std::array<Eigen::Isometry3d, kArmLinkCount> forward(const JointVector& q, double finger);
  /// The boxes of the moving links (and the base) used for contacts, rendering and view checks.
  static const std::vector<LinkBox>& linkBoxes();
  /// linkBoxes with a pad of `pad` [m] inside each finger (GripperGeometry::pad): the finger's
  /// box grows by it towards the other finger.
  static std::vector<LinkBox> linkBoxes(double pad);
};

}  // namespace rascal_sim
