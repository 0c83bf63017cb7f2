#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "rascal_perception/GraspPlanner.hpp"

using namespace rascal_perception;

namespace {
/// The defaults with the gripper of rascal_description's URDF (what the node reads).
PerceptionConfig withGripper() {
  PerceptionConfig c;
  c.gripper = rascal_workcell::GripperGeometry::fromPackageUrdf();
  return c;
}

SherdDetection sherd(double x, double y, double yaw, double length, double width, double height) {
  SherdDetection s;
  s.centre = Eigen::Vector3d(x, y, height);
  s.yaw = yaw;
  s.length = length;
  s.width = width;
  s.height = height;
  s.area = length * width;
  s.depth_valid = true;
  const Eigen::Rotation2Dd r(yaw);
  for (const auto& c : {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1), Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1)}) {
    const Eigen::Vector2d p = Eigen::Vector2d(x, y) + r * Eigen::Vector2d(c.x() * length / 2, c.y() * width / 2);
    s.outline.emplace_back(p.x(), p.y(), 0.0);
  }
  return s;
}
}  // namespace

TEST(GraspPlanner, TakesTheGripperFromTheUrdf) {
  const GraspPlanner planner(withGripper());
  EXPECT_NEAR(planner.minOpening(), 0.030, 1e-12);  // facts 1.4: 30 .. 74 mm between the fingers
  EXPECT_NEAR(planner.maxOpening(), 0.074, 1e-12);
  EXPECT_NEAR(withGripper().gripper.fingertip_offset, 0.0044, 0.0001);  // the finger box's end
  EXPECT_THROW(GraspPlanner{PerceptionConfig()}, std::invalid_argument);  // no gripper: refused
}

TEST(GraspPlanner, FingersCloseAcrossTheMinorAxisPointingDown) {
  const PerceptionConfig c = withGripper();
  SherdDetection s = sherd(0.2, 0.25, 0.7, 0.06, 0.04, 0.010);
  GraspPlanner(c).plan(s);
  const Eigen::Matrix3d R = s.grasp.linear();
  EXPECT_NEAR(R.col(0).z(), -1.0, 1e-9);  // approach: gripper x straight down
  const Eigen::Vector2d minor(-std::sin(0.7), std::cos(0.7));
  EXPECT_NEAR(std::fabs(R.col(1).head<2>().dot(minor)), 1.0, 1e-9);  // closing along y = minor axis
  EXPECT_NEAR(s.grasp.translation().z(), 0.6 * 0.010 + c.gripper.fingertip_offset, 1e-9);
  EXPECT_NEAR(s.grasp_width, 0.04 + c.grasp_margin, 1e-12);
}

TEST(GraspPlanner, ClampsTheHeightAndTheOpening) {
  const PerceptionConfig c = withGripper();
  SherdDetection thin = sherd(0.2, 0.25, 0.0, 0.05, 0.010, 0.004);
  GraspPlanner(c).plan(thin);
  EXPECT_NEAR(thin.grasp.translation().z(), c.grasp_tip_clearance + c.gripper.fingertip_offset, 1e-9);
  EXPECT_DOUBLE_EQ(thin.grasp_width, c.gripper.minOpening());
  SherdDetection wide = sherd(0.2, 0.25, 0.0, 0.09, 0.07, 0.01);
  GraspPlanner(c).plan(wide);
  EXPECT_DOUBLE_EQ(wide.grasp_width, c.gripper.maxOpening());
  std::vector<SherdDetection> v{wide};
  GraspPlanner(c).score(v);
  EXPECT_NEAR(v[0].score, 0.3, 1e-9);  // wider than the gripper opens: fit 0.3
}

TEST(GraspPlanner, ScoresCrowdedSherdsLower) {
  const PerceptionConfig c = withGripper();
  std::vector<SherdDetection> v{sherd(0.10, 0.25, 0, 0.05, 0.04, 0.01), sherd(0.155, 0.25, 0, 0.05, 0.04, 0.01),
                                sherd(0.30, 0.25, 0, 0.05, 0.04, 0.01)};
  GraspPlanner(c).score(v);
  EXPECT_NEAR(v[0].clearance, 0.005, 1e-9);
  EXPECT_LT(v[0].score, v[2].score);
  EXPECT_NEAR(v[2].score, 1.0, 1e-9);
}
