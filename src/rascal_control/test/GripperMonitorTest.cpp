#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "rascal_control/GripperMonitor.hpp"

using namespace rascal_control;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The URDF's finger limits: 15 .. 37 mm from the centreline (30 .. 74 mm opening).
const rascal_workcell::GripperGeometry& gripper() {
  static const auto g = rascal_workcell::GripperGeometry::fromPackageUrdf();
  return g;
}

GripperMonitor monitor() { return GripperMonitor(gripper(), GripperMonitor::Settings{0.5, 3.0, 0.002}); }

FingerSample sample(double t, double position, double velocity = kNaN) {
  return FingerSample{t, position, velocity, 2.0 * position};
}

// Samples every 10 ms of stamps from `t0` to `t1`, the finger moving linearly `from` -> `to` (no
// velocities reported, as from a driver that sends none).
void ramp(GripperMonitor& m, double t0, double t1, double from, double to) {
  const int n = static_cast<int>(std::lround((t1 - t0) / 0.01));
  for (int i = 0; i <= n; ++i) m.addSample(sample(t0 + 0.01 * i, from + (to - from) * i / n));
}

}  // namespace

TEST(GripperMonitor, UsesTheUrdfLimits) {
  EXPECT_DOUBLE_EQ(gripper().finger_min, 0.015);
  EXPECT_DOUBLE_EQ(gripper().finger_max, 0.037);
}

TEST(GripperMonitor, TargetFromTheCommand) {
  const GripperMonitor m = monitor();
  EXPECT_DOUBLE_EQ(m.target(GripperMonitor::kOpen, 0.0).finger, 0.037);  // 0 = fully open
  EXPECT_DOUBLE_EQ(m.target(GripperMonitor::kOpen, 0.05).finger, 0.025);
  EXPECT_DOUBLE_EQ(m.target(GripperMonitor::kClose, 0.06).finger, 0.015);  // width ignored
  EXPECT_DOUBLE_EQ(m.target(GripperMonitor::kWidth, 0.074).finger, 0.037);
  EXPECT_TRUE(m.target(GripperMonitor::kWidth, 0.030).valid);
}

TEST(GripperMonitor, InvalidCommandsAndWidths) {
  const GripperMonitor m = monitor();
  auto t = m.target(GripperMonitor::kWidth, 0.1);
  EXPECT_FALSE(t.valid);
  EXPECT_EQ(t.reason, "gripper width 0.100000 m is outside [0.030, 0.074]");
  EXPECT_FALSE(m.target(GripperMonitor::kWidth, 0.0).valid);  // WIDTH 0 is not "fully open"
  EXPECT_FALSE(m.target(GripperMonitor::kOpen, 0.02).valid);
  EXPECT_FALSE(m.target(GripperMonitor::kWidth, kNaN).valid);
  t = m.target(7, 0.05);
  EXPECT_FALSE(t.valid);
  EXPECT_EQ(t.reason, "unknown gripper command 7");
}

TEST(GripperMonitor, StrokeTimeIsTheShareOfAFullStroke) {
  const GripperMonitor m = monitor();
  EXPECT_DOUBLE_EQ(m.strokeTime(0.037, 0.015), 0.5);
  EXPECT_NEAR(m.strokeTime(0.015, 0.026), 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(m.strokeTime(0.02, 0.02), 0.0);
}

TEST(GripperMonitor, DoneWhenTheFingerReachesTheTarget) {
  GripperMonitor m = monitor();
  m.addSample(sample(10.0, 0.015));
  m.start(m.target(GripperMonitor::kOpen, 0.0).finger);
  m.addSample(sample(10.1, 0.030, 0.044));
  EXPECT_FALSE(m.update(0.1, 0.1).done());
  m.addSample(sample(10.2, 0.0366, 0.01));  // within 0.5 mm
  const auto d = m.update(0.2, 0.2);
  EXPECT_EQ(d.status, GripperMonitor::Status::Done);
  EXPECT_FALSE(d.holding);
  EXPECT_EQ(d.reason, "opening 73.2 mm");
}

TEST(GripperMonitor, CloseOnNothingIsNotHolding) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.037));
  m.start(m.target(GripperMonitor::kClose, 0.0).finger);
  ramp(m, 0.01, 0.25, 0.0366, 0.026);
  EXPECT_FALSE(m.update(0.25, 0.25).done());
  EXPECT_FALSE(m.holding());  // still moving: not over
  m.addSample(sample(0.5, 0.0152, 0.0));
  const auto d = m.update(0.5, 0.5);
  EXPECT_EQ(d.status, GripperMonitor::Status::Done);
  EXPECT_FALSE(d.holding);
  EXPECT_FALSE(m.holding());
}

