// s(t): how a path parameter s in [0, 1] advances in time, as pieces of constant acceleration,
// starting and ending at rest.
#pragma once

#include <vector>

namespace rascal_control {

class TimeScaling {
 public:
  struct Piece {
    double t0;   // [s] start of the piece
    double s0;   // s at t0
    double sd0;  // ds/dt at t0
    double sdd;  // d2s/dt2 during the piece
  };

  TimeScaling() = default;
  // The fastest rest-to-rest move over s in [0, 1] with |ds/dt| <= sd_max, |d2s/dt2| <= sdd_max
  // (a trapezoid, or a triangle when the top speed is never reached).
  static TimeScaling trapezoid(double sd_max, double sdd_max);
  // Constant acceleration between grid points s[k] with speeds sd[k] (sd.front() = sd.back() = 0).
  static TimeScaling fromGrid(const std::vector<double>& s, const std::vector<double>& sd);
  // No motion: duration 0.
  static TimeScaling still();

  // The same motion `factor` (>= 1) times slower: speeds / factor, accelerations / factor^2.
  TimeScaling stretched(double factor) const;

  double duration() const { return duration_; }
  void evaluate(double t, double& s, double& sd, double& sdd) const;
  const std::vector<Piece>& pieces() const { return pieces_; }

 private:
  std::vector<Piece> pieces_;
  double duration_ = 0.0;
};

}  // namespace rascal_control
