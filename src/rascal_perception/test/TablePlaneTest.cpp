#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rascal_perception/TablePlane.hpp"

using namespace rascal_perception;

TEST(TablePlane, FitsATiltedTableDespiteSherdsOnIt) {
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.0005f);
  std::uniform_real_distribution<float> u(-0.15f, 0.15f);
  std::vector<Eigen::Vector3f> pts;
  const Eigen::Vector3f n = Eigen::Vector3f(0.02f, -0.01f, 1.0f).normalized();
  for (int i = 0; i < 2000; ++i) {  // z = -(nx x + ny y) / nz + 0.025
    const float x = u(rng), y = u(rng);
    pts.emplace_back(x, y, -(n.x() * x + n.y() * y) / n.z() + 0.025f + noise(rng));
  }
  for (int i = 0; i < 600; ++i) pts.emplace_back(u(rng), u(rng), 0.025f + 0.008f);  // sherd tops
  const PlaneFit fit = TablePlane::fit(pts, 0.003);
  ASSERT_TRUE(fit.ok);
  EXPECT_GE(fit.inliers, 1900);
  EXPECT_NEAR(fit.plane.head<3>().dot(n.cast<double>()), 1.0, 1e-4);
  EXPECT_NEAR(-fit.plane.w() / fit.plane.z(), 0.025, 0.0005);  // height at x = y = 0
}

TEST(TablePlane, TooFewPointsIsNoFit) {
  EXPECT_FALSE(TablePlane::fit({Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0)}, 0.003).ok);
}