TEST(GripperMonitor, StallByVelocitySamplesHoldsTheSherd) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.037, 0.0));
  m.start(0.015);
  m.addSample(sample(0.01, 0.036, -0.044));
  m.addSample(sample(0.02, 0.021, 0.0));  // on the sherd (42 mm opening)
  m.addSample(sample(0.03, 0.021, 0.0));
  EXPECT_FALSE(m.update(0.03, 0.03).done());  // two samples at rest are not yet three
  m.addSample(sample(0.04, 0.021, 5e-5));
  const auto d = m.update(0.04, 0.04);
  EXPECT_EQ(d.status, GripperMonitor::Status::Done);
  EXPECT_TRUE(d.holding);
  EXPECT_EQ(d.reason, "opening 42.0 mm, holding an object");
  EXPECT_TRUE(m.holding());
}

TEST(GripperMonitor, StallByPositionWindowWithoutVelocities) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.037));
  m.start(0.015);
  ramp(m, 0.01, 0.10, 0.035, 0.0201);  // on the sherd at 0.10 s
  ramp(m, 0.11, 0.15, 0.0201, 0.0201);
  // Still for 50 ms of stamps only.
  EXPECT_FALSE(m.update(0.16, 0.16).done());
  ramp(m, 0.16, 0.21, 0.0201, 0.0201 + 0.00005);
  // Still (< 0.1 mm) over the last 0.1 s of stamps, and 0.1 s of wall time passed: stalled.
  EXPECT_FALSE(m.update(0.22, 0.09).done());  // ... but not in wall time yet
  const auto d = m.update(0.22, 0.22);
  EXPECT_EQ(d.status, GripperMonitor::Status::Done);
  EXPECT_TRUE(d.holding);
}

TEST(GripperMonitor, BeforeMovingOnlyAFullStrokeOfStillnessIsAStall) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.037, 0.0));
  m.start(0.015);
  double t = 0.01;
  for (; t < 0.555; t += 0.01) m.addSample(sample(t, 0.037, 0.0));  // the command has not arrived
  EXPECT_FALSE(m.update(0.55, 0.55).done());  // velocity 0 does not count before the finger moved
  for (; t < 0.615; t += 0.01) m.addSample(sample(t, 0.037, 0.0));
  EXPECT_FALSE(m.update(0.61, 0.5).done());  // stroke time + window in ROS time, not in wall time
  EXPECT_EQ(m.update(0.61, 0.61).status, GripperMonitor::Status::Done);
}

TEST(GripperMonitor, TheHoldingRuleIsHalfTheMarginWiderThanTheTarget) {
  // Closing and stopped with the left finger more than held_margin/2 (1 mm) beyond its target.
  for (const auto& [left, expected] : {std::pair{0.0159, false}, {0.0161, true}, {0.030, true}}) {
    GripperMonitor m = monitor();
    m.addSample(sample(0.0, 0.037, 0.0));
    m.start(0.015);
    m.addSample(sample(0.01, 0.036, -0.04));
    for (int i = 2; i <= 4; ++i) m.addSample(sample(0.01 * i, left, 0.0));
    const auto d = m.update(0.04, 0.04);
    ASSERT_EQ(d.status, GripperMonitor::Status::Done) << left;
    EXPECT_EQ(d.holding, expected) << left;
    EXPECT_EQ(m.holding(), expected) << left;
  }
}

TEST(GripperMonitor, OnlyAClosingCommandHolds) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.015, 0.0));
  m.start(m.target(GripperMonitor::kWidth, 0.06).finger);  // opening to 60 mm, blocked at 50 mm
  m.addSample(sample(0.01, 0.02, 0.04));
  for (int i = 2; i <= 4; ++i) m.addSample(sample(0.01 * i, 0.025, 0.0));
  const auto d = m.update(0.04, 0.04);
  EXPECT_EQ(d.status, GripperMonitor::Status::Done);
  EXPECT_FALSE(d.holding);
}

