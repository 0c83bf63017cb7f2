#include <gtest/gtest.h>

#include <cmath>

#include "rascal_sim/ServoModel.hpp"

using namespace rascal_sim;

TEST(ServoModel, TrajectoryFasterThanLimitsIsFollowedNoFasterThanLimits) {
  ServoModel servo(JointVector{0, 0, 0, 0, 0, 0});
  // ask for 2 rad on every joint in 0.1 s (20 rad/s): far beyond pi rad/s and 5 rad/s^2
  TrajectoryPoint p;
  p.positions = {2.0, 1.5, -1.5, 2.0, 1.5, -2.0};
  p.time_from_start = 0.1;
  servo.setTrajectory(0.0, 0.0, {p}, {true, true, true, true, true, true});
  const double dt = 0.001;
  JointVector v_prev = servo.velocities();
  double vmax = 0, amax = 0, arrived = -1;
  for (int i = 0; i < 6000; ++i) {
    servo.step(i * dt, dt);
    for (int j = 0; j < kArmJoints; ++j) {
      vmax = std::max(vmax, std::abs(servo.velocities()[j]));
      amax = std::max(amax, std::abs(servo.velocities()[j] - v_prev[j]) / dt);
    }
    v_prev = servo.velocities();
    if (arrived < 0 && servo.settled()) arrived = (i + 1) * dt;
  }
  EXPECT_LE(vmax, ArmKinematics::kMaxVelocity + 1e-9);
  EXPECT_LE(amax, ArmKinematics::kMaxAcceleration + 1e-6);
  // 2 rad at pi rad/s and 5 rad/s^2: trapezoid of 2/pi + pi/5 = 1.27 s at the very least
  ASSERT_GT(arrived, 0);
  EXPECT_GE(arrived, 2.0 / M_PI + M_PI / 5.0);
  EXPECT_NEAR(servo.positions()[0], 2.0, 0.01);
}

TEST(ServoModel, EmptyTrajectoryStopsWithinTheAccelerationLimit) {
  ServoModel servo(JointVector{0, 0, 0, 0, 0, 0});
  TrajectoryPoint p;
  p.positions = {3.0, 0, 0, 0, 0, 0};
  p.time_from_start = 2.0;
  servo.setTrajectory(0.0, 0.0, {p}, {true, true, true, true, true, true});
  double t = 0;
  for (; t < 0.5; t += 0.001) servo.step(t, 0.001);
  const double v0 = servo.velocities()[0];
  EXPECT_GT(v0, 0.5);
  servo.setTrajectory(t, t, {}, {true, true, true, true, true, true});
  double prev = v0;
  for (int i = 0; i < 2000; ++i, t += 0.001) {
    servo.step(t, 0.001);
    EXPECT_LE(std::abs(servo.velocities()[0] - prev), 5.0 * 0.001 + 1e-9);
    prev = servo.velocities()[0];
  }
  EXPECT_LT(std::abs(servo.velocities()[0]), 1e-3);
}

TEST(ServoModel, StaysInsideJointLimits) {
  ServoModel servo(JointVector{0, 0, 0, 0, 0, 0});
  TrajectoryPoint p;
  p.positions = {0, 3.0, 0, 0, 0, 0};  // shoulder upper limit is 1.99 rad
  p.time_from_start = 1.0;
  servo.setTrajectory(0.0, 0.0, {p}, {true, true, true, true, true, true});
  for (int i = 0; i < 3000; ++i) servo.step(i * 0.001, 0.001);
  EXPECT_LE(servo.positions()[1], ArmKinematics::upperLimits()[1] + 1e-12);
  EXPECT_NEAR(servo.positions()[1], ArmKinematics::upperLimits()[1], 0.01);
}

TEST(ServoModel, FeasibleTrajectoryIsTrackedClosely) {
  ServoModel servo(JointVector{0, 0, 0, 0, 0, 0});
  // a triangular profile at the acceleration limit: 1 rad in 2 * sqrt(1 / 5) s, points every 10 ms
  const double a = 5.0, th = std::sqrt(1.0 / a), total = 2 * th;
  std::vector<TrajectoryPoint> points;
  for (double t = 0.0; t <= total + 1e-9; t += 0.01) {
    TrajectoryPoint p;
    const double s = t <= th ? 0.5 * a * t * t : 1.0 - 0.5 * a * (total - t) * (total - t);
    const double v = t <= th ? a * t : a * (total - t);
    p.positions = {s, 0, 0, 0, 0, 0};
    p.velocities = {v, 0, 0, 0, 0, 0};
    p.has_velocities = true;
    p.time_from_start = t;
    points.push_back(p);
  }
  servo.setTrajectory(0.0, 0.2, points, {true, true, true, true, true, true});
  double worst = 0.0, t = 0.0;
  for (; t < 0.2 + total; t += 0.001) {
    servo.step(t, 0.001);
    const double tau = std::min(total, std::max(0.0, t + 0.001 - 0.2));
    const double ref = tau <= th ? 0.5 * a * tau * tau : 1.0 - 0.5 * a * (total - tau) * (total - tau);
    worst = std::max(worst, std::abs(servo.positions()[0] - ref));
  }
  EXPECT_LT(worst, 0.02);
  for (int i = 0; i < 500; ++i, t += 0.001) servo.step(t, 0.001);
  EXPECT_TRUE(servo.settled());
}
