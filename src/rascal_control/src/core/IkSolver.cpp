#include "rascal_control/IkSolver.hpp"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <limits>

namespace rascal_control {

namespace {

constexpr double kAnalyticCheck = 1e-6;   // [m], [rad] the closed form must be this exact
constexpr int kNumericIterations = 150;
constexpr int kRandomSeeds = 12;
constexpr unsigned kRandomSeed = 20240611u;

bool finiteFrame(const KDL::Frame& f) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(f.p(i))) {
      return false;
    }
    for (int j = 0; j < 3; ++j) {
      if (!std::isfinite(f.M(i, j))) {
        return false;
      }
    }
  }
  return true;
}

bool orthonormal(const KDL::Rotation& r) {
  const KDL::Rotation e = r * r.Inverse();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (std::fabs(e(i, j) - (i == j ? 1.0 : 0.0)) > 1e-6) {
        return false;
      }
    }
  }
  return std::fabs(r(0, 0) * (r(1, 1) * r(2, 2) - r(1, 2) * r(2, 1)) -
                   r(0, 1) * (r(1, 0) * r(2, 2) - r(1, 2) * r(2, 0)) +
                   r(0, 2) * (r(1, 0) * r(2, 1) - r(1, 1) * r(2, 0)) - 1.0) < 1e-6;
}

}  // namespace

IkSolver::IkSolver(const KinematicModel& model) : model_(model), rng_(kRandomSeed) {
  AnalyticIk::Geometry geometry;
  if (AnalyticIk::extract(model_.chain(), geometry, analytic_why_)) {
    analytic_ = std::make_unique<AnalyticIk>(geometry);
  }
  Eigen::Matrix<double, 6, 1> weights;
  weights << 1.0, 1.0, 1.0, 0.1, 0.1, 0.1;
  lma_ = std::make_unique<KDL::ChainIkSolverPos_LMA>(model_.chain(), weights, 1e-12,
                                                     kNumericIterations, 1e-14);
}

KDL::Frame IkSolver::topDown(double x, double y, double z, double yaw) {
  return KDL::Frame(KDL::Rotation::RotZ(yaw) * KDL::Rotation::RotY(M_PI / 2.0), KDL::Vector(x, y, z));
}

void IkSolver::frameError(const KDL::Frame& a, const KDL::Frame& b, double& position, double& angle) {
  position = (a.p - b.p).Norm();
  KDL::Vector axis;
  angle = (a.M.Inverse() * b.M).GetRotAngle(axis);
}

bool IkSolver::accurate(const KDL::Frame& target, const JointVector& q) const {
  double position = 0.0, angle = 0.0;
  frameError(target, model_.forward(q), position, angle);
  return position <= kPositionTolerance && angle <= kOrientationTolerance;
}

double IkSolver::distance(const JointVector& a, const JointVector& b) const {
  double sum = 0.0;
  for (std::size_t i = 0; i < kArmJoints; ++i) {
    sum += (a[i] - b[i]) * (a[i] - b[i]);
  }
  return sum;
}

bool IkSolver::intoLimits(JointVector& q, const JointVector& seed) const {
  const auto& limits = model_.limits();
  bool ok = true;
  for (std::size_t i = 0; i < kArmJoints; ++i) {
    double best = std::numeric_limits<double>::quiet_NaN();
    const double base = std::remainder(q[i], 2.0 * M_PI);
    for (int k = -2; k <= 2; ++k) {
      const double v = base + 2.0 * M_PI * k;
      if (v >= limits[i].lower && v <= limits[i].upper &&
          (std::isnan(best) || std::fabs(v - seed[i]) < std::fabs(best - seed[i]))) {
        best = v;
      }
    }
    if (std::isnan(best)) {
      ok = false;
    } else {
      q[i] = best;
    }
  }
  return ok;
}

