#include "rascal_sim/SlipModel.hpp"

#include <gtest/gtest.h>

#include <cmath>

using rascal_sim::OutlineAxes;
using rascal_sim::SlipModel;

TEST(SlipModel, ACentredGraspAcrossSlipsOnlyByTheFlatChance) {
  EXPECT_DOUBLE_EQ(SlipModel::chance(0.0, 0.0, 0.43, false), 0.02);
}

TEST(SlipModel, ClosingAlongGrowsWithTheElongationUntilWidthIsSixTenthsOfLength) {
  EXPECT_NEAR(SlipModel::alongTerm(1.0, 0.0), 0.0, 1e-12);  // round: no long axis
  EXPECT_NEAR(SlipModel::alongTerm(1.0, 0.2), 0.3, 1e-12);
  EXPECT_NEAR(SlipModel::alongTerm(1.0, 0.4), 0.6, 1e-12);
  EXPECT_NEAR(SlipModel::alongTerm(1.0, 0.7), 0.6, 1e-12);
  EXPECT_NEAR(SlipModel::alongTerm(0.5, 0.4), 0.15, 1e-12);  // turned 30 degrees
}

TEST(SlipModel, ClosingAlongIsTheCosineToTheMajorAxisWhicheverWayTheFingersFace) {
  OutlineAxes axes;
  axes.major = Eigen::Vector2d(std::cos(0.3), std::sin(0.3));
  axes.length = 0.06, axes.width = 0.03;
  EXPECT_DOUBLE_EQ(SlipModel::elongation(axes), 0.5);
  const double turn = 0.3 + M_PI / 3;  // 60 degrees off the major axis
  EXPECT_NEAR(SlipModel::closingAlong({std::cos(turn), std::sin(turn), 0.2}, axes), 0.5, 1e-12);
  EXPECT_NEAR(SlipModel::closingAlong({-std::cos(turn), -std::sin(turn), 0.0}, axes), 0.5, 1e-12);
}

TEST(SlipModel, AnOverweightSherdNearlyAlwaysSlipsAndNoChanceExceedsNinetyEightPercent) {
  EXPECT_DOUBLE_EQ(SlipModel::chance(0.0, 0.0, 0.0, true), 0.92);
  EXPECT_DOUBLE_EQ(SlipModel::chance(1.0, 1.0, 0.5, true), 0.98);
}
