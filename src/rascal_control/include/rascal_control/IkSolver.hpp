// Inverse kinematics of ee_gripper_link: closed form (AnalyticIk) where the URDF allows it, else
// KDL's Levenberg-Marquardt solver from several seeds. Respects joint limits, returns the solution
// closest to a seed, and says why when there is none.
#pragma once

#include <memory>
#include <random>
#include <string>
#include <vector>

#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/frames.hpp>

#include "rascal_control/AnalyticIk.hpp"
#include "rascal_control/KinematicModel.hpp"

namespace rascal_control {

// Same values as rascal_msgs/ComputeIK's codes.
enum class IkCode { Ok = 0, Unreachable = 1, JointLimit = 2, Singular = 3, Invalid = 4 };

struct IkResult {
  IkCode code = IkCode::Invalid;
  std::string message;
  JointVector joints{};
  bool ok() const { return code == IkCode::Ok; }
};

class IkSolver {
 public:
  enum class Method { Auto, Analytic, Numeric };

  static constexpr double kPositionTolerance = 1e-4;     // [m] a solution must reach this close
  static constexpr double kOrientationTolerance = 1e-3;  // [rad]

  explicit IkSolver(const KinematicModel& model);

  // Not thread-safe (KDL's solver keeps state): one IkSolver per thread, or a lock around it.
  IkResult solve(const KDL::Frame& target, const JointVector& seed, Method method = Method::Auto);

  const KinematicModel& model() const { return model_; }
  // Every solution inside the limits, closest to `seed` first (the closed form's up to 8; with
  // KDL only, just solve()'s answer). Empty when solve() fails.
  std::vector<JointVector> solveAll(const KDL::Frame& target, const JointVector& seed);

  bool analyticAvailable() const { return static_cast<bool>(analytic_); }
  // Why the closed form is not used (empty when it is).
  const std::string& analyticUnavailableReason() const { return analytic_why_; }

  // ee_gripper_link pointing straight down (its +x along -z) at (x, y, z), turned by `yaw` about z.
  static KDL::Frame topDown(double x, double y, double z, double yaw);
  // Position [m] and angle [rad] between two frames.
  static void frameError(const KDL::Frame& a, const KDL::Frame& b, double& position, double& angle);

 private:
  IkResult solveAnalytic(const KDL::Frame& target, const JointVector& seed, bool& verified);
  IkResult solveNumeric(const KDL::Frame& target, const JointVector& seed);
  // Moves each angle by +-2 pi into its limits where that helps; false if some joint stays out.
  bool intoLimits(JointVector& q, const JointVector& seed) const;
  double distance(const JointVector& a, const JointVector& b) const;
  bool accurate(const KDL::Frame& target, const JointVector& q) const;
  std::string describe(const KDL::Frame& target) const;

  const KinematicModel& model_;
  std::unique_ptr<AnalyticIk> analytic_;
  std::string analytic_why_;
  std::unique_ptr<KDL::ChainIkSolverPos_LMA> lma_;
  std::mt19937 rng_;
};

}  // namespace rascal_control
