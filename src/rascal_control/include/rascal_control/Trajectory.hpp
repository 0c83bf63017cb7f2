// A timed joint trajectory: a geometric path q(s) followed with a time scaling s(t); or a chain
// of such moves, each starting where the one before ends, the next one started before the one
// before has stopped (a blended corner: over the overlap their joint motions add up).
#pragma once

#include <vector>

#include "rascal_control/JointPath.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/TimeScaling.hpp"

namespace rascal_control {

class Trajectory {
 public:
  struct Sample {
    double t = 0.0;    // [s] from the start
    JointVector q{};   // [rad]
    JointVector qd{};  // [rad/s]
    JointVector qdd{}; // [rad/s^2]
  };

  Trajectory() = default;
  Trajectory(JointPath path, TimeScaling timing);
  // `moves[i]` starts at `starts[i]` [s] (starts[0] = 0, non-decreasing); each move must start
  // where the one before ends. Throws std::invalid_argument otherwise.
  static Trajectory chain(std::vector<Trajectory> moves, std::vector<double> starts);

  double duration() const { return duration_; }
  Sample sample(double t) const;
  // Samples every `dt` from 0, plus the end point.
  std::vector<Sample> sampled(double dt) const;
  // The path and timing of a single move (of a chain: its first move's).
  const JointPath& path() const { return moves_.empty() ? path_ : moves_.front().path_; }
  const TimeScaling& timing() const { return moves_.empty() ? timing_ : moves_.front().timing_; }
  bool chained() const { return !moves_.empty(); }
  const std::vector<Trajectory>& moves() const { return moves_; }
  const std::vector<double>& starts() const { return starts_; }
  JointVector start() const { return moves_.empty() ? path_.at(0.0) : moves_.front().start(); }
  JointVector goal() const { return moves_.empty() ? path_.at(1.0) : moves_.back().goal(); }

 private:
  JointPath path_;
  TimeScaling timing_;
  double duration_ = 0.0;
  std::vector<Trajectory> moves_;  // a chain: its moves and their start times
  std::vector<double> starts_;
};

}  // namespace rascal_control
