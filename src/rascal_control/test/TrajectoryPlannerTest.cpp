#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "TestModel.hpp"
#include "rascal_control/TrajectoryPlanner.hpp"

using namespace rascal_control;

namespace {

constexpr double kVelocity = M_PI;  // [rad/s] facts/timing.md
constexpr double kAcceleration = 5.0;  // [rad/s^2]
constexpr double kDt = 0.001;

// Largest |qd| / limit and |qdd| / limit at 1 ms sampling, from the trajectory's own derivatives
// and from finite differences of its positions.
void limitRatios(const Trajectory& t, double scale, double& velocity, double& acceleration,
                 double& fd_velocity) {
  velocity = acceleration = fd_velocity = 0.0;
  Trajectory::Sample previous = t.sample(0.0);
  for (double time = kDt; time <= t.duration() + kDt; time += kDt) {
    const Trajectory::Sample s = t.sample(std::min(time, t.duration()));
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      velocity = std::max(velocity, std::fabs(s.qd[j]) / (kVelocity * scale));
      acceleration = std::max(acceleration, std::fabs(s.qdd[j]) / (kAcceleration * scale));
      const double dt = s.t - previous.t;
      if (dt > 1e-9) {
        fd_velocity = std::max(fd_velocity, std::fabs(s.q[j] - previous.q[j]) / dt / (kVelocity * scale));
      }
    }
    previous = s;
  }
}

// Rest-to-rest minimum time of one joint moving d under the limits.
double trapezoidMinimum(double d, double v, double a) {
  d = std::fabs(d);
  return d >= v * v / a ? d / v + v / a : 2.0 * std::sqrt(d / a);
}

}  // namespace

TEST(TrajectoryPlanner, JointMovesAreSynchronisedTrapezoids) {
  IkSolver ik(testModel());
  TrajectoryPlanner planner(testModel(), ik, nullptr);
  std::mt19937 rng(3);
  for (int n = 0; n < 200; ++n) {
    const JointVector a = randomJoints(rng, testModel());
    const JointVector b = randomJoints(rng, testModel());
    const double scale = n % 4 == 0 ? 0.5 : 1.0;
    const PlanResult r = planner.planJoint(a, b, scale);
    ASSERT_TRUE(r.ok()) << r.message;
    double slowest = 0.0;
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      slowest = std::max(slowest, trapezoidMinimum(b[j] - a[j], kVelocity * scale, kAcceleration * scale));
    }
    EXPECT_LE(r.trajectory.duration(), 1.05 * slowest);
    EXPECT_GE(r.trajectory.duration(), slowest - 1e-9);
    double v = 0, acc = 0, fd = 0;
    limitRatios(r.trajectory, scale, v, acc, fd);
    EXPECT_LE(v, 1.0 + 1e-9);
    EXPECT_LE(acc, 1.0 + 1e-9);
    EXPECT_LE(fd, 1.0 + 1e-9);
    const Trajectory::Sample end = r.trajectory.sample(r.trajectory.duration());
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      EXPECT_NEAR(end.q[j], b[j], 1e-12);
      EXPECT_NEAR(end.qd[j], 0.0, 1e-12);
      EXPECT_NEAR(r.trajectory.sample(0.0).q[j], a[j], 1e-12);
    }
  }
}

TEST(TrajectoryPlanner, ZeroMoveAndBadInput) {
  IkSolver ik(testModel());
  TrajectoryPlanner planner(testModel(), ik, nullptr);
  const JointVector q{0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  PlanResult r = planner.planJoint(q, q, 1.0);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.trajectory.duration(), 0.0);
  EXPECT_EQ(r.trajectory.sampled(0.01).size(), 1u);
  EXPECT_EQ(planner.planJoint(q, q, 0.0).code, PlanCode::InvalidGoal);
  EXPECT_EQ(planner.planJoint(q, q, 1.5).code, PlanCode::InvalidGoal);
  r = planner.planJoint(q, JointVector{0, 0, 1.7, 0, 0, 0}, 1.0);
  EXPECT_EQ(r.code, PlanCode::InvalidGoal);
  EXPECT_NE(r.message.find("elbow"), std::string::npos) << r.message;
}

