#include "rascal_control/JointPath.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rascal_control {

JointPath JointPath::line(const JointVector& from, const JointVector& to) {
  JointPath path;
  path.knots_ = {from, to};
  path.second_ = {JointVector{}, JointVector{}};
  return path;
}

JointPath JointPath::spline(const std::vector<JointVector>& knots) {
  if (knots.size() < 2) {
    throw std::invalid_argument("JointPath::spline: needs at least two knots");
  }
  JointPath path;
  path.knots_ = knots;
  const std::size_t n = knots.size();
  path.second_.assign(n, JointVector{});
  if (n == 2) {
    return path;
  }
  // Natural spline on a uniform grid: M[k-1] + 4 M[k] + M[k+1] = 6 (q[k-1] - 2 q[k] + q[k+1]) / h^2.
  const double h = 1.0 / static_cast<double>(n - 1);
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    std::vector<double> c(n, 0.0), d(n, 0.0);
    for (std::size_t k = 1; k + 1 < n; ++k) {
      const double rhs = 6.0 * (knots[k - 1][j] - 2.0 * knots[k][j] + knots[k + 1][j]) / (h * h);
      const double denom = 4.0 - (k > 1 ? c[k - 1] : 0.0);
      c[k] = 1.0 / denom;
      d[k] = (rhs - (k > 1 ? d[k - 1] : 0.0)) / denom;
    }
    for (std::size_t k = n - 2; k >= 1; --k) {
      path.second_[k][j] = d[k] - c[k] * path.second_[k + 1][j];
    }
  }
  return path;
}

void JointPath::evaluate(double s, JointVector& q, JointVector& dq, JointVector& ddq) const {
  if (knots_.size() < 2) {
    throw std::logic_error("JointPath::evaluate: empty path");
  }
  const std::size_t n = knots_.size() - 1;
  s = std::min(1.0, std::max(0.0, s));
  const double h = 1.0 / static_cast<double>(n);
  const std::size_t k = std::min(n - 1, static_cast<std::size_t>(s / h));
  const double a = (static_cast<double>(k + 1) * h - s) / h;  // weight of knot k
  const double b = 1.0 - a;                                   // weight of knot k + 1
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    const double q0 = knots_[k][j], q1 = knots_[k + 1][j];
    const double m0 = second_[k][j], m1 = second_[k + 1][j];
    q[j] = a * q0 + b * q1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
    dq[j] = (q1 - q0) / h - (3.0 * a * a - 1.0) * h / 6.0 * m0 + (3.0 * b * b - 1.0) * h / 6.0 * m1;
    ddq[j] = a * m0 + b * m1;
  }
}

JointVector JointPath::at(double s) const {
  JointVector q{}, dq{}, ddq{};
  evaluate(s, q, dq, ddq);
  return q;
}

}  // namespace rascal_control
