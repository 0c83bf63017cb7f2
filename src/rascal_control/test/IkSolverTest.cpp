#include <chrono>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "TestModel.hpp"
#include "rascal_control/IkSolver.hpp"

using namespace rascal_control;

namespace {

struct Score {
  int tried = 0;
  int solved = 0;
  double worst_position = 0.0;
  double worst_angle = 0.0;
  int limit_breaks = 0;
};

// Poses from random joint vectors inside the limits, solved from a seed that is `seed_noise` rad
// away from the sampled vector on every joint.
Score score(IkSolver& ik, IkSolver::Method method, int count, unsigned seed, double seed_noise) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-seed_noise, seed_noise);
  Score s;
  for (int n = 0; n < count; ++n) {
    const JointVector q = randomJoints(rng, testModel());
    JointVector start = q;
    for (double& v : start) {
      v += noise(rng);
    }
    const KDL::Frame target = testModel().forward(q);
    const IkResult r = ik.solve(target, start, method);
    ++s.tried;
    if (!r.ok()) {
      continue;
    }
    ++s.solved;
    double position = 0.0, angle = 0.0;
    IkSolver::frameError(target, testModel().forward(r.joints), position, angle);
    s.worst_position = std::max(s.worst_position, position);
    s.worst_angle = std::max(s.worst_angle, angle);
    s.limit_breaks += testModel().withinLimits(r.joints) ? 0 : 1;
  }
  return s;
}

}  // namespace

TEST(IkSolver, TenThousandRandomPoses) {
  IkSolver ik(testModel());
  ASSERT_TRUE(ik.analyticAvailable()) << ik.analyticUnavailableReason();
  const Score s = score(ik, IkSolver::Method::Auto, 10000, 42, 3.0);
  EXPECT_GE(s.solved, 9950) << "success " << s.solved << " / " << s.tried;
  EXPECT_LT(s.worst_position, 0.0005);
  EXPECT_LT(s.worst_angle, 0.005);
  EXPECT_EQ(s.limit_breaks, 0);
}

TEST(IkSolver, NumericKdlRandomPoses) {
  IkSolver ik(testModel());
  const Score s = score(ik, IkSolver::Method::Numeric, 10000, 43, 3.0);
  EXPECT_GE(s.solved, static_cast<int>(0.995 * s.tried)) << "success " << s.solved << " / " << s.tried;
  EXPECT_LT(s.worst_position, 0.0005);
  EXPECT_LT(s.worst_angle, 0.005);
  EXPECT_EQ(s.limit_breaks, 0);
}

TEST(IkSolver, ReturnsTheSolutionClosestToTheSeed) {
  IkSolver ik(testModel());
  std::mt19937 rng(5);
  for (int n = 0; n < 500; ++n) {
    const JointVector q = randomJoints(rng, testModel(), 0.01);
    const IkResult r = ik.solve(testModel().forward(q), q);
    ASSERT_TRUE(r.ok()) << r.message;
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      if (std::fabs(q[4]) > 1e-3) {  // away from the wrist singularity the seed itself is the answer
        EXPECT_NEAR(r.joints[j], q[j], 1e-6);
      }
    }
  }
}

TEST(IkSolver, TopDownPose) {
  IkSolver ik(testModel());
  const KDL::Frame target = IkSolver::topDown(0.3, -0.1, 0.05, 0.4);
  const IkResult r = ik.solve(target, JointVector{});
  ASSERT_TRUE(r.ok()) << r.message;
  const KDL::Frame tip = testModel().forward(r.joints);
  EXPECT_NEAR(tip.M.UnitX().z(), -1.0, 1e-9);  // fingers point down
  EXPECT_NEAR((tip.p - target.p).Norm(), 0.0, 1e-9);
}

TEST(IkSolver, FarPoseIsUnreachable) {
  IkSolver ik(testModel());
  const KDL::Frame far = IkSolver::topDown(1.0, 0.0, 0.1, 0.0);
  IkResult r = ik.solve(far, JointVector{});
  EXPECT_EQ(r.code, IkCode::Unreachable);
  EXPECT_NE(r.message.find("out of reach"), std::string::npos) << r.message;
  r = ik.solve(far, JointVector{}, IkSolver::Method::Numeric);
  EXPECT_EQ(r.code, IkCode::Unreachable) << r.message;
}

TEST(IkSolver, PoseBeyondTheLimitsIsJointLimit) {
  // Configurations with the elbow folded beyond its limit; keep those whose pose no in-limit
  // configuration reaches.
  IkSolver ik(testModel());
  std::mt19937 rng(9);
  int limited = 0;
  for (int n = 0; n < 200 && limited < 5; ++n) {
    JointVector q = randomJoints(rng, testModel());
    q[2] = -2.6;
    const IkResult r = ik.solve(testModel().forward(q), q);
    if (r.code == IkCode::JointLimit) {
      ++limited;
      EXPECT_NE(r.message.find("limit"), std::string::npos);
    } else {
      EXPECT_EQ(r.code, IkCode::Ok) << r.message;
    }
  }
  EXPECT_GT(limited, 0);
}

TEST(IkSolver, MalformedTargetIsInvalid) {
  IkSolver ik(testModel());
  KDL::Frame bad;
  bad.M = KDL::Rotation(1, 0, 0, 0, 2, 0, 0, 0, 1);
  EXPECT_EQ(ik.solve(bad, JointVector{}).code, IkCode::Invalid);
  bad = KDL::Frame(KDL::Vector(std::nan(""), 0, 0));
  EXPECT_EQ(ik.solve(bad, JointVector{}).code, IkCode::Invalid);
}
