// The wx250s arm's kinematic model, built from the URDF with kdl_parser and urdfdom.
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/tree.hpp>

namespace rascal_control {

constexpr std::size_t kArmJoints = 6;
// [rad] waist, shoulder, elbow, forearm_roll, wrist_angle, wrist_rotate.
using JointVector = std::array<double, kArmJoints>;

struct JointLimit {
  double lower = 0.0;     // [rad]
  double upper = 0.0;     // [rad]
  double velocity = 0.0;  // [rad/s] from the URDF
};

// One <collision> primitive of the URDF, in its link's frame.
struct CollisionShape {
  enum class Type { Box, Cylinder, Sphere };
  std::string link;
  Type type = Type::Box;
  KDL::Vector size;   // box: x, y, z [m]; cylinder: radius, length, 0; sphere: radius, 0, 0
  KDL::Frame origin;  // shape centre in the link frame
};

// A fixed or moving transform between two links, as robot_state_publisher would send it.
struct LinkTransform {
  std::string parent;
  std::string child;
  KDL::Frame pose;
};

class KinematicModel {
 public:
  static constexpr const char* kBaseLink = "base_link";
  static constexpr const char* kTipLink = "ee_gripper_link";
  static constexpr const char* kCameraLink = "camera_color_optical_frame";
  static const std::array<std::string, kArmJoints>& armJointNames();

  // Both throw std::runtime_error naming the problem (unreadable file, bad XML, missing link or joint).
  static KinematicModel fromFile(const std::string& path);
  static KinematicModel fromString(const std::string& urdf_xml);

  const std::array<JointLimit, kArmJoints>& limits() const { return limits_; }
  // True when every joint is inside its limits (widened by `tolerance`).
  bool withinLimits(const JointVector& q, double tolerance = 0.0) const;
  // Index of the first joint outside its limits, or -1.
  int firstLimitViolation(const JointVector& q, double tolerance = 0.0) const;

  // Pose of ee_gripper_link in base_link.
  KDL::Frame forward(const JointVector& q) const;
  // Pose of camera_color_optical_frame in base_link (throws std::logic_error if the URDF has none).
  KDL::Frame cameraOptical(const JointVector& q) const;
  bool hasCamera() const { return has_camera_; }
  // Pose of any link of the URDF in base_link; fingers at `finger` [m]. False if the link is unknown.
  bool linkPose(const std::string& link, const JointVector& q, double finger, KDL::Frame& pose) const;
  // Tip frame of every segment of the base_link -> ee_gripper_link chain, in base_link.
  std::vector<KDL::Frame> chainFrames(const JointVector& q) const;
  // Index into chainFrames() of a chain link, or -1.
  int chainIndex(const std::string& link) const;
  // parent -> child transforms of every joint of the URDF (moving or fixed); joints missing from
  // `positions` are at 0, or at their lower limit if 0 is outside it.
  std::vector<LinkTransform> transforms(const std::map<std::string, double>& positions, bool fixed) const;

  // Every box, cylinder and sphere <collision> of the URDF (meshes are skipped).
  const std::vector<CollisionShape>& collisionShapes() const { return collision_shapes_; }
  // Lower and upper limit of any moving joint of the URDF (continuous: -pi, pi); false if unknown.
  bool jointLimits(const std::string& joint, double& lower, double& upper) const;

  const KDL::Chain& chain() const { return chain_; }
  const KDL::Tree& tree() const { return tree_; }

 private:
  KinematicModel() = default;
  void build(const std::string& urdf_xml);

  KDL::Tree tree_;
  KDL::Chain chain_;
  KDL::Chain camera_chain_;
  bool has_camera_ = false;
  std::array<JointLimit, kArmJoints> limits_{};
  std::map<std::string, std::pair<double, double>> all_limits_;
  std::vector<CollisionShape> collision_shapes_;  // every non-fixed joint of the URDF
};

}  // namespace rascal_control
