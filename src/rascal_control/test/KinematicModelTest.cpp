#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "TestModel.hpp"
#include "rascal_control/KinematicModel.hpp"

using namespace rascal_control;

namespace {

// Product of exponentials with Interbotix's M and screw list (facts/widowx250_d435.md §3).
Eigen::Matrix4d poeForward(const JointVector& q) {
  const double s[6][6] = {{0, 0, 1, 0, 0, 0},
                          {0, 1, 0, -0.11065, 0, 0},
                          {0, 1, 0, -0.36065, 0, 0.04975},
                          {1, 0, 0, 0, 0.36065, 0},
                          {0, 1, 0, -0.36065, 0, 0.29975},
                          {1, 0, 0, 0, 0.36065, 0}};
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d w(s[i][0], s[i][1], s[i][2]), v(s[i][3], s[i][4], s[i][5]);
    Eigen::Matrix3d w_hat;
    w_hat << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    const double th = q[i];
    const Eigen::Matrix3d r = Eigen::Matrix3d::Identity() + std::sin(th) * w_hat +
                              (1 - std::cos(th)) * w_hat * w_hat;
    const Eigen::Matrix3d g = Eigen::Matrix3d::Identity() * th + (1 - std::cos(th)) * w_hat +
                              (th - std::sin(th)) * w_hat * w_hat;
    Eigen::Matrix4d e = Eigen::Matrix4d::Identity();
    e.block<3, 3>(0, 0) = r;
    e.block<3, 1>(0, 3) = g * v;
    t = t * e;
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 3) = 0.458325;
  m(2, 3) = 0.36065;
  return t * m;
}

}  // namespace

TEST(KinematicModel, HomePoseMatchesFacts) {
  const KDL::Frame tip = testModel().forward(JointVector{});
  EXPECT_NEAR(tip.p.x(), 0.458325, 1e-9);
  EXPECT_NEAR(tip.p.y(), 0.0, 1e-9);
  EXPECT_NEAR(tip.p.z(), 0.36065, 1e-9);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(tip.M(i, j), i == j ? 1.0 : 0.0, 1e-12);
    }
  }
}

TEST(KinematicModel, NamedPosesMatchFacts) {
  const KDL::Frame sleep = testModel().forward(JointVector{0, -1.80, 1.55, 0, 0.8, 0});
  EXPECT_NEAR(sleep.p.x(), 0.12265, 1e-5);
  EXPECT_NEAR(sleep.p.y(), 0.0, 1e-9);
  EXPECT_NEAR(sleep.p.z(), 0.08126, 1e-5);
  const KDL::Frame upright = testModel().forward(JointVector{0, 0, -1.5708, 0, 0, 0});
  EXPECT_NEAR(upright.p.x(), 0.04975, 1e-5);
  EXPECT_NEAR(upright.p.z(), 0.76922, 1e-5);
}

TEST(KinematicModel, ForwardMatchesProductOfExponentials) {
  std::mt19937 rng(7);
  double worst = 0.0;
  for (int n = 0; n < 500; ++n) {
    const JointVector q = randomJoints(rng, testModel());
    const KDL::Frame kdl = testModel().forward(q);
    const Eigen::Matrix4d poe = poeForward(q);
    for (int i = 0; i < 3; ++i) {
      worst = std::max(worst, std::fabs(kdl.p(i) - poe(i, 3)));
      for (int j = 0; j < 3; ++j) {
        worst = std::max(worst, std::fabs(kdl.M(i, j) - poe(i, j)));
      }
    }
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(KinematicModel, LimitsMatchFacts) {
  const auto& l = testModel().limits();
  const double lower[6] = {-3.141583, -1.884956, -2.146755, -3.141583, -1.745329, -3.141583};
  const double upper[6] = {3.141583, 1.989675, 1.605703, 3.141583, 2.146755, 3.141583};
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    EXPECT_NEAR(l[j].lower, lower[j], 1e-6) << j;
    EXPECT_NEAR(l[j].upper, upper[j], 1e-6) << j;
    EXPECT_NEAR(l[j].velocity, M_PI, 1e-4) << j;
  }
  EXPECT_TRUE(testModel().withinLimits(JointVector{}));
  EXPECT_EQ(testModel().firstLimitViolation(JointVector{0, 0, 1.7, 0, 0, 0}), 2);
}

TEST(KinematicModel, CameraLooksAlongTheGripper) {
  ASSERT_TRUE(testModel().hasCamera());
  const KDL::Frame camera = testModel().cameraOptical(JointVector{});
  // gripper_link (0.36475, 0, 0.36065) + camera_link (0.04, 0, 0.055) + colour (0, 0.015, 0).
  EXPECT_NEAR(camera.p.x(), 0.40475, 1e-9);
  EXPECT_NEAR(camera.p.y(), 0.015, 1e-9);
  EXPECT_NEAR(camera.p.z(), 0.41565, 1e-9);
  const KDL::Vector z = camera.M.UnitZ();  // optical axis
  EXPECT_NEAR(z.x(), 1.0, 1e-9);
  KDL::Frame via_tree;
  ASSERT_TRUE(testModel().linkPose("camera_color_optical_frame", JointVector{0.3, 0.2, -0.4, 0.1, 1.0, 0.5},
                                   0.02, via_tree));
  EXPECT_TRUE(KDL::Equal(via_tree, testModel().cameraOptical({0.3, 0.2, -0.4, 0.1, 1.0, 0.5}), 1e-12));
}

TEST(KinematicModel, LinkPosesAndTransforms) {
  KDL::Frame finger;
  ASSERT_TRUE(testModel().linkPose("left_finger_link", JointVector{}, 0.03, finger));
  EXPECT_NEAR(finger.p.x(), 0.43075, 1e-9);
  EXPECT_NEAR(finger.p.y(), 0.03, 1e-9);
  EXPECT_FALSE(testModel().linkPose("no_such_link", JointVector{}, 0.03, finger));
  const auto moving = testModel().transforms({{"waist", 0.5}}, false);
  const auto fixed = testModel().transforms({}, true);
  EXPECT_EQ(moving.size(), 9u);  // 6 arm joints, gripper horn, 2 fingers
  EXPECT_GE(fixed.size(), 7u);
  bool waist_found = false;
  for (const auto& t : moving) {
    if (t.child == "shoulder_link") {
      waist_found = true;
      EXPECT_EQ(t.parent, "base_link");
      double r, p, y;
      t.pose.M.GetRPY(r, p, y);
      EXPECT_NEAR(y, 0.5, 1e-12);
    }
    if (t.child == "left_finger_link") {
      EXPECT_NEAR(t.pose.p.y(), 0.015, 1e-12);  // missing = lower limit
    }
  }
  EXPECT_TRUE(waist_found);
}

TEST(KinematicModel, BadInputThrows) {
  EXPECT_THROW(KinematicModel::fromFile("/nonexistent/wx250s.urdf"), std::runtime_error);
  EXPECT_THROW(KinematicModel::fromString("<robot"), std::runtime_error);
  EXPECT_THROW(KinematicModel::fromString("<robot name=\"r\"><link name=\"base_link\"/></robot>"),
               std::runtime_error);
}
