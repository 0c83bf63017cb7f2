#include "rascal_control/TrajectoryPlanner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace rascal_control {

namespace {

constexpr double kStartTolerance = 0.05;   // [rad] a measured start may sit this far past a limit
constexpr double kVelocityMargin = 0.995;  // planning margins; enforceLimits() checks the truth
constexpr double kAccelerationMargin = 0.98;
constexpr int kGridPerSegment = 8;
constexpr int kMinGrid = 64;
constexpr int kMaxRefinements = 3;
constexpr double kBlendStep = 0.002;  // [s] blended overlaps are checked this often (< 0.01 rad a step)
// Overlaps tried at a corner, as fractions of the shorter move; the first that passes is taken.
constexpr double kBlendFractions[] = {1.0,  0.95, 0.9,  0.85, 0.8,  0.75, 0.7,  0.65, 0.6, 0.55,
                                     0.5,  0.45, 0.4,  0.35, 0.3,  0.25, 0.2,  0.15, 0.1, 0.05};
// Straight moves of a blended chain are planned at this fraction of the limits: the joints the
// move next to them also drives keep some acceleration for it (TrajectoryPlannerTest's lift,
// carry and descent blended above 0.05 m: at 1.0 the descent cannot start before the carry has
// stopped, their accelerations adding past a joint's limit; at 0.9 it starts 0.3 s before).
constexpr double kBlendedLinearScale = 0.9;

std::string vectorText(const KDL::Vector& v) {
  char text[64];
  std::snprintf(text, sizeof(text), "(%.3f, %.3f, %.3f)", v.x(), v.y(), v.z());
  return text;
}

// Distance from p to the segment a-b.
double distanceToSegment(const KDL::Vector& p, const KDL::Vector& a, const KDL::Vector& b) {
  const KDL::Vector ab = b - a;
  const double len2 = KDL::dot(ab, ab);
  double t = len2 > 0.0 ? KDL::dot(p - a, ab) / len2 : 0.0;
  t = std::min(1.0, std::max(0.0, t));
  return (p - (a + ab * t)).Norm();
}

}  // namespace

TrajectoryPlanner::TrajectoryPlanner(const KinematicModel& model, IkSolver& ik,
                                     const CollisionChecker* collisions)
    : TrajectoryPlanner(model, ik, collisions, Options()) {}

TrajectoryPlanner::TrajectoryPlanner(const KinematicModel& model, IkSolver& ik,
                                     const CollisionChecker* collisions, const Options& options)
    : model_(model), ik_(ik), collisions_(collisions), options_(options) {}

bool TrajectoryPlanner::validStart(const JointVector& start, double speed_scale,
                                   PlanResult& result) const {
  if (!(speed_scale > 0.0 && speed_scale <= 1.0)) {
    result.code = PlanCode::InvalidGoal;
    result.message = "speed scale " + std::to_string(speed_scale) + " is outside (0, 1]";
    return false;
  }
  for (double q : start) {
    if (!std::isfinite(q)) {
      result.code = PlanCode::InvalidGoal;
      result.message = "start joint vector is not finite";
      return false;
    }
  }
  const int joint = model_.firstLimitViolation(start, kStartTolerance);
  if (joint >= 0) {
    result.code = PlanCode::InvalidGoal;
    result.message = "start position of " + KinematicModel::armJointNames()[joint] + " (" +
                     std::to_string(start[joint]) + " rad) is outside its limits";
    return false;
  }
  return true;
}

bool TrajectoryPlanner::collisionFree(const JointPath& path, PlanResult& result) const {
  if (collisions_ == nullptr) {
    return true;
  }
  const auto hit = collisions_->check(path, options_.collision_step);
  if (!hit) {
    return true;
  }
  const KDL::Frame tip = model_.forward(hit->q);
  char text[64];
  std::snprintf(text, sizeof(text), " at %.0f %% of the path", hit->s * 100.0);
  result.code = PlanCode::Collision;
  result.message = hit->link + " would hit the " + hit->fixture + text + " (gripper at " +
                   vectorText(tip.p) + ")";
  return false;
}