TEST(TrajectoryPlanner, LinearMoveStaysOnTheLine) {
  IkSolver ik(testModel());
  TrajectoryPlanner planner(testModel(), ik, nullptr);
  struct Case {
    KDL::Frame from, to;
    double scale;
  };
  const Case cases[] = {
      {IkSolver::topDown(0.25, 0.15, 0.15, 0.0), IkSolver::topDown(0.35, -0.10, 0.05, 0.8), 1.0},
      {IkSolver::topDown(0.20, 0.25, 0.12, 0.3), IkSolver::topDown(0.20, 0.25, 0.02, 0.3), 1.0},
      {IkSolver::topDown(0.30, 0.00, 0.10, 0.0), IkSolver::topDown(0.02, -0.31, 0.12, -1.0), 0.5},
      {KDL::Frame(KDL::Vector(0.40, 0.10, 0.25)), KDL::Frame(KDL::Vector(0.30, -0.20, 0.35)), 1.0},
  };
  for (const Case& c : cases) {
    const IkResult start = ik.solve(c.from, JointVector{});
    ASSERT_TRUE(start.ok()) << start.message;
    const PlanResult r = planner.planLinear(start.joints, c.to, c.scale);
    ASSERT_TRUE(r.ok()) << r.message;
    double worst = 0.0;
    const KDL::Vector a = c.from.p, b = c.to.p, ab = b - a;
    for (double t = 0.0; t <= r.trajectory.duration(); t += kDt) {
      const KDL::Vector p = testModel().forward(r.trajectory.sample(t).q).p;
      const double u = std::min(1.0, std::max(0.0, KDL::dot(p - a, ab) / KDL::dot(ab, ab)));
      worst = std::max(worst, (p - (a + ab * u)).Norm());
    }
    EXPECT_LT(worst, 0.001);
    const KDL::Frame end = testModel().forward(r.trajectory.sample(r.trajectory.duration()).q);
    EXPECT_LT((end.p - c.to.p).Norm(), 1e-4);
    double v = 0, acc = 0, fd = 0;
    limitRatios(r.trajectory, c.scale, v, acc, fd);
    EXPECT_LE(v, 1.0 + 1e-6);
    EXPECT_LE(acc, 1.0 + 1e-6);
    EXPECT_LE(fd, 1.0 + 1e-6);
    EXPECT_GT(r.trajectory.duration(), 0.0);
  }
}

TEST(TrajectoryPlanner, RandomTopDownLinearMoves) {
  IkSolver ik(testModel());
  TrajectoryPlanner planner(testModel(), ik, nullptr);
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> ux(0.12, 0.40), uy(-0.30, 0.30), uz(0.02, 0.25), uyaw(-1.0, 1.0);
  int planned = 0;
  for (int n = 0; n < 60; ++n) {
    const KDL::Frame from = IkSolver::topDown(ux(rng), uy(rng), uz(rng), uyaw(rng));
    const KDL::Frame to = IkSolver::topDown(ux(rng), uy(rng), uz(rng), uyaw(rng));
    const IkResult start = ik.solve(from, JointVector{});
    if (!start.ok()) {
      continue;
    }
    const PlanResult r = planner.planLinear(start.joints, to, 1.0);
    if (!r.ok()) {
      EXPECT_EQ(r.code, PlanCode::Unreachable) << r.message;
      continue;
    }
    ++planned;
    double v = 0, acc = 0, fd = 0;
    limitRatios(r.trajectory, 1.0, v, acc, fd);
    EXPECT_LE(v, 1.0 + 1e-6);
    EXPECT_LE(acc, 1.0 + 1e-6);
    double worst = 0.0;
    const KDL::Vector ab = to.p - from.p;
    for (double t = 0.0; t <= r.trajectory.duration(); t += kDt) {
      const KDL::Vector p = testModel().forward(r.trajectory.sample(t).q).p;
      const double u = std::min(1.0, std::max(0.0, KDL::dot(p - from.p, ab) / KDL::dot(ab, ab)));
      worst = std::max(worst, (p - (from.p + ab * u)).Norm());
    }
    EXPECT_LT(worst, 0.001);
  }
  EXPECT_GT(planned, 40);
}

TEST(TrajectoryPlanner, LinearMoveToAnUnreachablePointFails) {
  IkSolver ik(testModel());
  TrajectoryPlanner planner(testModel(), ik, nullptr);
  const IkResult start = ik.solve(IkSolver::topDown(0.3, 0.0, 0.15, 0.0), JointVector{});
  ASSERT_TRUE(start.ok());
  const PlanResult r = planner.planLinear(start.joints, IkSolver::topDown(1.0, 0.0, 0.15, 0.0), 1.0);
  EXPECT_EQ(r.code, PlanCode::Unreachable);
  EXPECT_NE(r.message.find("waypoint"), std::string::npos) << r.message;
}

