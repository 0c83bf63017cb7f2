#include "rascal_control/Trajectory.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace rascal_control {

Trajectory::Trajectory(JointPath path, TimeScaling timing)
    : path_(std::move(path)), timing_(std::move(timing)) {}

Trajectory::Sample Trajectory::sample(double t) const {
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