PlanResult TrajectoryPlanner::planJoint(const JointVector& start, const JointVector& goal,
                                        double speed_scale) const {
  PlanResult result;
  if (!validStart(start, speed_scale, result)) {
    return result;
  }
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    if (!std::isfinite(goal[j]) || goal[j] < model_.limits()[j].lower ||
        goal[j] > model_.limits()[j].upper) {
      result.code = PlanCode::InvalidGoal;
      char text[128];
      std::snprintf(text, sizeof(text), "goal %s = %.4f rad is outside its limits [%.4f, %.4f]",
                    KinematicModel::armJointNames()[j].c_str(), goal[j], model_.limits()[j].lower,
                    model_.limits()[j].upper);
      result.message = text;
      return result;
    }
  }
  // Rest-to-rest along the joint-space line: s(t) is the trapezoid whose speed and acceleration,
  // multiplied by each joint's distance, meet the tightest joint's limits.
  double sd_max = std::numeric_limits<double>::infinity();
  double sdd_max = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    const double d = std::fabs(goal[j] - start[j]);
    if (d > 1e-12) {
      sd_max = std::min(sd_max, model_.limits()[j].velocity * speed_scale / d);
      sdd_max = std::min(sdd_max, options_.max_acceleration * speed_scale / d);
    }
  }
  JointPath path = JointPath::line(start, goal);
  if (!std::isfinite(sd_max)) {
    result.code = PlanCode::Ok;
    result.message = "already there";
    result.trajectory = Trajectory(path, TimeScaling::still());
    return result;
  }
  if (!collisionFree(path, result)) {
    return result;
  }
  result.code = PlanCode::Ok;
  result.message = "ok";
  result.trajectory = Trajectory(path, TimeScaling::trapezoid(sd_max, sdd_max));
  return result;
}

PlanResult TrajectoryPlanner::planJointToPose(const JointVector& start, const KDL::Frame& goal,
                                              double speed_scale) {
  PlanResult result;
  if (!validStart(start, speed_scale, result)) {
    return result;
  }
  const IkResult ik = ik_.solve(goal, start);
  if (!ik.ok()) {
    result.code = ik.code == IkCode::Invalid ? PlanCode::InvalidGoal : PlanCode::Unreachable;
    result.message = ik.message;
    return result;
  }
  PlanResult first;
  bool have_first = false;
  for (const JointVector& q : ik_.solveAll(goal, start)) {
    PlanResult r = planJoint(start, q, speed_scale);
    if (r.code != PlanCode::Collision) {
      return r;
    }
    if (!have_first) {
      first = r;
      have_first = true;
    }
  }
  return have_first ? first : planJoint(start, ik.joints, speed_scale);
}

PlanResult TrajectoryPlanner::planLinear(const JointVector& start, const KDL::Frame& goal,
                                         double speed_scale) {
  PlanResult result;
  if (!validStart(start, speed_scale, result)) {
    return result;
  }
  const KDL::Frame from = model_.forward(start);
  const double length = (goal.p - from.p).Norm();
  KDL::Vector axis;
  const double angle = (from.M.Inverse() * goal.M).GetRotAngle(axis);
  int n = std::max({1, static_cast<int>(std::ceil(length / options_.linear_step)),
                    static_cast<int>(std::ceil(angle / options_.angular_step))});

  for (int refinement = 0; refinement <= kMaxRefinements; ++refinement, n *= 2) {
    std::vector<JointVector> knots{start};
    for (int k = 1; k <= n; ++k) {
      const double s = static_cast<double>(k) / n;
      const KDL::Frame waypoint(from.M * KDL::Rotation::Rot2(axis, angle * s),
                                from.p + (goal.p - from.p) * s);
      const IkResult ik = ik_.solve(waypoint, knots.back());
      if (!ik.ok()) {
        result.code = ik.code == IkCode::Invalid ? PlanCode::InvalidGoal : PlanCode::Unreachable;
        result.message = "linear move: waypoint " + std::to_string(k) + "/" + std::to_string(n) +
                         " fails: " + ik.message;
        return result;
      }
      for (std::size_t j = 0; j < kArmJoints; ++j) {
        if (std::fabs(ik.joints[j] - knots.back()[j]) > options_.max_joint_step) {
          result.code = PlanCode::Unreachable;
          result.message = "linear move: the line from " + vectorText(from.p) + " to " +
                           vectorText(goal.p) + " needs a jump of " +
                           KinematicModel::armJointNames()[j] + " near " +
                           vectorText(waypoint.p) + " (passes a singularity or a joint limit)";
          return result;
        }
      }
      knots.push_back(ik.joints);
    }
    JointPath path = JointPath::spline(knots);
    // Between the waypoints the spline must stay on the line.
    double worst = 0.0;
    for (int k = 0; k < n; ++k) {
      const double s = (static_cast<double>(k) + 0.5) / n;
      worst = std::max(worst, distanceToSegment(model_.forward(path.at(s)).p, from.p, goal.p));
    }
    if (worst > options_.line_tolerance && refinement < kMaxRefinements) {
      continue;
    }
    if (!collisionFree(path, result)) {
      return result;
    }
    result.trajectory = Trajectory(path, timeOptimal(path, speed_scale));
    enforceLimits(result.trajectory, speed_scale);
    result.code = PlanCode::Ok;
    result.message = "ok";
    return result;
  }
  result.code = PlanCode::Unreachable;
  result.message = "linear move: no joint path stays on the line";
  return result;
}

