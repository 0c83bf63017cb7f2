// Plans joint-space and straight-line Cartesian moves of the arm as time-optimal trajectories under
// joint speed and acceleration limits, and refuses motions that would hit a fixture.
#pragma once

#include <string>

#include <kdl/frames.hpp>

#include "rascal_control/CollisionChecker.hpp"
#include "rascal_control/IkSolver.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/Trajectory.hpp"

namespace rascal_control {

// Same values as rascal_msgs/MoveArm's result codes.
enum class PlanCode { Ok = 0, Unreachable = 1, Collision = 2, InvalidGoal = 5 };

// One move of a chain (TrajectoryPlanner::planChain): to `goal` by a joint or a linear move.
struct ChainStep {
  KDL::Frame goal;
  bool linear = false;
};

struct PlanResult {
  PlanCode code = PlanCode::InvalidGoal;
  std::string message;
  Trajectory trajectory;
  bool ok() const { return code == PlanCode::Ok; }
};

class TrajectoryPlanner {
 public:
  struct Options {
    double max_acceleration = 5.0;  // [rad/s^2] every arm joint (facts/timing.md)
    double linear_step = 0.005;     // [m] Cartesian waypoint spacing of linear moves
    double angular_step = 0.05;     // [rad] orientation change between waypoints
    double max_joint_step = 0.25;   // [rad] larger jumps between waypoints = not a continuous path
    double line_tolerance = 0.0005; // [m] the planned joint path stays this close to the line
    double collision_step = 0.01;   // [rad] joint change between collision samples
  };

  // `collisions` may be null (no checking). The model, solver and checker must outlive the planner.
  TrajectoryPlanner(const KinematicModel& model, IkSolver& ik, const CollisionChecker* collisions);
  TrajectoryPlanner(const KinematicModel& model, IkSolver& ik, const CollisionChecker* collisions,
                    const Options& options);

  // Synchronised rest-to-rest move along the joint-space line: the trapezoid of the slowest joint.
  // speed_scale in (0, 1] scales the speed and acceleration limits.
  PlanResult planJoint(const JointVector& start, const JointVector& goal, double speed_scale) const;
  // Joint move to a pose: the IK solution closest to `start` whose move is collision-free (the
  // others are tried in order of distance when the closest one's move would collide).
  PlanResult planJointToPose(const JointVector& start, const KDL::Frame& goal, double speed_scale);
  // ee_gripper_link along the straight line (orientation interpolated) from FK(start) to `goal`.
  PlanResult planLinear(const JointVector& start, const KDL::Frame& goal, double speed_scale);

  // The moves to `steps` in order, each planned from where the one before ends (as
  // planJointToPose / planLinear). With `blend_above` > 0 [m] they are blended: each move starts
  // as early before the one before has stopped as it can while, over the overlap, the gripper
  // (ee_gripper_link) stays above z = blend_above in base_link, every joint within its speed and
  // acceleration limits and every link clear of the fixtures; below that height every move runs
  // as planned alone (straight descents and lifts stay straight). A step that fails fails the
  // chain, its message naming the step.
  PlanResult planChain(const JointVector& start, const std::vector<ChainStep>& steps,
                       double blend_above, double speed_scale);

  // Scales a trajectory's time so that it stays inside the limits, checked every `dt` and on
  // both sides of every piece boundary; returns the factor used (1 = unchanged).
  double enforceLimits(Trajectory& trajectory, double speed_scale, double dt = 0.0001) const;

  const Options& options() const { return options_; }

 private:
  bool validStart(const JointVector& start, double speed_scale, PlanResult& result) const;
  bool collisionFree(const JointPath& path, PlanResult& result) const;
  // Whether `second` may start `overlap` [s] before `first` ends (planChain's rules).
  bool blendable(const Trajectory& first, const Trajectory& second, double overlap,
                 double blend_above, double speed_scale) const;
  TimeScaling timeOptimal(const JointPath& path, double speed_scale) const;

  const KinematicModel& model_;
  IkSolver& ik_;
  const CollisionChecker* collisions_;
  Options options_;
};

}  // namespace rascal_control
