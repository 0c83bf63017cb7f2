#include "rascal_control/TimeScaling.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rascal_control {

TimeScaling TimeScaling::still() {
  TimeScaling scaling;
  scaling.pieces_.push_back({0.0, 1.0, 0.0, 0.0});
  return scaling;
}

TimeScaling TimeScaling::trapezoid(double sd_max, double sdd_max) {
  if (!(sd_max > 0.0) || !(sdd_max > 0.0) || !std::isfinite(sd_max) || !std::isfinite(sdd_max)) {
    throw std::invalid_argument("TimeScaling::trapezoid: limits must be finite and positive");
  }
  TimeScaling scaling;
  if (sd_max * sd_max / sdd_max >= 1.0) {
    // Triangle: accelerate to the middle, then brake.
    const double ta = std::sqrt(1.0 / sdd_max);
    scaling.pieces_.push_back({0.0, 0.0, 0.0, sdd_max});
    scaling.pieces_.push_back({ta, 0.5, sdd_max * ta, -sdd_max});
    scaling.duration_ = 2.0 * ta;
  } else {
    const double ta = sd_max / sdd_max;
    const double sa = 0.5 * sd_max * ta;
    const double tc = (1.0 - 2.0 * sa) / sd_max;
    scaling.pieces_.push_back({0.0, 0.0, 0.0, sdd_max});
    scaling.pieces_.push_back({ta, sa, sd_max, 0.0});
    scaling.pieces_.push_back({ta + tc, 1.0 - sa, sd_max, -sdd_max});
    scaling.duration_ = 2.0 * ta + tc;
  }
  return scaling;
}

TimeScaling TimeScaling::fromGrid(const std::vector<double>& s, const std::vector<double>& sd) {
  if (s.size() < 2 || s.size() != sd.size()) {
    throw std::invalid_argument("TimeScaling::fromGrid: needs matching grids of at least two points");
  }
  TimeScaling scaling;
  double t = 0.0;
  for (std::size_t k = 0; k + 1 < s.size(); ++k) {
    const double ds = s[k + 1] - s[k];
    const double v0 = std::max(0.0, sd[k]), v1 = std::max(0.0, sd[k + 1]);
    if (!(ds > 0.0) || !(v0 + v1 > 0.0)) {
      throw std::invalid_argument("TimeScaling::fromGrid: grid must increase and never stop inside");
    }
    const double dt = 2.0 * ds / (v0 + v1);
    scaling.pieces_.push_back({t, s[k], v0, (v1 - v0) / dt});
    t += dt;
  }
  scaling.duration_ = t;
  return scaling;
}

TimeScaling TimeScaling::stretched(double factor) const {
  if (!(factor >= 1.0)) {
    throw std::invalid_argument("TimeScaling::stretched: factor must be >= 1");
  }
  TimeScaling scaling;
  for (const Piece& p : pieces_) {
    scaling.pieces_.push_back({p.t0 * factor, p.s0, p.sd0 / factor, p.sdd / (factor * factor)});
  }
  scaling.duration_ = duration_ * factor;
  return scaling;
}

void TimeScaling::evaluate(double t, double& s, double& sd, double& sdd) const {
  if (pieces_.empty()) {
    throw std::logic_error("TimeScaling::evaluate: empty time scaling");
  }
  if (t >= duration_) {
    s = 1.0;
    sd = 0.0;
    sdd = 0.0;
    return;
  }
  if (t <= 0.0) {
    s = pieces_.front().s0;
    sd = 0.0;
    sdd = pieces_.front().sdd;
    return;
  }
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), t,
                             [](double time, const Piece& p) { return time < p.t0; });
  const Piece& p = *(it - 1);
  const double tau = t - p.t0;
  s = std::min(1.0, p.s0 + p.sd0 * tau + 0.5 * p.sdd * tau * tau);
  sd = std::max(0.0, p.sd0 + p.sdd * tau);
  sdd = p.sdd;
}

}  // namespace rascal_control
