#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "TestModel.hpp"
#include "rascal_control/MoveMonitor.hpp"
#include "rascal_control/TrajectoryPlanner.hpp"

using namespace rascal_control;

namespace {

const JointVector kStart{0.2, -0.2, 0.3, 0.0, 0.8, -0.1};
const JointVector kGoal{0.5, -0.2, 0.3, 0.0, 0.8, -0.1};

// A straight joint-space path from kStart to kGoal over 1.5 s, a point every 5 ms.
std::vector<PathPoint> line(const JointVector& from = kStart, const JointVector& to = kGoal, double duration = 1.5) {
  std::vector<PathPoint> path;
  const int n = static_cast<int>(std::round(duration / MoveMonitor::kReferenceStep));
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    PathPoint p;
    p.t = s * duration;
    for (std::size_t j = 0; j < kArmJoints; ++j) p.q[j] = from[j] + s * (to[j] - from[j]);
    path.push_back(p);
  }
  return path;
}

MoveMonitor monitor() { return MoveMonitor(line(), MoveMonitor::Settings{0.002, 2.0, 0.1}); }

// At `q` (default the goal) and at rest, `elapsed` ROS seconds and `wall` wall seconds after the
// trajectory was sent.
ArmSample at(double elapsed, double wall, const JointVector& q = kGoal) {
  ArmSample s;
  s.elapsed = elapsed;
  s.measured = elapsed;
  s.wall = wall;
  s.state_age = 0.01;
  s.q = q;
  return s;
}

// The point `share` of the way along the line, plus `offset` on joint `joint`.
JointVector along(double share, std::size_t joint = 0, double offset = 0.0) {
  JointVector q{};
  for (std::size_t j = 0; j < kArmJoints; ++j) q[j] = kStart[j] + share * (kGoal[j] - kStart[j]);
  q[joint] += offset;
  return q;
}

}  // namespace

TEST(MoveMonitor, ArrivesOnlyAfterThePlannedDuration) {
  const MoveMonitor m = monitor();
  EXPECT_EQ(m.update(at(1.49, 1.49)).status, MoveMonitor::Status::Moving);
  const auto d = m.update(at(1.5, 1.5));
  EXPECT_EQ(d.status, MoveMonitor::Status::Arrived);
  EXPECT_EQ(d.reason, "arrived");
  EXPECT_DOUBLE_EQ(m.duration(), 1.5);
  EXPECT_EQ(m.goal(), kGoal);
}

TEST(MoveMonitor, OnlyASampleMeasuredAfterThePlannedEndArrives) {
  const MoveMonitor m = monitor();
  ArmSample s = at(1.6, 1.6);
  s.measured = 1.49;  // still the driver's message from before the end, late in the queue
  EXPECT_EQ(m.update(s).status, MoveMonitor::Status::Moving);
  // A zero-length move (already at the goal): not on the strength of a message from before it
  // was sent (a restarted driver's last one, say), only on one measured after.
  const MoveMonitor still({PathPoint{0.0, kGoal}}, MoveMonitor::Settings{});
  s = at(0.3, 0.01);
  s.measured = -0.02;
  EXPECT_EQ(still.update(s).status, MoveMonitor::Status::Moving);
  s.measured = 0.0;
  EXPECT_EQ(still.update(s).status, MoveMonitor::Status::Arrived);
}

TEST(MoveMonitor, EveryJointWithinTheGoalTolerance) {
  const MoveMonitor m = monitor();
  JointVector q = kGoal;
  q[4] += 0.0019;
  EXPECT_EQ(m.update(at(2.0, 2.0, q)).status, MoveMonitor::Status::Arrived);
  q[4] = kGoal[4] - 0.0021;
  EXPECT_EQ(m.update(at(2.0, 2.0, q)).status, MoveMonitor::Status::Moving);
}

TEST(MoveMonitor, EveryJointAtRest) {
  const MoveMonitor m = monitor();
  ArmSample s = at(2.0, 2.0);
  s.velocity[2] = 0.03;  // still settling
  EXPECT_EQ(m.update(s).status, MoveMonitor::Status::Moving);
  s.velocity[2] = -0.019;
  EXPECT_EQ(m.update(s).status, MoveMonitor::Status::Arrived);
  s.velocity[2] = std::numeric_limits<double>::quiet_NaN();  // a driver reporting garbage
  EXPECT_EQ(m.update(s).status, MoveMonitor::Status::Moving);
}

TEST(MoveMonitor, TimesOutAfterTheSettleTimeoutInRosAndWallTime) {
  const MoveMonitor m = monitor();
  JointVector q = kGoal;
  q[1] += 0.05;
  // Late in ROS time only (a simulator far faster than real time): not yet.
  EXPECT_EQ(m.update(at(3.6, 0.5, q)).status, MoveMonitor::Status::Moving);
  // Late in wall time only: not yet.
  EXPECT_EQ(m.update(at(3.4, 3.4, q)).status, MoveMonitor::Status::Moving);
  const auto d = m.update(at(3.6, 2.1, q));
  EXPECT_EQ(d.status, MoveMonitor::Status::Timeout);
  EXPECT_EQ(d.reason, "timeout: arm not at the goal 3.6 s after the planned 1.50 s (shoulder off by 0.0500 rad)");
}

