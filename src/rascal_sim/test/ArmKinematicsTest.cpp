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

using rascal_sim::LinkBox;

TEST(ArmKinematics, PadsGrowEachFingerBoxTowardsTheOtherFinger) {
  const auto stock = ArmKinematics::linkBoxes();
  const auto padded = ArmKinematics::linkBoxes(0.0075);
  ASSERT_EQ(stock.size(), padded.size());
  int fingers = 0;
  for (size_t i = 0; i < stock.size(); ++i) {
    const double side = stock[i].link == rascal_sim::kLeftFingerLink ? 1.0 : stock[i].link == rascal_sim::kRightFingerLink ? -1.0 : 0.0;
    const auto inner = [side](const LinkBox& b) {  // the inner face's y in the finger's frame
      return b.offset.translation().y() - side * b.size.y() / 2.0;
    };
    if (side == 0.0) {
      EXPECT_TRUE(padded[i].size.isApprox(stock[i].size));
      continue;
    }
    ++fingers;
    EXPECT_NEAR(inner(stock[i]), 0.0, 1e-12);  // the stock face on the joint (30 mm closed)
    EXPECT_NEAR(inner(padded[i]), -side * 0.0075, 1e-12);
    // the outer face stays where it was
    EXPECT_NEAR(padded[i].offset.translation().y() + side * padded[i].size.y() / 2.0,
                stock[i].offset.translation().y() + side * stock[i].size.y() / 2.0, 1e-12);
  }
  EXPECT_EQ(fingers, 2);
}
