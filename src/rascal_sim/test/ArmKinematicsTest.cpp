#include <gtest/gtest.h>

#include "rascal_sim/ArmKinematics.hpp"

using rascal_sim::ArmKinematics;
using rascal_sim::JointVector;

TEST(ArmKinematics, HomeMatchesFacts) {
  const auto T = ArmKinematics::forward(JointVector{0, 0, 0, 0, 0, 0}, 0.03);
  const Eigen::Vector3d ee = T[rascal_sim::kEeGripperLink].translation();
  EXPECT_NEAR(ee.x(), 0.458325, 1e-9);
  EXPECT_NEAR(ee.y(), 0.0, 1e-9);
  EXPECT_NEAR(ee.z(), 0.36065, 1e-9);
  EXPECT_NEAR(T[rascal_sim::kLeftFingerLink].translation().y(), 0.03, 1e-12);
}

TEST(ArmKinematics, SleepMatchesFacts) {
  const auto T = ArmKinematics::forward(JointVector{0, -1.80, 1.55, 0, 0.8, 0}, 0.03);
  const Eigen::Vector3d ee = T[rascal_sim::kEeGripperLink].translation();
  EXPECT_NEAR(ee.x(), 0.12265, 1e-4);
  EXPECT_NEAR(ee.z(), 0.08126, 1e-4);
}

TEST(ArmKinematics, WristCameraLooksAlongTheGripper) {
  const auto T = ArmKinematics::forward(JointVector{0, 0, 0, 0, 0, 0}, 0.03);
  const Eigen::Isometry3d& cam = T[rascal_sim::kCameraColorOpticalFrame];
  EXPECT_NEAR(cam.translation().x(), 0.36475 + 0.04, 1e-9);
  EXPECT_NEAR(cam.translation().y(), 0.015, 1e-9);
  EXPECT_NEAR(cam.translation().z(), 0.36065 + 0.055, 1e-9);
  EXPECT_TRUE(cam.linear().col(2).isApprox(Eigen::Vector3d::UnitX(), 1e-9));   // z forward
  EXPECT_TRUE(cam.linear().col(0).isApprox(-Eigen::Vector3d::UnitY(), 1e-9));  // x right
  EXPECT_TRUE(cam.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ(), 1e-9));  // y down
}
