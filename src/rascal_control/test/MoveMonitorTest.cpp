#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "rascal_control/MoveMonitor.hpp"

using namespace rascal_control;

namespace {

const JointVector kGoal{0.5, -0.2, 0.3, 0.0, 0.8, -0.1};

MoveMonitor monitor() { return MoveMonitor(kGoal, 1.5, MoveMonitor::Settings{0.002, 2.0}); }

// At the goal and at rest, `elapsed` ROS seconds and `wall` wall seconds after the trajectory was sent.
ArmSample at(double elapsed, double wall, const JointVector& q = kGoal) {
  ArmSample s;
  s.elapsed = elapsed;
  s.wall = wall;
  s.state_age = 0.01;
  s.q = q;
  return s;
}

}  // namespace

TEST(MoveMonitor, ArrivesOnlyAfterThePlannedDuration) {
  const MoveMonitor m = monitor();
  EXPECT_EQ(m.update(at(1.49, 1.49)).status, MoveMonitor::Status::Moving);
  const auto d = m.update(at(1.5, 1.5));
  EXPECT_EQ(d.status, MoveMonitor::Status::Arrived);
  EXPECT_EQ(d.reason, "arrived");
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
  JointVector q = kGoal;
  q[0] -= 0.3;
  ArmSample s = at(0.4, 2.5, q);
  s.state_age = 1.9;
  EXPECT_EQ(m.update(s).status, MoveMonitor::Status::Moving);
  s.state_age = 2.1;
  const auto d = m.update(s);
  EXPECT_EQ(d.status, MoveMonitor::Status::DriverSilent);
  EXPECT_EQ(d.reason.rfind("driver silent: ", 0), 0u) << d.reason;
  EXPECT_NE(d.reason.find("waist off by 0.3000 rad"), std::string::npos) << d.reason;
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
  EXPECT_DOUBLE_EQ(MoveMonitor(kGoal, 0.0, {}).progress(0.0), 1.0);
}
