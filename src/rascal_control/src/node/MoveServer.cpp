#include "MoveServer.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

#include <trajectory_msgs/JointTrajectory.h>

#include "RosConversions.hpp"

namespace rascal_control {

namespace {

uint8_t resultCode(MoveMonitor::Status status) {
  switch (status) {
    case MoveMonitor::Status::Arrived:
      return rascal_msgs::MoveArmResult::OK;
    case MoveMonitor::Status::OffPath:
      return rascal_msgs::MoveArmResult::TRACKING_ERROR;
    default:
      return rascal_msgs::MoveArmResult::TIMEOUT;
  }
}

}  // namespace

MoveServer::MoveServer(ros::NodeHandle& root, JointStates& states, const KinematicModel& model,
                       TrajectoryPlanner& planner, std::mutex& core_mutex, const ControllerParameters& params)
    : states_(states), model_(model), planner_(planner), core_mutex_(core_mutex), params_(params) {
  command_pub_ = root.advertise<trajectory_msgs::JointTrajectory>("/arm/joint_trajectory", 1);
  server_ = std::make_unique<actionlib::SimpleActionServer<rascal_msgs::MoveArmAction>>(
      root, "/rascal/arm/move", [this](const rascal_msgs::MoveArmGoalConstPtr& goal) { execute(goal); }, false);
  server_->start();
}

void MoveServer::execute(const rascal_msgs::MoveArmGoalConstPtr& goal) {
  rascal_msgs::MoveArmResult result;
  try {
    result = run(*goal);
  } catch (const std::exception& e) {
    ROS_ERROR("/rascal/arm/move: %s", e.what());
    command_pub_.publish(stopTrajectory(ros::Time::now()));
    result.code = rascal_msgs::MoveArmResult::INVALID_GOAL;
    result.message = std::string("internal error: ") + e.what();
  }
  if (result.code == rascal_msgs::MoveArmResult::OK) {
    server_->setSucceeded(result, result.message);
  } else if (result.code == rascal_msgs::MoveArmResult::PREEMPTED) {
    server_->setPreempted(result, result.message);
  } else {
    ROS_WARN("/rascal/arm/move: %s", result.message.c_str());
    server_->setAborted(result, result.message);
  }
}

PlanResult MoveServer::plan(const rascal_msgs::MoveArmGoal& goal, const JointVector& start) {
  PlanResult failed;
  failed.code = PlanCode::InvalidGoal;
  double scale = goal.speed_scale == 0.0 ? 1.0 : goal.speed_scale;
  if (!(scale > 0.0 && scale <= 1.0)) {
    failed.message = "speed_scale " + std::to_string(goal.speed_scale) + " is outside (0, 1]";
    return failed;
  }
  scale *= params_.speed_scale;
  if (goal.motion != rascal_msgs::MoveArmGoal::MOTION_JOINT && goal.motion != rascal_msgs::MoveArmGoal::MOTION_LINEAR) {
    failed.message = "unknown motion " + std::to_string(goal.motion) + " (0 joint, 1 linear)";
    return failed;
  }
  const bool linear = goal.motion == rascal_msgs::MoveArmGoal::MOTION_LINEAR;
  JointVector target_joints{};
  std::lock_guard<std::mutex> lock(core_mutex_);
  if (!goal.then_poses.empty() && goal.target_type != rascal_msgs::MoveArmGoal::TARGET_POSE) {
    failed.message = "then_poses need a pose target (target_type TARGET_POSE)";
    return failed;
  }
  switch (goal.target_type) {
    case rascal_msgs::MoveArmGoal::TARGET_POSE: {
      const std::string& frame = goal.pose.header.frame_id;
      if (!frame.empty() && frame != "base_link" && frame != "/base_link") {
        failed.message = "pose goal in frame '" + frame + "'; only base_link is accepted";
        return failed;
      }
      KDL::Frame target_pose;
      std::string why;
      if (!poseToFrame(goal.pose.pose, target_pose, why)) {
        failed.message = "pose goal: " + why;
        return failed;
      }
      if (!goal.then_poses.empty()) {
        return planChain(goal, target_pose, linear, start, scale);
      }
      return linear ? planner_.planLinear(start, target_pose, scale)
                    : planner_.planJointToPose(start, target_pose, scale);
    }
    case rascal_msgs::MoveArmGoal::TARGET_NAMED: {
      const auto it = params_.named_poses.find(goal.named_pose);
      if (it == params_.named_poses.end()) {
        std::string known;
        for (const auto& p : params_.named_poses) known += (known.empty() ? "" : ", ") + p.first;
        failed.message = "unknown named pose '" + goal.named_pose + "' (known: " + known + ")";
        return failed;
      }
      target_joints = it->second;
      break;
    }
    case rascal_msgs::MoveArmGoal::TARGET_JOINTS:
      if (goal.joints.size() != kArmJoints) {
        failed.message = "joint goal has " + std::to_string(goal.joints.size()) + " values, expected 6";
        return failed;
      }
      target_joints = toJointVector(goal.joints);
      break;
    default:
      failed.message = "unknown target_type " + std::to_string(goal.target_type);
      return failed;
  }
  if (linear) {
    const int joint = model_.firstLimitViolation(target_joints);
    if (joint >= 0) {
      failed.message = "goal " + KinematicModel::armJointNames()[joint] + " is outside its limits";
      return failed;
    }
    return planner_.planLinear(start, model_.forward(target_joints), scale);
  }
  return planner_.planJoint(start, target_joints, scale);
}

PlanResult MoveServer::planChain(const rascal_msgs::MoveArmGoal& goal, const KDL::Frame& first, bool linear,
                                 const JointVector& start, double scale) {
  PlanResult failed;
  failed.code = PlanCode::InvalidGoal;
  if (goal.then_motions.size() != goal.then_poses.size()) {
    failed.message = "then_motions has " + std::to_string(goal.then_motions.size()) +
                     " values for " + std::to_string(goal.then_poses.size()) + " then_poses";
    return failed;
  }
  if (!std::isfinite(goal.blend_above)) {
    failed.message = "blend_above is not finite";
    return failed;
  }
  std::vector<ChainStep> steps{{first, linear}};
  for (std::size_t i = 0; i < goal.then_poses.size(); ++i) {
    const uint8_t motion = goal.then_motions[i];
    if (motion != rascal_msgs::MoveArmGoal::MOTION_JOINT && motion != rascal_msgs::MoveArmGoal::MOTION_LINEAR) {
      failed.message = "then_motions[" + std::to_string(i) + "] = " + std::to_string(motion) + " (0 joint, 1 linear)";
      return failed;
    }
    ChainStep step;
    std::string why;
    if (!poseToFrame(goal.then_poses[i], step.goal, why)) {
      failed.message = "then_poses[" + std::to_string(i) + "]: " + why;
      return failed;
    }
    step.linear = motion == rascal_msgs::MoveArmGoal::MOTION_LINEAR;
    steps.push_back(step);
  }
  return planner_.planChain(start, steps, goal.blend_above, scale);
}

int MoveServer::driverSubscribers() const { return static_cast<int>(command_pub_.getNumSubscribers()); }

rascal_msgs::MoveArmResult MoveServer::run(const rascal_msgs::MoveArmGoal& goal) {
  rascal_msgs::MoveArmResult result;
  states_.checkClock();
  const std::string restart = states_.restart();
  if (!restart.empty()) {
    result.code = rascal_msgs::MoveArmResult::DRIVER_RESTARTED;
    result.message = restartMessage(restart);
    return result;
  }
  JointVector start{};
  if (!states_.nextArm(start, params_.state_timeout)) {  // planned from where the arm is now
    result.code = rascal_msgs::MoveArmResult::TIMEOUT;
    char text[120];
    std::snprintf(text, sizeof(text), "no arm joints on /joint_states within %.1f s; is the driver running?",
                  params_.state_timeout);
    result.message = text;
    return result;
  }
  // A cancelled move may still be braking: plan from where the arm comes to rest (after
  // state_timeout from where it is; the tracking rule judges the rest).
  states_.armAtRest(start, MoveMonitor::kAtRest, params_.state_timeout);
  result.joints = toStdVector(start);
  const PlanResult planned = plan(goal, start);
  if (!planned.ok()) {
    result.code = static_cast<uint8_t>(planned.code);
    result.message = planned.message;
    return result;
  }
  const Trajectory& trajectory = planned.trajectory;
  const MoveMonitor monitor(MoveMonitor::reference(trajectory), params_.move);
  if (!driverListening(command_pub_, params_.state_timeout)) {
    result.code = rascal_msgs::MoveArmResult::TIMEOUT;
    result.message = "no driver subscribes to /arm/joint_trajectory; is it running?";
    return result;
  }
  // The restart rule once more, right before sending: a driver that has just subscribed again
  // (restarted) must not get a trajectory planned for the arm it had before.
  states_.checkSubscribers(driverSubscribers());
  states_.checkClock();
  const std::string late_restart = states_.restart();
  if (!late_restart.empty()) {
    result.code = rascal_msgs::MoveArmResult::DRIVER_RESTARTED;
    result.message = restartMessage(late_restart);
    return result;
  }
  const ros::Time t0 = ros::Time::now();
  const ros::WallTime wall0 = ros::WallTime::now();
  // Stamp 0: the driver starts the trajectory when it arrives (no catching up on a late message).
  command_pub_.publish(toJointTrajectory(trajectory, params_.command_period, ros::Time(0)));

  rascal_msgs::MoveArmFeedback feedback;
  ros::Time last_feedback;
  while (true) {
    ArmSample sample = states_.armSample(std::chrono::milliseconds(5));
    const ros::Time now = ros::Time::now();
    sample.elapsed = (now - t0).toSec();
    sample.measured -= t0.toSec();
    sample.wall = (ros::WallTime::now() - wall0).toSec();
    result.joints = toStdVector(sample.q);
    result.duration = sample.elapsed;
    if (server_->isPreemptRequested() || !ros::ok()) {
      command_pub_.publish(stopTrajectory(now));
      result.code = rascal_msgs::MoveArmResult::PREEMPTED;
      result.message = "move cancelled; arm stopped";
      return result;
    }
    states_.checkClock();
    const std::string restarted = states_.restart();
    if (!restarted.empty()) {  // before any decision: the samples may be the restarted driver's
      command_pub_.publish(stopTrajectory(now));
      result.code = rascal_msgs::MoveArmResult::DRIVER_RESTARTED;
      result.message = restartMessage(restarted);
      return result;
    }
    const MoveMonitor::Decision decision = monitor.update(sample);
    if (decision.done()) {
      if (decision.status != MoveMonitor::Status::Arrived) {
        command_pub_.publish(stopTrajectory(now));
      }
      result.code = resultCode(decision.status);
      result.message = decision.reason;
      return result;
    }
    if ((now - last_feedback).toSec() >= 0.05 || now < last_feedback || last_feedback.isZero()) {
      feedback.duration = monitor.duration();
      feedback.progress = monitor.progress(sample.elapsed);
      feedback.joints = result.joints;
      server_->publishFeedback(feedback);
      last_feedback = now;
    }
  }
}

}  // namespace rascal_control
