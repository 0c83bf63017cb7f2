#include "rascal_control/Trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace rascal_control {

Trajectory::Trajectory(JointPath path, TimeScaling timing)
    : path_(std::move(path)), timing_(std::move(timing)), duration_(timing_.duration()) {}

Trajectory Trajectory::chain(std::vector<Trajectory> moves, std::vector<double> starts) {
  if (moves.empty() || moves.size() != starts.size() || starts.front() != 0.0) {
    throw std::invalid_argument("Trajectory::chain: one start time per move, the first at 0");
  }
  Trajectory out;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    if (moves[i].chained()) {
      throw std::invalid_argument("Trajectory::chain: a chain of chains");
    }
    if (i > 0) {
      if (!(starts[i] >= starts[i - 1])) {
        throw std::invalid_argument("Trajectory::chain: start times must not decrease");
      }
      const JointVector end = moves[i - 1].goal(), next = moves[i].start();
      for (std::size_t j = 0; j < kArmJoints; ++j) {
        if (std::fabs(end[j] - next[j]) > 1e-9) {
          throw std::invalid_argument("Trajectory::chain: a move does not start where the one before ends");
        }
      }
    }
    out.duration_ = std::max(out.duration_, starts[i] + moves[i].duration());
  }
  out.moves_ = std::move(moves);
  out.starts_ = std::move(starts);
  return out;
}

Trajectory::Sample Trajectory::sample(double t) const {
  if (!moves_.empty()) {
    // Each move adds its displacement so far; velocities and accelerations of moves under way add.
    Sample out;
    out.t = t;
    out.q = moves_.front().start();
    for (std::size_t i = 0; i < moves_.size(); ++i) {
      const Trajectory& m = moves_[i];
      const double local = std::min(std::max(t - starts_[i], 0.0), m.duration());
      const Sample s = m.sample(local);
      const JointVector from = m.start();
      const bool moving = t > starts_[i] && t < starts_[i] + m.duration();
      for (std::size_t j = 0; j < kArmJoints; ++j) {
        out.q[j] += s.q[j] - from[j];
        if (moving) {
          out.qd[j] += s.qd[j];
          out.qdd[j] += s.qdd[j];
        }
      }
    }
    return out;
  }
  Sample out;
  out.t = t;
  double s = 0.0, sd = 0.0, sdd = 0.0;
  timing_.evaluate(t, s, sd, sdd);
  JointVector dq{}, ddq{};
  path_.evaluate(s, out.q, dq, ddq);
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    out.qd[j] = dq[j] * sd;
    out.qdd[j] = dq[j] * sdd + ddq[j] * sd * sd;
  }
  return out;
}

std::vector<Trajectory::Sample> Trajectory::sampled(double dt) const {
  if (!(dt > 0.0)) {
    throw std::invalid_argument("Trajectory::sampled: dt must be positive");
  }
  std::vector<Sample> out;
  const double total = duration();
  const auto n = static_cast<std::size_t>(std::floor(total / dt));
  for (std::size_t k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) * dt;
    if (t < total - 1e-9) {
      out.push_back(sample(t));
    }
  }
  out.push_back(sample(total));
  out.back().t = total;
  return out;
}

}  // namespace rascal_control