TEST(GripperMonitor, TheStateFollowsADrop) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.037, 0.0));
  m.start(0.015);
  m.addSample(sample(0.01, 0.03, -0.04));
  for (int i = 2; i <= 4; ++i) m.addSample(sample(0.01 * i, 0.021, 0.0));
  ASSERT_TRUE(m.update(0.04, 0.04).holding);
  m.addSample(sample(1.0, 0.021, 0.0));
  EXPECT_TRUE(m.holding());
  m.addSample(sample(1.01, 0.018, -0.04));  // the sherd slipped out: the fingers close on
  EXPECT_TRUE(m.holding());                 // (still wider than the rule's threshold)
  m.addSample(sample(1.03, 0.0155, -0.02));
  EXPECT_FALSE(m.holding());
  m.start(0.037);  // an open command: never holding
  m.addSample(sample(1.1, 0.025, 0.04));
  EXPECT_FALSE(m.holding());
}

TEST(GripperMonitor, TimeWentBackForgetsTheHistoryAndTheCommand) {
  GripperMonitor m = monitor();
  m.addSample(sample(5.0, 0.037, 0.0));
  m.start(0.015);
  m.addSample(sample(5.01, 0.03, -0.04));
  for (int i = 2; i <= 4; ++i) m.addSample(sample(5.0 + 0.01 * i, 0.021, 0.0));
  ASSERT_TRUE(m.update(0.04, 0.04).holding);
  // The simulator restarted: its clock starts again and its fingers are open.
  m.addSample(sample(0.01, 0.037, 0.0));
  EXPECT_DOUBLE_EQ(m.latest().t, 0.01);
  EXPECT_FALSE(m.holding());  // the old close no longer applies
}

TEST(GripperMonitor, WithoutACommandFingersBetweenClosedAndOpenHold) {
  // After a controller restart nothing is known of the last command: fingers at rest between
  // closed + held_margin/2 and fully open - held_margin (30 + 2 .. 74 - 4 mm opening) hold.
  for (const auto& [left, expected] :
       {std::pair{0.015, false}, {0.0159, false}, {0.0161, true}, {0.025, true}, {0.0349, true}, {0.0351, false},
        {0.037, false}}) {
    GripperMonitor m = monitor();
    m.addSample(sample(1.0, left, 0.0));
    EXPECT_EQ(m.holding(), expected) << left;
  }
  EXPECT_FALSE(monitor().holding());  // no sample at all
}

TEST(GripperMonitor, TimesOutInRosAndWallTime) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.037, 0.0));
  m.start(0.015);
  double t = 0.0, left = 0.037;
  for (int i = 0; i < 400; ++i) {  // creeping 0.2 mm per 0.1 s: never still, never there
    t += 0.01;
    left -= 0.00002;
    m.addSample(sample(t, left, -0.002));
  }
  EXPECT_FALSE(m.update(3.1, 2.9).done());
  const auto d = m.update(3.1, 3.1);
  EXPECT_EQ(d.status, GripperMonitor::Status::Timeout);
  EXPECT_FALSE(d.holding);
  EXPECT_EQ(d.reason.rfind("fingers still moving 3.1", 0), 0u) << d.reason;
}

TEST(GripperMonitor, ACancelledCommandDoesNotHold) {
  GripperMonitor m = monitor();
  m.addSample(sample(0.0, 0.037, 0.0));
  m.start(0.015);
  m.addSample(sample(0.1, 0.028, 0.0));
  m.cancel();
  EXPECT_FALSE(m.holding());
}

TEST(GripperMonitor, WithPadsWidthsAreBetweenThePadsAndTheJointsStayTheUrdfs) {
  const GripperMonitor m(gripper().withPads(0.0075), GripperMonitor::Settings{0.5, 3.0, 0.002});
  EXPECT_DOUBLE_EQ(m.target(GripperMonitor::kClose, 0.0).finger, 0.015);  // the joints' own limits
  EXPECT_DOUBLE_EQ(m.target(GripperMonitor::kOpen, 0.0).finger, 0.037);
  EXPECT_DOUBLE_EQ(m.target(GripperMonitor::kWidth, 0.021).finger, 0.018);
  EXPECT_TRUE(m.target(GripperMonitor::kWidth, 0.015).valid);  // closed on the pads
  EXPECT_FALSE(m.target(GripperMonitor::kWidth, 0.060).valid);  // past 74 - 15 mm
  GripperMonitor held = m;
  held.addSample(sample(0.0, 0.018));  // the driver's joints 36 mm apart: a 21 mm chip between
  EXPECT_NEAR(held.latest().opening, 0.021, 1e-12);
}
