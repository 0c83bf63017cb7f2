#include <gtest/gtest.h>

#include <cmath>

#include "rascal_perception/GraspPlanner.hpp"
#include "rascal_perception/SherdSelector.hpp"

using namespace rascal_perception;

namespace {
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

TEST(SherdSelector, OrdersByPolicy) {
  std::vector<SherdDetection> v{sherd(0.30, 0.25, 0, 0.05, 0.04, 0.01), sherd(0.10, 0.25, 0, 0.07, 0.05, 0.01),
                                sherd(0.16, 0.25, 0, 0.04, 0.035, 0.01)};
  GraspPlanner(PerceptionConfig()).score(v);
  SherdSelector::order(v, SelectionPolicy::kNearest, Eigen::Vector2d(0.15, 0.25));
  EXPECT_NEAR(v[0].centre.x(), 0.16, 1e-12);
  SherdSelector::order(v, SelectionPolicy::kLargest, Eigen::Vector2d::Zero());
  EXPECT_NEAR(v[0].centre.x(), 0.10, 1e-12);
  SherdSelector::order(v, SelectionPolicy::kMostIsolated, Eigen::Vector2d::Zero());
  EXPECT_NEAR(v[0].centre.x(), 0.30, 1e-12);
  EXPECT_THROW(parseSelectionPolicy("random"), std::invalid_argument);
  EXPECT_EQ(parseSelectionPolicy("most_isolated"), SelectionPolicy::kMostIsolated);
}