std::string IkSolver::describe(const KDL::Frame& target) const {
  double roll = 0.0, pitch = 0.0, yaw = 0.0;
  target.M.GetRPY(roll, pitch, yaw);
  char text[160];
  std::snprintf(text, sizeof(text), "pose (%.3f, %.3f, %.3f) m rpy (%.3f, %.3f, %.3f) rad",
                target.p.x(), target.p.y(), target.p.z(), roll, pitch, yaw);
  return text;
}

IkResult IkSolver::solve(const KDL::Frame& target, const JointVector& seed, Method method) {
  IkResult result;
  if (!finiteFrame(target) || !orthonormal(target.M)) {
    result.code = IkCode::Invalid;
    result.message = "IK target is not a finite rigid transform";
    return result;
  }
  for (double s : seed) {
    if (!std::isfinite(s)) {
      result.code = IkCode::Invalid;
      result.message = "IK seed is not finite";
      return result;
    }
  }
  if (method == Method::Analytic && !analytic_) {
    result.code = IkCode::Invalid;
    result.message = "closed-form IK is not available for this URDF: " + analytic_why_;
    return result;
  }
  if (method != Method::Numeric && analytic_) {
    bool verified = true;
    result = solveAnalytic(target, seed, verified);
    if (verified || method == Method::Analytic) {
      return result;
    }
  }
  return solveNumeric(target, seed);
}

