// A geometric joint-space path q(s), s in [0, 1]: a straight line, or a natural cubic spline
// (C2: continuous velocity and acceleration) through equally spaced knots.
#pragma once

#include <vector>

#include "rascal_control/KinematicModel.hpp"

namespace rascal_control {

class JointPath {
 public:
  JointPath() = default;
  static JointPath line(const JointVector& from, const JointVector& to);
  // Knots at s = k / (n - 1); needs at least two.
  static JointPath spline(const std::vector<JointVector>& knots);

  // q(s) and its first and second derivatives with respect to s; s is clamped to [0, 1].
  void evaluate(double s, JointVector& q, JointVector& dq, JointVector& ddq) const;
  JointVector at(double s) const;
  std::size_t segments() const { return knots_.empty() ? 0 : knots_.size() - 1; }
  const std::vector<JointVector>& knots() const { return knots_; }

 private:
  std::vector<JointVector> knots_;
  std::vector<JointVector> second_;  // d2q/ds2 at the knots
};

}  // namespace rascal_control
