#pragma once
// Test helper: wrist RGB-D frames of simulator scenarios (rascal_sim_core), with ground truth.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rascal_perception/DetectorParameters.hpp"
#include "rascal_perception/SherdMeasurer.hpp"
#include "rascal_sim/ArmKinematics.hpp"
#include "rascal_sim/Scenario.hpp"
#include "rascal_sim/SherdMeshBuilder.hpp"
#include "rascal_sim/SimParameters.hpp"
#include "rascal_sim/WorldLayout.hpp"

namespace rascal_perception_test {

struct Truth {
  std::string name;
  Eigen::Vector2d centre;
  double yaw = 0.0, length = 0.0, width = 0.0, top = 0.0;  ///< top: z of the box top
  double thickness = 0.0;  ///< [m] wall thickness (vertical, as the simulator builds the shell)
  double curvature = 0.0;  ///< [1/m] across; both faces curve by it (vertical offsets)
  double curvature_long = 0.0;  ///< [1/m] along (the vessel's profile)
  bool convex_up = true;
  std::vector<Eigen::Vector2d> outline;  ///< true outline in base_link (x, y)
  double principal_yaw = 0.0;            ///< major axis of the outline's area moments
  /// The sherd's own frame in base_link, and its outline's own axes in it, as the simulator's
  /// slip model (rascal_sim::SlipModel) reads them: a sherd tilted in a heap shows a shorter
  /// outline from above than its own.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  rascal_sim::OutlineAxes own_axes;
  double ownElongation() const;
  /// How far fingers closing along `closing` (base_link, horizontal) close along its own long
  /// axis, as the simulator's slip model reads it: 0 across, 1 along.
  double closingAlong(const Eigen::Vector3d& closing) const;
  /// Extents of the true outline along `yaw` and across it, and the centre of that box.
  void extents(double yaw, double& length, double& width, Eigen::Vector2d& centre) const;
};

struct Frame {
  cv::Mat rgb, depth;
  rascal_perception::CameraView view;
  std::vector<Truth> truth;
};

/// Is the truth sherd entirely in the image, 5 px from its edges (so it must be found)?
bool fullyInView(const Truth& t, const rascal_perception::CameraView& view);
/// Leftovers said to be cut by the image border that are no part of a sherd partly in view
/// (their centre inside no such sherd's outline circle); the others are counted in `parts`.
int falseParts(const Frame& f, const std::vector<rascal_perception::Leftover>& leftovers, int* parts = nullptr);
/// How many leftovers were seen whole (not cut by the image border).
int wholeLeftovers(const std::vector<rascal_perception::Leftover>& leftovers);
/// The detector as the node configures it: the shipped config/rascal.yaml and the package URDF's
/// gripper (read once).
const rascal_perception::DetectorParameters& shippedDetector();
/// The simulator as the shipped config/rascal.yaml and the URDF set it up (read once).
const rascal_sim::SimParameters& simParameters();
const rascal_sim::WorldLayout& layout();
/// A station of the shipped workcell by type (its area, surface_z, place_at).
const rascal_workcell::Station& station(rascal_workcell::StationType type);
/// Joints putting ee_gripper_link at (x, y, z) pointing straight down.
rascal_sim::JointVector pointDown(double x, double y, double z);
/// Joints putting the wrist camera over `goal` (x, y), image rows along base_link x.
rascal_sim::JointVector cameraOver(const Eigen::Vector2d& goal, double ee_z = 0.25);
/// Survey joints over the pickup mat (computed once).
const rascal_sim::JointVector& surveyJoints();
/// Renders one wrist frame of `scenario` at joints q, after `settle_s` seconds of physics (none:
/// sherds rest where spawned).
Frame render(const rascal_sim::Scenario& scenario, const rascal_sim::JointVector& q, double settle_s = 0.0);
/// A generated scenario on the pickup mat.
rascal_sim::Scenario generated(unsigned seed, int count, double brightness, double kelvin, double shadow,
                               int touching_pairs = 0);
/// A generated heap: `count` sherds tipped out about the pickup mat's centre (spread: standard
/// deviation of their centres), let go 1 cm over what lies under them, three layers at most.
rascal_sim::Scenario generatedHeap(unsigned seed, int count, double spread);
/// Slides sherd j towards sherd i until their outlines touch (within 0.3 mm).
void makeTouching(rascal_sim::Scenario& scenario, size_t i, size_t j);
rascal_sim::Scenario loadScenario(const std::string& file);

}  // namespace rascal_perception_test