TEST(MoveMonitor, DriverSilentAfterTwoSecondsWithoutJointStates) {
  const MoveMonitor m = monitor();
  ArmSample s = at(0.4, 2.5, along(0.2));
  s.state_age = 1.9;
  EXPECT_EQ(m.update(s).status, MoveMonitor::Status::Moving);
  s.state_age = 2.1;
  const auto d = m.update(s);
  EXPECT_EQ(d.status, MoveMonitor::Status::DriverSilent);
  EXPECT_EQ(d.reason.rfind("driver silent: ", 0), 0u) << d.reason;
  EXPECT_NE(d.reason.find("waist off by 0.2400 rad"), std::string::npos) << d.reason;
}

TEST(MoveMonitor, ArrivalWinsOverSilence) {
  ArmSample s = at(2.0, 5.0);
  s.state_age = 3.0;  // the last message had the arm at the goal and at rest
  EXPECT_EQ(monitor().update(s).status, MoveMonitor::Status::Arrived);
}

TEST(MoveMonitor, Progress) {
  const MoveMonitor m = monitor();
  EXPECT_DOUBLE_EQ(m.progress(0.75), 0.5);
  EXPECT_DOUBLE_EQ(m.progress(3.0), 1.0);
  EXPECT_DOUBLE_EQ(MoveMonitor({PathPoint{0.0, kGoal}}, {}).progress(0.0), 1.0);
}

// --- tracking: the arm must stay near the planned path and keep up with it

TEST(MoveMonitor, AnArmFollowingThePathLateIsStillMoving) {
  const MoveMonitor m = monitor();
  // 0.3 s behind the reference (servo lag plus message latency), on the path.
  EXPECT_EQ(m.update(at(0.9, 0.9, along(0.4))).status, MoveMonitor::Status::Moving);
  // Slightly beside the path, within the tracking tolerance.
  EXPECT_EQ(m.update(at(0.9, 0.9, along(0.5, 1, 0.09))).status, MoveMonitor::Status::Moving);
}

TEST(MoveMonitor, AnArmOffThePathIsStoppedAtOnce) {
  const MoveMonitor m = monitor();
  const auto d = m.update(at(0.6, 0.6, along(0.4, 2, 0.15)));  // elbow pushed 0.15 rad aside
  EXPECT_EQ(d.status, MoveMonitor::Status::OffPath);
  EXPECT_EQ(d.reason.rfind("off its path: elbow 0.150 rad from the planned path", 0), 0u) << d.reason;
}

TEST(MoveMonitor, AnArmAtAnotherPoseIsOffThePathEvenAtTheEnd) {
  // A restarted driver reporting its reset pose: never "arrived", whatever the time says.
  const MoveMonitor m = monitor();
  const JointVector sleep{0.0, -1.8, 1.55, 0.0, 0.8, 0.0};
  EXPECT_EQ(m.update(at(0.0, 0.0, sleep)).status, MoveMonitor::Status::OffPath);
  EXPECT_EQ(m.update(at(5.0, 5.0, sleep)).status, MoveMonitor::Status::OffPath);
}

TEST(MoveMonitor, AnArmThatDoesNotStartTimesOutBeforeTheEndOfALongMove) {
  const MoveMonitor m(line(kStart, kGoal, 6.0), MoveMonitor::Settings{0.002, 2.0, 0.1});
  EXPECT_EQ(m.update(at(1.9, 1.9, kStart)).status, MoveMonitor::Status::Moving);
  EXPECT_EQ(m.update(at(2.1, 0.5, kStart)).status, MoveMonitor::Status::Moving);  // wall time not yet
  const auto d = m.update(at(2.1, 2.1, kStart));
  EXPECT_EQ(d.status, MoveMonitor::Status::Timeout);
  EXPECT_EQ(d.reason.rfind("timeout: arm 2.1 s behind its trajectory (at 0 % of the path", 0), 0u) << d.reason;
}

TEST(MoveMonitor, AnArmThatStallsHalfWayTimesOut) {
  const MoveMonitor m(line(kStart, kGoal, 6.0), MoveMonitor::Settings{0.002, 2.0, 0.1});
  EXPECT_EQ(m.update(at(4.9, 4.9, along(0.5))).status, MoveMonitor::Status::Moving);
  const auto d = m.update(at(5.1, 5.1, along(0.5)));
  EXPECT_EQ(d.status, MoveMonitor::Status::Timeout);
  EXPECT_NE(d.reason.find("at 50 % of the path"), std::string::npos) << d.reason;
}

TEST(MoveMonitor, ReferenceOfAPlannedTrajectory) {
  const KinematicModel& model = testModel();
  IkSolver ik(model);
  TrajectoryPlanner planner(model, ik, nullptr);
  const PlanResult plan = planner.planJoint(kStart, kGoal, 1.0);
  ASSERT_TRUE(plan.ok()) << plan.message;
  const std::vector<PathPoint> path = MoveMonitor::reference(plan.trajectory);
  ASSERT_GE(path.size(), 3u);
  EXPECT_DOUBLE_EQ(path.front().t, 0.0);
  EXPECT_DOUBLE_EQ(path.back().t, plan.trajectory.duration());
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    EXPECT_NEAR(path.front().q[j], kStart[j], 1e-9);
    EXPECT_NEAR(path.back().q[j], kGoal[j], 1e-9);
  }
  for (std::size_t k = 1; k < path.size(); ++k) {
    EXPECT_LE(path[k].t - path[k - 1].t, MoveMonitor::kReferenceStep + 1e-9);
  }
  // Following the planned trajectory exactly is never off the path nor behind it.
  const MoveMonitor m(path, MoveMonitor::Settings{});
  for (double t = 0.0; t < plan.trajectory.duration(); t += 0.013) {
    EXPECT_EQ(m.update(at(t, t, plan.trajectory.sample(t).q)).status, MoveMonitor::Status::Moving) << t;
  }
}