std::vector<JointVector> IkSolver::solveAll(const KDL::Frame& target, const JointVector& seed) {
  const IkResult best = solve(target, seed);
  if (!best.ok()) {
    return {};
  }
  std::vector<std::pair<double, JointVector>> found{{distance(best.joints, seed), best.joints}};
  std::vector<JointVector> solutions;
  double reach_error = 0.0;
  if (analytic_ && analytic_->solveAll(target, seed, solutions, reach_error)) {
    for (JointVector q : solutions) {
      if (!intoLimits(q, seed) || !accurate(target, q)) {
        continue;
      }
      bool known = false;
      for (const auto& f : found) {
        known = known || distance(f.second, q) < 1e-12;
      }
      if (!known) {
        found.emplace_back(distance(q, seed), q);
      }
    }
  }
  std::stable_sort(found.begin(), found.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<JointVector> out;
  for (const auto& f : found) {
    out.push_back(f.second);
  }
  return out;
}

IkResult IkSolver::solveAnalytic(const KDL::Frame& target, const JointVector& seed, bool& verified) {
  IkResult result;
  verified = true;
  std::vector<JointVector> solutions;
  double reach_error = 0.0;
  if (!analytic_->solveAll(target, seed, solutions, reach_error)) {
    char text[96];
    std::snprintf(text, sizeof(text), " is out of reach (wrist centre %.3f m beyond the workspace)",
                  reach_error);
    result.code = IkCode::Unreachable;
    result.message = describe(target) + text;
    return result;
  }
  double best = std::numeric_limits<double>::infinity();
  JointVector closest_violation{};
  double closest_violation_distance = std::numeric_limits<double>::infinity();
  for (JointVector q : solutions) {
    double position = 0.0, angle = 0.0;
    frameError(target, model_.forward(q), position, angle);
    if (position > kAnalyticCheck || angle > kAnalyticCheck) {
      verified = false;
      continue;
    }
    JointVector wrapped = q;
    if (!intoLimits(wrapped, seed)) {
      const double d = distance(q, seed);
      if (d < closest_violation_distance) {
        closest_violation_distance = d;
        closest_violation = q;
      }
      continue;
    }
    const double d = distance(wrapped, seed);
    if (d < best) {
      best = d;
      result.joints = wrapped;
    }
  }
  if (std::isfinite(best)) {
    result.code = IkCode::Ok;
    result.message = "ok";
    return result;
  }
  if (!verified) {
    result.code = IkCode::Singular;
    result.message = describe(target) + ": closed-form solution failed its check";
    return result;
  }
  const int joint = model_.firstLimitViolation(closest_violation);
  const auto& limit = model_.limits()[joint < 0 ? 0 : joint];
  char text[160];
  std::snprintf(text, sizeof(text), " is reachable only beyond joint limits (%s %.3f rad outside [%.3f, %.3f])",
                KinematicModel::armJointNames()[joint < 0 ? 0 : joint].c_str(),
                closest_violation[joint < 0 ? 0 : joint], limit.lower, limit.upper);
  result.code = IkCode::JointLimit;
  result.message = describe(target) + text;
  return result;
}

IkResult IkSolver::solveNumeric(const KDL::Frame& target, const JointVector& seed) {
  const auto& limits = model_.limits();
  rng_.seed(kRandomSeed);
  std::vector<JointVector> starts;
  JointVector clamped = seed;
  for (std::size_t i = 0; i < kArmJoints; ++i) {
    clamped[i] = std::min(limits[i].upper, std::max(limits[i].lower, seed[i]));
  }
  starts.push_back(clamped);
  // Interbotix's seeds: zeros, then the waist at -120 and +120 degrees.
  starts.push_back(JointVector{});
  starts.push_back(JointVector{-2.0 * M_PI / 3.0, 0, 0, 0, 0, 0});
  starts.push_back(JointVector{2.0 * M_PI / 3.0, 0, 0, 0, 0, 0});
  const double toward = std::atan2(target.p.y(), target.p.x());
  starts.push_back(JointVector{toward, 0, 0, 0, 0, 0});
  starts.push_back(JointVector{toward, 0.3, 0.3, 0, 1.0, 0});
  for (int k = 0; k < kRandomSeeds; ++k) {
    JointVector q{};
    for (std::size_t i = 0; i < kArmJoints; ++i) {
      std::uniform_real_distribution<double> u(limits[i].lower, limits[i].upper);
      q[i] = u(rng_);
    }
    starts.push_back(q);
  }

  IkResult result;
  double best = std::numeric_limits<double>::infinity();
  bool converged_outside = false;
  JointVector outside{};
  int found = 0;
  KDL::JntArray init(kArmJoints), out(kArmJoints);
  for (std::size_t s = 0; s < starts.size(); ++s) {
    for (std::size_t i = 0; i < kArmJoints; ++i) {
      init(i) = starts[s][i];
    }
    lma_->CartToJnt(init, target, out);
    JointVector q{};
    for (std::size_t i = 0; i < kArmJoints; ++i) {
      q[i] = out(i);
    }
    if (!accurate(target, q)) {
      continue;
    }
    JointVector wrapped = q;
    if (!intoLimits(wrapped, seed)) {
      converged_outside = true;
      outside = q;
      continue;
    }
    const double d = distance(wrapped, seed);
    if (d < best) {
      best = d;
      result.joints = wrapped;
    }
    ++found;
    if (s == 0 || found >= 2) {
      break;  // the seed's own basin, or the closer of two solutions
    }
  }
  if (std::isfinite(best)) {
    result.code = IkCode::Ok;
    result.message = "ok";
    return result;
  }
  if (analytic_) {
    const KDL::Vector w = target.p - target.M * (analytic_->geometry().tip_home.M.Inverse() *
                                                 (analytic_->geometry().tip_home.p -
                                                  analytic_->geometry().wrist));
    const KDL::Vector& shoulder = analytic_->geometry().shoulder;
    const double rho = std::hypot(w.x(), w.y());
    const double front = std::hypot(rho - shoulder.x(), w.z() - shoulder.z());
    const double back = std::hypot(-rho - shoulder.x(), w.z() - shoulder.z());
    if (std::min(front, back) > analytic_->maxReach() + 1e-9 ||
        std::max(front, back) < analytic_->minReach() - 1e-9) {
      result.code = IkCode::Unreachable;
      result.message = describe(target) + " is out of reach";
      return result;
    }
  }
  if (converged_outside) {
    const int joint = model_.firstLimitViolation(outside);
    result.code = IkCode::JointLimit;
    result.message = describe(target) + " is reachable only beyond the limit of " +
                     KinematicModel::armJointNames()[joint < 0 ? 0 : joint];
    return result;
  }
  result.code = IkCode::Singular;
  result.message = describe(target) + ": numeric IK did not converge (near a singularity or out of reach)";
  return result;
}

}  // namespace rascal_control
