#pragma once
// The ODE world: table, station fixtures (the workcell's collision boxes), the scale platform as
// its own body, sherds, and the arm as kinematic collision boxes that follow the servos.
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "rascal_sim/ArmKinematics.hpp"
#include "rascal_sim/Renderer.hpp"
#include "rascal_sim/Scenario.hpp"
#include "rascal_sim/WorldLayout.hpp"
#include "rascal_workcell/GripperGeometry.hpp"

namespace rascal_sim {

struct SherdState {
  std::string name;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< body frame (box centre) in base_link
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  double mass = 0.0, thickness = 0.0, length = 0.0, width = 0.0;
  /// [1/m] the shell's curvature across (the vessel's: diameter 2 / curvature), 0 for a mesh;
  /// the shell's faces are vertical offsets of one surface, so both faces curve by it
  double curvature = 0.0;
  double curvature_long = 0.0;  ///< [1/m] along (the vessel's profile)
  bool convex_up = true;
  Eigen::Vector3d box_size = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector2d> outline;  ///< in the body frame
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();
  bool held = false;
};

/// Which sherd each finger touched in the last step (-1 = none) and how deep.
struct FingerContacts {
  int left = -1, right = -1;
  double left_depth = 0.0, right_depth = 0.0;
};

/// An arm box (a finger or a link) in contact with a sherd it does not hold, in the last step.
struct ArmTouch {
  int sherd = -1;
  int link = -1;  ///< ArmLink of the box
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< [m] a contact point in base_link (the first)
};

class World {
 public:
  /// Static fixtures from layout.boxes (where the stations really stand); the arm starts at the
  /// sleep pose with the fingers fully open (gripper.finger_max). The clock starts at start_time
  /// (a world rebuilt for a scenario that moves the stations carries the simulator's time on).
  World(const WorldLayout& layout, const rascal_workcell::GripperGeometry& gripper, double start_time = 0.0);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Replaces all sherds (throws std::runtime_error for a bad spec, naming the sherd).
  void spawn(const std::vector<SherdSpec>& sherds);
  void clearSherds();
  /// Seeds ODE's (process-wide) random generator, with which QuickStep reorders its constraints:
  /// the same seed and commands replay the same motion, whatever ran before in the process.
  void seedSolver(unsigned long seed);
  /// Puts the arm at q / finger at once (start-up and reset).
  void placeArm(const JointVector& q, double finger);
  /// The arm pose the kinematic links must reach at the end of the next step.
  void setArmTarget(const JointVector& q, double finger);
  void step(double dt);
  double time() const { return time_; }

  /// Load on the scale platform [kg] from its support force over the last step.
  double scaleLoad() const;
  const FingerContacts& fingerContacts() const;
  /// Every arm box touching a sherd it does not hold in the last step, one per (sherd, link).
  const std::vector<ArmTouch>& armTouches() const;
  /// Fixes sherd i to the gripper (ODE fixed joint) / lets it go.
  void hold(int sherd);
  void release();
  int held() const;
  /// Fingers and gripper pass through sherd i until `until` (a slipping sherd falls out).
  void ignoreGripperContacts(int sherd, double until);
  /// The arm passes through sherd i until a step in which no arm box overlaps it any more (a
  /// sherd let go while its box is wedged between the fingers falls out instead of sticking).
  void ignoreGripperContactsWhileOverlapping(int sherd);
  /// Ends every such pass-through (a new close touches whatever is between the fingers again).
  void stopIgnoringOverlaps();

  size_t sherdCount() const;
  SherdState sherd(size_t i) const;
  const std::array<Eigen::Isometry3d, kArmLinkCount>& armPose() const;
  /// Everything the cameras see (fixtures, sherds and, if asked, the arm links).
  void renderItems(std::vector<RenderItem>& items, bool include_arm = true) const;
  const WorldLayout& layout() const { return layout_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  WorldLayout layout_;
  double time_ = 0.0;
};

}  // namespace rascal_sim