PlanResult TrajectoryPlanner::planChain(const JointVector& start, const std::vector<ChainStep>& steps,
                                        double blend_above, double speed_scale) {
  PlanResult result;
  if (steps.empty()) {
    result.code = PlanCode::InvalidGoal;
    result.message = "a chain of no moves";
    return result;
  }
  std::vector<Trajectory> moves;
  std::vector<double> starts;
  JointVector from = start;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const double linear_scale = blend_above > 0.0 ? speed_scale * kBlendedLinearScale : speed_scale;
    PlanResult step = steps[i].linear ? planLinear(from, steps[i].goal, linear_scale)
                                      : planJointToPose(from, steps[i].goal, speed_scale);
    if (!step.ok()) {
      step.message = "move " + std::to_string(i + 1) + " of " + std::to_string(steps.size()) +
                     " (to " + vectorText(steps[i].goal.p) + "): " + step.message;
      return step;
    }
    from = step.trajectory.goal();
    if (moves.empty()) {
      starts.push_back(0.0);
    } else {
      const Trajectory& before = moves.back();
      // never three moves at once: this one starts after the one before the last has ended
      const double earliest =
          moves.size() >= 2 ? starts[starts.size() - 2] + moves[moves.size() - 2].duration() : 0.0;
      const double end = starts.back() + before.duration();
      double overlap = 0.0;
      if (blend_above > 0.0) {
        const double longest =
            std::min({before.duration(), step.trajectory.duration(), end - earliest});
        for (double fraction : kBlendFractions) {
          if (longest * fraction > kBlendStep &&
              blendable(before, step.trajectory, longest * fraction, blend_above, speed_scale)) {
            overlap = longest * fraction;
            break;
          }
        }
      }
      starts.push_back(end - overlap);
    }
    moves.push_back(step.trajectory);
  }
  result.code = PlanCode::Ok;
  result.message = "ok";
  result.trajectory = moves.size() == 1 ? moves.front() : Trajectory::chain(moves, starts);
  return result;
}

bool TrajectoryPlanner::blendable(const Trajectory& first, const Trajectory& second, double overlap,
                                  double blend_above, double speed_scale) const {
  const double begin = first.duration() - overlap;
  const Trajectory both = Trajectory::chain({first, second}, {0.0, begin});
  std::vector<JointVector> samples;
  for (double t = begin; t <= first.duration() + 1e-12; t += kBlendStep) {
    const Trajectory::Sample s = both.sample(t);
    if (model_.forward(s.q).p.z() < blend_above) {
      return false;
    }
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      // each move alone keeps within the limits (a joint move's slowest joint at them)
      if (std::fabs(s.qd[j]) > model_.limits()[j].velocity * speed_scale * (1.0 + 1e-9) ||
          std::fabs(s.qdd[j]) > options_.max_acceleration * speed_scale * (1.0 + 1e-9)) {
        return false;
      }
    }
    samples.push_back(s.q);
  }
  if (collisions_ != nullptr) {
    for (const JointVector& q : samples) {
      if (collisions_->check(q)) {
        return false;
      }
    }
  }
  return true;
}

