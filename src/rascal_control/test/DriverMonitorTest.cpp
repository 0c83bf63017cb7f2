#include <gtest/gtest.h>

#include "rascal_control/DriverMonitor.hpp"

using namespace rascal_control;

namespace {

const JointVector kSleep{0.0, -1.8, 1.55, 0.0, 0.8, 0.0};
const JointVector kOverPickup{0.9, 0.3, 0.4, 0.0, 0.9, 0.1};

DriverMonitor monitor() { return DriverMonitor(DriverMonitor::Settings{3.14159}); }

}  // namespace

TEST(DriverMonitor, ASmoothlyMovingArmIsNoRestart) {
  DriverMonitor m = monitor();
  JointVector q = kOverPickup;
  for (int k = 0; k < 200; ++k) {  // 2 s at 100 Hz, every joint at the speed limit
    for (double& v : q) v += 3.14159 * 0.01;
    m.addJointState(100.0 + 0.01 * k, q);
    m.addClock(100.0 + 0.01 * k);
  }
  m.addJointState(100.0 + 0.01 * 199, q);  // the same stamp again (two messages in one step)
  EXPECT_FALSE(m.restarted());
  EXPECT_EQ(m.reason(), "");
}

TEST(DriverMonitor, PositionsAFewMillisecondsLateAreNoJump) {
  // The emulated rig: the servos move on the emulator's own copy of /clock, which on a loaded
  // machine stands still for a while and then catches up, while the driver stamps on its copy:
  // a position is up to 30 ms older than its stamp, then none (between two messages 5 ms apart
  // that read as 0.11 rad in 5 ms).
  DriverMonitor m = monitor();
  const double lag[] = {0.030, 0.0, 0.020, 0.0, 0.025};
  for (int k = 0; k < 400; ++k) {  // 2 s at 200 Hz, the wrist at the speed limit
    const double t = 100.0 + 0.005 * k;
    JointVector q = kOverPickup;
    q[5] += 3.14159 * (t - lag[k % 5] - 100.0);
    m.addJointState(t, q);
  }
  EXPECT_FALSE(m.restarted()) << m.reason();
}

TEST(DriverMonitor, AStepInTheMiddleOfAMoveIsStillAJump) {
  DriverMonitor m = monitor();
  JointVector q = kOverPickup;
  for (int k = 0; k < 100; ++k) {
    q[0] += 1.0 * 0.005;  // 1 rad/s
    m.addJointState(10.0 + 0.005 * k, q);
  }
  ASSERT_FALSE(m.restarted());
  m.addJointState(10.5, kSleep);
  ASSERT_TRUE(m.restarted());
  EXPECT_EQ(m.reason().rfind("shoulder jumped", 0), 0u) << m.reason();
}

TEST(DriverMonitor, JointStateTimeGoingBackwardsIsARestart) {
  DriverMonitor m = monitor();
  m.addJointState(312.41, kOverPickup);
  m.addJointState(0.02, kOverPickup);
  ASSERT_TRUE(m.restarted());
  EXPECT_EQ(m.reason(), "/joint_states time went backwards (312.410 s -> 0.020 s)");
}

TEST(DriverMonitor, AJumpToTheResetPoseIsARestart) {
  // A simulator reset (/sim/reset) or a driver that came up at its sleep pose with time going on.
  DriverMonitor m = monitor();
  m.addJointState(50.00, kOverPickup);
  m.addJointState(50.01, kSleep);
  ASSERT_TRUE(m.restarted());
  EXPECT_EQ(m.reason().rfind("shoulder jumped 2.100 rad in 0.010 s on /joint_states", 0), 0u) << m.reason();
}

TEST(DriverMonitor, AFarMoveAfterALongGapIsNoJump) {
  // No messages for 2 s (a loaded machine): the arm may have moved that far.
  DriverMonitor m = monitor();
  m.addJointState(50.0, kOverPickup);
  m.addJointState(52.0, kSleep);
  EXPECT_FALSE(m.restarted());
}

TEST(DriverMonitor, RosTimeGoingBackwardsIsARestart) {
  DriverMonitor m = monitor();
  m.addClock(0.0);  // no /clock yet under use_sim_time: ignored
  m.addClock(200.0);
  m.addClock(200.0);
  EXPECT_FALSE(m.restarted());
  m.addClock(0.5);
  ASSERT_TRUE(m.restarted());
  EXPECT_EQ(m.reason(), "ROS time went backwards (200.000 s -> 0.500 s: /clock restarted)");
}

TEST(DriverMonitor, TheDriversSubscriptionComingBackIsARestart) {
  DriverMonitor m = monitor();
  m.addSubscribers(0);  // the controller started before the driver: not a restart
  m.addSubscribers(1);
  m.addSubscribers(2);  // someone echoes the topic
  m.addSubscribers(1);
  EXPECT_FALSE(m.restarted());
  m.addSubscribers(0);  // the driver is gone: goals fail on their own (no driver subscribes)
  EXPECT_FALSE(m.restarted());
  m.addSubscribers(1);
  ASSERT_TRUE(m.restarted());
  EXPECT_EQ(m.reason(), "the driver's subscription to its command topic went away and came back");
}

TEST(DriverMonitor, TheFirstSignIsTheReasonAndItHoldsUntilAcknowledged) {
  DriverMonitor m = monitor();
  m.addClock(300.0);
  m.addJointState(300.0, kOverPickup);
  m.addSubscribers(1);
  m.addSubscribers(0);
  m.addSubscribers(1);
  m.addClock(0.1);
  m.addJointState(0.1, kSleep);
  EXPECT_EQ(m.reason(), "the driver's subscription to its command topic went away and came back");
  for (int k = 0; k < 100; ++k) m.addJointState(0.1 + 0.01 * k, kSleep);  // a quiet driver again
  EXPECT_TRUE(m.restarted());
  EXPECT_TRUE(m.acknowledge());
  EXPECT_FALSE(m.restarted());
  EXPECT_EQ(m.reason(), "");
  EXPECT_FALSE(m.acknowledge());  // nothing left to acknowledge
}

TEST(DriverMonitor, AfterAnAcknowledgeTheNextSamplesAreTheBaseline) {
  DriverMonitor m = monitor();
  m.addClock(300.0);
  m.addJointState(300.0, kOverPickup);
  m.addClock(0.2);
  ASSERT_TRUE(m.restarted());
  m.acknowledge();
  m.addClock(0.3);  // earlier than 300 s, but after the acknowledge
  m.addJointState(0.3, kSleep);  // far from the pose before the restart
  m.addJointState(0.31, kSleep);
  EXPECT_FALSE(m.restarted());
  m.addJointState(0.2, kSleep);
  EXPECT_TRUE(m.restarted());  // and the rules hold again
}