namespace {

KDL::Frame topDown(double x, double y, double z, double yaw) {
  return KDL::Frame(KDL::Rotation::RPY(0.0, M_PI / 2, yaw), KDL::Vector(x, y, z));
}

// A sherd's way from the pickup mat to the scale: lift, carry at travel height, descend.
std::vector<ChainStep> liftCarryDescend() {
  return {{topDown(0.15, 0.25, 0.10, 0.3), true},
          {topDown(0.25, -0.25, 0.10, 0.0), false},
          {topDown(0.25, -0.25, 0.04, 0.0), true}};
}

// A sherd grasped on the pickup mat: the arm's joints there, and a planner without fixtures.
class TrajectoryChain : public ::testing::Test {
 protected:
  void SetUp() override {
    start_ = ik_.solve(topDown(0.15, 0.25, 0.02, 0.3), JointVector{});
    ASSERT_TRUE(start_.ok()) << start_.message;
  }
  IkSolver ik_{testModel()};
  TrajectoryPlanner planner_{testModel(), ik_, nullptr};
  IkResult start_;
};

}  // namespace

TEST_F(TrajectoryChain, WithoutBlendingItStopsAtEveryCorner) {
  const PlanResult r = planner_.planChain(start_.joints, liftCarryDescend(), 0.0, 1.0);
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_TRUE(r.trajectory.chained());
  double sum = 0.0;
  for (const Trajectory& m : r.trajectory.moves()) sum += m.duration();
  EXPECT_NEAR(r.trajectory.duration(), sum, 1e-9);
  // at rest at each corner, and there
  double t = 0.0;
  for (std::size_t i = 0; i + 1 < r.trajectory.moves().size(); ++i) {
    t += r.trajectory.moves()[i].duration();
    const Trajectory::Sample s = r.trajectory.sample(t);
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      EXPECT_NEAR(s.qd[j], 0.0, 1e-6);
      EXPECT_NEAR(s.q[j], r.trajectory.moves()[i].goal()[j], 1e-9);
    }
  }
}

TEST_F(TrajectoryChain, BlendedItIsFasterWithinTheLimitsAndStraightBelowTheFloor) {
  const PlanResult stop = planner_.planChain(start_.joints, liftCarryDescend(), 0.0, 1.0);
  const double floor = 0.06;
  const PlanResult r = planner_.planChain(start_.joints, liftCarryDescend(), floor, 1.0);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_LT(r.trajectory.duration(), stop.trajectory.duration() - 0.1);
  double velocity, acceleration, fd_velocity;
  limitRatios(r.trajectory, 1.0, velocity, acceleration, fd_velocity);
  EXPECT_LE(velocity, 1.0 + 1e-6);
  EXPECT_LE(acceleration, 1.0 + 1e-6);
  EXPECT_LE(fd_velocity, 1.0 + 1e-3);
  // same start and end; where the gripper is below the floor it is on a move's own path: the
  // lift and the descent straight above their points
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    EXPECT_NEAR(r.trajectory.sample(0.0).q[j], start_.joints[j], 1e-9);
    EXPECT_NEAR(r.trajectory.sample(r.trajectory.duration()).q[j], stop.trajectory.goal()[j], 1e-9);
  }
  for (double t = 0.0; t <= r.trajectory.duration(); t += 0.005) {
    const KDL::Vector p = testModel().forward(r.trajectory.sample(t).q).p;
    if (p.z() < floor - 1e-6) {
      const bool near_lift = std::hypot(p.x() - 0.15, p.y() - 0.25) < 0.001;
      const bool near_descent = std::hypot(p.x() - 0.25, p.y() + 0.25) < 0.001;
      EXPECT_TRUE(near_lift || near_descent) << "at t = " << t << " the gripper is at (" << p.x()
                                             << ", " << p.y() << ", " << p.z() << ")";
    }
  }
}

TEST_F(TrajectoryChain, ItNamesTheStepThatFails) {
  std::vector<ChainStep> steps = liftCarryDescend();
  steps[1].goal = topDown(2.0, 0.0, 0.10, 0.0);  // out of reach
  const PlanResult r = planner_.planChain(start_.joints, steps, 0.07, 1.0);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.message.find("move 2 of 3"), std::string::npos) << r.message;
}
