#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "TestModel.hpp"
#include "rascal_control/AnalyticIk.hpp"

using namespace rascal_control;

namespace {

AnalyticIk makeIk() {
  AnalyticIk::Geometry g;
  std::string why;
  EXPECT_TRUE(AnalyticIk::extract(testModel().chain(), g, why)) << why;
  return AnalyticIk(g);
}

}  // namespace

TEST(AnalyticIk, GeometryMatchesFacts) {
  const AnalyticIk ik = makeIk();
  const auto& g = ik.geometry();
  EXPECT_NEAR(g.shoulder.x(), 0.0, 1e-12);
  EXPECT_NEAR(g.shoulder.z(), 0.11065, 1e-12);
  EXPECT_NEAR(g.elbow.x(), 0.04975, 1e-12);
  EXPECT_NEAR(g.elbow.z(), 0.36065, 1e-12);
  EXPECT_NEAR(g.wrist.x(), 0.29975, 1e-12);
  EXPECT_NEAR(g.wrist.z(), 0.36065, 1e-12);
  EXPECT_NEAR(g.tip_home.p.x(), 0.458325, 1e-12);
  // facts §1.5: shoulder -> elbow 0.25490 m, elbow -> wrist 0.25 m.
  EXPECT_NEAR(ik.maxReach(), 0.25490 + 0.25, 1e-5);
}

TEST(AnalyticIk, EverySolutionReachesThePose) {
  const AnalyticIk ik = makeIk();
  std::mt19937 rng(11);
  for (int n = 0; n < 2000; ++n) {
    const JointVector q = randomJoints(rng, testModel());
    const KDL::Frame target = testModel().forward(q);
    std::vector<JointVector> solutions;
    double reach = 0.0;
    ASSERT_TRUE(ik.solveAll(target, q, solutions, reach));
    ASSERT_GE(solutions.size(), 2u);
    bool original = false;
    for (const JointVector& s : solutions) {
      EXPECT_TRUE(KDL::Equal(testModel().forward(s), target, 1e-9));
      double d = 0.0;
      for (std::size_t j = 0; j < kArmJoints; ++j) {
        d = std::max(d, std::fabs(std::remainder(s[j] - q[j], 2 * M_PI)));
      }
      original = original || d < 1e-6;
    }
    EXPECT_TRUE(original) << "the sampled configuration is among the solutions";
  }
}

TEST(AnalyticIk, WristSingularityKeepsTheSeed) {
  const AnalyticIk ik = makeIk();
  const JointVector q{0.2, 0.1, -0.3, 0.7, 0.0, -0.4};
  std::vector<JointVector> solutions;
  double reach = 0.0;
  ASSERT_TRUE(ik.solveAll(testModel().forward(q), q, solutions, reach));
  bool seed_kept = false;
  for (const JointVector& s : solutions) {
    EXPECT_TRUE(KDL::Equal(testModel().forward(s), testModel().forward(q), 1e-9));
    seed_kept = seed_kept || (std::fabs(s[3] - 0.7) < 1e-9 && std::fabs(s[5] + 0.4) < 1e-9);
  }
  EXPECT_TRUE(seed_kept);
}

TEST(AnalyticIk, FarPoseIsOutOfReach) {
  const AnalyticIk ik = makeIk();
  std::vector<JointVector> solutions;
  double reach = 0.0;
  EXPECT_FALSE(ik.solveAll(KDL::Frame(KDL::Vector(1.3, 0.0, 0.2)), JointVector{}, solutions, reach));
  EXPECT_GT(reach, 0.3);
}

TEST(AnalyticIk, RejectsOtherChains) {
  KDL::Chain chain;
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame(KDL::Vector(0, 0, 0.1))));
  AnalyticIk::Geometry g;
  std::string why;
  EXPECT_FALSE(AnalyticIk::extract(chain, g, why));
  EXPECT_FALSE(why.empty());
}
