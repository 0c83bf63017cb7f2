#include "rascal_sim/ArmKinematics.hpp"

#include <cmath>

namespace rascal_sim {

namespace {
using Eigen::AngleAxisd;
using Eigen::Isometry3d;
using Eigen::Vector3d;

Isometry3d translation(double x, double y, double z) {
  Isometry3d t = Isometry3d::Identity();
  t.translation() = Vector3d(x, y, z);
  return t;
}

Isometry3d rotation(const Vector3d& axis, double angle) {
  Isometry3d t = Isometry3d::Identity();
  t.linear() = AngleAxisd(angle, axis).toRotationMatrix();
  return t;
}

LinkBox box(ArmLink link, const Vector3d& centre, const Vector3d& size, double grey,
            const Eigen::Matrix3d& rot = Eigen::Matrix3d::Identity()) {
  Isometry3d o = Isometry3d::Identity();
  o.translation() = centre;
  o.linear() = rot;
  return {link, o, size, Vector3d::Constant(grey)};
}
}  // namespace

const std::array<std::string, kArmJoints>& ArmKinematics::jointNames() {
  static const std::array<std::string, kArmJoints> names = {
      "waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"};
  return names;
}

// facts widowx250_d435.md §1.1 (URDF limits)
const JointVector& ArmKinematics::lowerLimits() {
  static const JointVector lo = {-3.141583, -1.884956, -2.146755, -3.141583, -1.745329, -3.141583};
  return lo;
}

const JointVector& ArmKinematics::upperLimits() {
  static const JointVector hi = {3.141583, 1.989675, 1.605703, 3.141583, 2.146755, 3.141583};
  return hi;
}

const char* ArmKinematics::linkName(ArmLink link) {
  static const char* names[kArmLinkCount] = {
      "base_link", "shoulder_link", "upper_arm_link", "upper_forearm_link", "lower_forearm_link",
      "wrist_link", "gripper_link", "fingers_link", "left_finger_link", "right_finger_link",
      "ee_gripper_link", "camera_link", "camera_color_optical_frame"};
  return names[link];
}

std::array<Isometry3d, kArmLinkCount> ArmKinematics::forward(const JointVector& q, double finger) {
  const Vector3d X = Vector3d::UnitX(), Y = Vector3d::UnitY(), Z = Vector3d::UnitZ();
  std::array<Isometry3d, kArmLinkCount> T;
  T[kBaseLink] = Isometry3d::Identity();
  T[kShoulderLink] = translation(0, 0, 0.072) * rotation(Z, q[0]);
  T[kUpperArmLink] = T[kShoulderLink] * translation(0, 0, 0.03865) * rotation(Y, q[1]);
  T[kUpperForearmLink] = T[kUpperArmLink] * translation(0.04975, 0, 0.25) * rotation(Y, q[2]);
  T[kLowerForearmLink] = T[kUpperForearmLink] * translation(0.175, 0, 0) * rotation(X, q[3]);
  T[kWristLink] = T[kLowerForearmLink] * translation(0.075, 0, 0) * rotation(Y, q[4]);
  T[kGripperLink] = T[kWristLink] * translation(0.065, 0, 0) * rotation(X, q[5]);
  // ee_arm (0.043) + gripper_bar (0) + ee_bar (0.023)
  T[kFingersLink] = T[kGripperLink] * translation(0.043 + 0.023, 0, 0);
  T[kLeftFingerLink] = T[kFingersLink] * translation(0, finger, 0);
  T[kRightFingerLink] = T[kFingersLink] * translation(0, -finger, 0);
  T[kEeGripperLink] = T[kFingersLink] * translation(0.027575, 0, 0);
  // RASCAL's wrist D435 mount: camera_link on gripper_link at (0.04, 0, 0.055), rpy 0;
  // colour frame +0.015 along y; optical frame rpy (-pi/2, 0, -pi/2).
  T[kCameraLink] = T[kGripperLink] * translation(0.04, 0, 0.055);
  T[kCameraColorOpticalFrame] = T[kCameraLink] * translation(0, 0.015, 0) * rotation(Z, -M_PI / 2) *
                                rotation(X, -M_PI / 2);
  return T;
}

std::vector<LinkBox> ArmKinematics::linkBoxes(double pad) {
  std::vector<LinkBox> boxes = linkBoxes();
  for (LinkBox& b : boxes) {
    if (b.link != kLeftFingerLink && b.link != kRightFingerLink) continue;
    const double inwards = b.link == kLeftFingerLink ? -1.0 : 1.0;  // towards the centreline
    b.size.y() += pad;
    b.offset.translation().y() += inwards * pad / 2.0;
  }
  return boxes;
}

const std::vector<LinkBox>& ArmKinematics::linkBoxes() {
  static const std::vector<LinkBox> boxes = [] {
    std::vector<LinkBox> b;
    const double upper_tilt = std::atan2(0.04975, 0.25);
    b.push_back(box(kBaseLink, {-0.01, 0, 0.036}, {0.14, 0.11, 0.072}, 0.12));
    b.push_back(box(kShoulderLink, {0, 0, 0.02}, {0.07, 0.09, 0.04}, 0.15));
    b.push_back(box(kUpperArmLink, {0.02487, 0, 0.125}, {0.045, 0.05, 0.30}, 0.12,
                    Eigen::AngleAxisd(upper_tilt, Vector3d::UnitY()).toRotationMatrix()));
    b.push_back(box(kUpperForearmLink, {0.0875, 0, 0}, {0.20, 0.04, 0.04}, 0.12));
    b.push_back(box(kLowerForearmLink, {0.0375, 0, 0}, {0.075, 0.035, 0.035}, 0.14));
    b.push_back(box(kWristLink, {0.0325, 0, 0}, {0.065, 0.035, 0.045}, 0.12));
    b.push_back(box(kGripperLink, {0.022, 0, 0}, {0.044, 0.05, 0.045}, 0.14));
    b.push_back(box(kGripperLink, {0.058, 0, 0}, {0.016, 0.10, 0.03}, 0.18));
    b.push_back(box(kCameraLink, {-0.01, -0.0175 + 0.015, 0}, {0.025, 0.09, 0.025}, 0.35));
    b.push_back(box(kLeftFingerLink, {0.012, 0.004, 0}, {0.040, 0.008, 0.02}, 0.2));
    b.push_back(box(kRightFingerLink, {0.012, -0.004, 0}, {0.040, 0.008, 0.02}, 0.2));
    return b;
  }();
  return boxes;
}

}  // namespace rascal_sim
