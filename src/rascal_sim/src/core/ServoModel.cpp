#include "rascal_sim/ServoModel.hpp"

#include <algorithm>
#include <cmath>

namespace rascal_sim {

namespace {
constexpr double kGain = 25.0;  // [1/s] position loop of the servo
}

ServoModel::ServoModel(const JointVector& initial) { reset(initial); }

void ServoModel::reset(const JointVector& q) {
  q_ = q;
  v_.fill(0.0);
  points_.clear();
  TrajectoryPoint hold;
  hold.positions = q;
  points_.push_back(hold);
  start_time_ = 0.0;
}

void ServoModel::setTrajectory(double now, double start_time, const std::vector<TrajectoryPoint>& points,
                               const std::array<bool, kArmJoints>& mask) {
  if (points.empty()) {
    stop(now);
    return;
  }
  JointVector q_ref, v_ref;
  reference(now, q_ref, v_ref);
  std::vector<TrajectoryPoint> next;
  TrajectoryPoint first;
  first.positions = q_ref;
  first.time_from_start = 0.0;
  next.push_back(first);
  // a trajectory that arrives late is played from now with its own timing (not skipped ahead)
  const double start = std::max(start_time, now);
  for (const auto& p : points) {
    TrajectoryPoint c = p;
    for (int j = 0; j < kArmJoints; ++j) {
      if (!mask[j]) {
        c.positions[j] = q_ref[j];
        c.velocities[j] = 0.0;
      }
    }
    c.time_from_start = std::max(0.0, p.time_from_start);
    if (c.time_from_start <= next.back().time_from_start) {
      // a point at (or before) the start replaces the start
      if (next.size() == 1) c.time_from_start = 0.0;
      else c.time_from_start = next.back().time_from_start + 1e-6;
    }
    if (c.time_from_start == 0.0 && next.size() == 1) next[0] = c;
    else next.push_back(c);
  }
  points_ = next;
  start_time_ = start;
}

void ServoModel::stop(double /*now*/) {
  // hold where the joints can stop at the acceleration limit
  TrajectoryPoint hold;
  for (int j = 0; j < kArmJoints; ++j) {
    const double v = v_[j];
    hold.positions[j] = q_[j] + v * std::abs(v) / (2 * ArmKinematics::kMaxAcceleration);
  }
  points_.assign(1, hold);
  start_time_ = 0.0;
}

void ServoModel::reference(double t, JointVector& q_ref, JointVector& v_ref) const {
  const double tau = t - start_time_;
  v_ref.fill(0.0);
  if (points_.size() == 1 || tau <= 0.0) {
    q_ref = points_.front().positions;
    if (tau > 0.0 || points_.size() == 1) return;
    return;
  }
  if (tau >= points_.back().time_from_start) {
    q_ref = points_.back().positions;
    return;
  }
  size_t k = 1;
  while (k < points_.size() && points_[k].time_from_start < tau) ++k;
  const TrajectoryPoint& a = points_[k - 1];
  const TrajectoryPoint& b = points_[k];
  const double h = b.time_from_start - a.time_from_start;
  const double s = h > 0 ? (tau - a.time_from_start) / h : 1.0;
  for (int j = 0; j < kArmJoints; ++j) {
    if (a.has_velocities && b.has_velocities && h > 0) {
      // cubic Hermite between the two points
      const double p0 = a.positions[j], p1 = b.positions[j];
      const double m0 = a.velocities[j] * h, m1 = b.velocities[j] * h;
      const double s2 = s * s, s3 = s2 * s;
      q_ref[j] = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1;
      v_ref[j] = ((6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * p1 + (3 * s2 - 2 * s) * m1) / h;
    } else {
      q_ref[j] = a.positions[j] + s * (b.positions[j] - a.positions[j]);
      v_ref[j] = h > 0 ? (b.positions[j] - a.positions[j]) / h : 0.0;
    }
  }
}

void ServoModel::step(double now, double dt) {
  JointVector q_ref, v_ref;
  reference(now + dt, q_ref, v_ref);
  const double vmax = ArmKinematics::kMaxVelocity, amax = ArmKinematics::kMaxAcceleration;
  const auto& lo = ArmKinematics::lowerLimits();
  const auto& hi = ArmKinematics::upperLimits();
  for (int j = 0; j < kArmJoints; ++j) {
    const double target = std::min(hi[j], std::max(lo[j], q_ref[j]));
    const double err = target - q_[j];
    // feed-forward plus a position loop that can still brake in time at the acceleration limit
    const double correction = std::copysign(std::min(kGain * std::abs(err), std::sqrt(2 * amax * std::abs(err))), err);
    double v_des = v_ref[j] + correction;
    v_des = std::min(vmax, std::max(-vmax, v_des));
    const double dv = std::min(amax * dt, std::max(-amax * dt, v_des - v_[j]));
    v_[j] += dv;
    q_[j] += v_[j] * dt;
    if (q_[j] < lo[j] || q_[j] > hi[j]) {
      q_[j] = std::min(hi[j], std::max(lo[j], q_[j]));
      v_[j] = 0.0;  // the servo's position limit stops it
    }
  }
}

double ServoModel::maxSpeed() const {
  double m = 0.0;
  for (double v : v_) m = std::max(m, std::abs(v));
  return m;
}

bool ServoModel::settled(double tolerance) const {
  const JointVector& goal = points_.back().positions;
  for (int j = 0; j < kArmJoints; ++j) {
    if (std::abs(goal[j] - q_[j]) > tolerance || std::abs(v_[j]) > 1e-3) return false;
  }
  return true;
}

}  // namespace rascal_sim