TimeScaling TrajectoryPlanner::timeOptimal(const JointPath& path, double speed_scale) const {
  const int m = std::max(kMinGrid, static_cast<int>(path.segments()) * kGridPerSegment);
  const double ds = 1.0 / m;
  std::vector<JointVector> dq(m + 1), ddq(m + 1);
  JointVector v{}, a{};
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    v[j] = model_.limits()[j].velocity * speed_scale * kVelocityMargin;
    a[j] = options_.max_acceleration * speed_scale * kAccelerationMargin;
  }
  std::vector<double> grid(m + 1), x_max(m + 1);
  for (int k = 0; k <= m; ++k) {
    grid[k] = static_cast<double>(k) * ds;
    JointVector q{};
    path.evaluate(grid[k], q, dq[k], ddq[k]);
  }
  // Acceleration bounds u = d2s/dt2 at grid point k for x = (ds/dt)^2: |dq u + ddq x| <= a.
  auto bounds = [&](int k, double x, double& lo, double& hi) {
    lo = -std::numeric_limits<double>::infinity();
    hi = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      const double d = dq[k][j], dd = ddq[k][j];
      if (std::fabs(d) < 1e-12) {
        if (std::fabs(dd) * x > a[j]) {
          lo = 1.0;
          hi = -1.0;
          return;
        }
        continue;
      }
      const double u1 = (-a[j] - dd * x) / d, u2 = (a[j] - dd * x) / d;
      lo = std::max(lo, std::min(u1, u2));
      hi = std::min(hi, std::max(u1, u2));
    }
  };
  for (int k = 0; k <= m; ++k) {
    double x_vel = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      if (std::fabs(dq[k][j]) > 1e-12) {
        x_vel = std::min(x_vel, std::pow(v[j] / std::fabs(dq[k][j]), 2));
      }
    }
    if (!std::isfinite(x_vel)) {
      x_vel = 1e6;
    }
    double lo = 0.0, hi = 0.0;
    bounds(k, x_vel, lo, hi);
    if (lo <= hi) {
      x_max[k] = x_vel;
      continue;
    }
    double good = 0.0, bad = x_vel;  // the feasible set of x is an interval [0, x*]
    for (int it = 0; it < 50; ++it) {
      const double mid = 0.5 * (good + bad);
      bounds(k, mid, lo, hi);
      (lo <= hi ? good : bad) = mid;
    }
    x_max[k] = good;
  }
  std::vector<double> x(m + 1, 0.0);
  for (int k = 0; k < m; ++k) {  // forward: accelerate as hard as allowed
    double lo = 0.0, hi = 0.0;
    bounds(k, x[k], lo, hi);
    x[k + 1] = std::min(x_max[k + 1], std::max(0.0, x[k] + 2.0 * ds * std::max(0.0, hi)));
  }
  x[m] = 0.0;
  for (int k = m; k > 0; --k) {  // backward: brake in time
    double lo = 0.0, hi = 0.0;
    bounds(k, x[k], lo, hi);
    x[k - 1] = std::min(x[k - 1], x[k] + 2.0 * ds * std::max(0.0, -lo));
  }
  x[0] = 0.0;
  std::vector<double> sd(m + 1);
  for (int k = 0; k <= m; ++k) {
    sd[k] = (k == 0 || k == m) ? 0.0 : std::max(1e-6, std::sqrt(std::max(0.0, x[k])));
  }
  return TimeScaling::fromGrid(grid, sd);
}

double TrajectoryPlanner::enforceLimits(Trajectory& trajectory, double speed_scale, double dt) const {
  double total_factor = 1.0;
  for (int pass = 0; pass < 3; ++pass) {
    double ratio_v = 0.0, ratio_a = 0.0;
    auto check = [&](double t) {
      const Trajectory::Sample sample = trajectory.sample(t);
      for (std::size_t j = 0; j < kArmJoints; ++j) {
        ratio_v = std::max(ratio_v, std::fabs(sample.qd[j]) / (model_.limits()[j].velocity * speed_scale));
        ratio_a = std::max(ratio_a, std::fabs(sample.qdd[j]) / (options_.max_acceleration * speed_scale));
      }
    };
    const double total = trajectory.duration();
    const auto steps = static_cast<long>(std::ceil(total / dt));
    for (long k = 0; k <= steps; ++k) {
      check(std::min(total, static_cast<double>(k) * dt));
    }
    for (const TimeScaling::Piece& piece : trajectory.timing().pieces()) {
      check(std::max(0.0, piece.t0 - 1e-9));
      check(std::min(total, piece.t0 + 1e-9));
    }
    const double factor = std::max({1.0, ratio_v, std::sqrt(ratio_a)});
    if (factor <= 1.0) {
      break;
    }
    trajectory = Trajectory(trajectory.path(), trajectory.timing().stretched(factor * 1.0005));
    total_factor *= factor * 1.0005;
  }
  return total_factor;
}

}  // namespace rascal_control
