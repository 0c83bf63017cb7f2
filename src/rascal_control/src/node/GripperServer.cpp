#include "GripperServer.hpp"

#include <chrono>

#include <rascal_msgs/GripperState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include "RosConversions.hpp"

namespace rascal_control {

static_assert(GripperMonitor::kOpen == rascal_msgs::GripperGoal::OPEN &&
                  GripperMonitor::kClose == rascal_msgs::GripperGoal::CLOSE &&
                  GripperMonitor::kWidth == rascal_msgs::GripperGoal::WIDTH,
              "GripperMonitor's command codes are rascal_msgs/Gripper's");

GripperServer::GripperServer(ros::NodeHandle& root, JointStates& states,
                             const rascal_workcell::GripperGeometry& gripper, const GripperMonitor::Settings& settings,
                             double state_timeout)
    : states_(states), state_timeout_(state_timeout), monitor_(gripper, settings) {
  command_pub_ = root.advertise<trajectory_msgs::JointTrajectory>("/gripper/command", 1);
  state_pub_ = root.advertise<rascal_msgs::GripperState>("/rascal/gripper/state", 1);
  server_ = std::make_unique<actionlib::SimpleActionServer<rascal_msgs::GripperAction>>(
      root, "/rascal/gripper", [this](const rascal_msgs::GripperGoalConstPtr& goal) { execute(goal); }, false);
  server_->start();
}

void GripperServer::onFinger(const FingerSample& sample) {
  rascal_msgs::GripperState state;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    monitor_.addSample(sample);
    state.holding = monitor_.holding();
  }
  sampled_.notify_all();
  state.header.stamp.fromSec(sample.t);
  state.width = sample.opening;
  state_pub_.publish(state);
}

void GripperServer::execute(const rascal_msgs::GripperGoalConstPtr& goal) {
  rascal_msgs::GripperResult result;
  try {
    result = run(*goal);
  } catch (const std::exception& e) {
    ROS_ERROR("/rascal/gripper: %s", e.what());
    result.code = rascal_msgs::GripperResult::INVALID_GOAL;
    result.message = std::string("internal error: ") + e.what();
  }
  if (result.code == rascal_msgs::GripperResult::OK) {
    server_->setSucceeded(result, result.message);
  } else if (result.code == rascal_msgs::GripperResult::PREEMPTED) {
    server_->setPreempted(result, result.message);
  } else {
    ROS_WARN("/rascal/gripper: %s", result.message.c_str());
    server_->setAborted(result, result.message);
  }
}

void GripperServer::command(double finger, double seconds) {
  command_pub_.publish(fingerCommand(finger, seconds, ros::Time::now()));
}

rascal_msgs::GripperResult GripperServer::run(const rascal_msgs::GripperGoal& goal) {
  rascal_msgs::GripperResult result;
  GripperMonitor::Target target;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    target = monitor_.target(goal.command, goal.width);
  }
  if (!target.valid) {
    result.code = rascal_msgs::GripperResult::INVALID_GOAL;
    result.message = target.reason;
    return result;
  }
  states_.checkClock();
  const std::string restart = states_.restart();
  if (!restart.empty()) {
    result.code = rascal_msgs::GripperResult::DRIVER_RESTARTED;
    result.message = restartMessage(restart);
    return result;
  }
  const std::optional<double> left = states_.waitForFinger(state_timeout_) ? states_.leftFinger() : std::nullopt;
  if (!left) {
    result.code = rascal_msgs::GripperResult::TIMEOUT;
    result.message = "no left_finger on /joint_states within " + std::to_string(state_timeout_) +
                     " s; is the driver running?";
    return result;
  }
  if (!driverListening(command_pub_, state_timeout_)) {
    result.code = rascal_msgs::GripperResult::TIMEOUT;
    result.message = "no driver subscribes to /gripper/command; is it running?";
    return result;
  }
  states_.checkClock();
  const std::string late_restart = states_.restart();
  if (!late_restart.empty()) {  // noticed while waiting for the fingers or the driver
    result.code = rascal_msgs::GripperResult::DRIVER_RESTARTED;
    result.message = restartMessage(late_restart);
    return result;
  }
  const ros::Time t0 = ros::Time::now();
  const ros::WallTime wall0 = ros::WallTime::now();
  double start = 0.0;  // [m] left finger when the command went out
  {
    std::unique_lock<std::mutex> lock(mutex_);
    sampled_.wait_for(lock, std::chrono::duration<double>(state_timeout_), [this] { return monitor_.hasSample(); });
    if (!monitor_.hasSample()) {
      result.code = rascal_msgs::GripperResult::TIMEOUT;
      result.message = "no finger sample from /joint_states; is the driver running?";
      return result;
    }
    start = monitor_.latest().position;
    monitor_.start(target.finger);
    command(target.finger, monitor_.strokeTime(monitor_.latest().position, target.finger));
  }
  rascal_msgs::GripperFeedback feedback;
  ros::Time last_feedback;
  while (true) {
    GripperMonitor::Decision decision;
    ros::Time now;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      sampled_.wait_for(lock, std::chrono::milliseconds(5));
      now = ros::Time::now();
      result.duration = (now - t0).toSec();
      result.width = monitor_.latest().opening;
      if (server_->isPreemptRequested() || !ros::ok()) {
        command(monitor_.latest().position, 0.0);  // stop where they are
        monitor_.cancel();
        result.code = rascal_msgs::GripperResult::PREEMPTED;
        result.message = "gripper command cancelled";
        return result;
      }
      decision = monitor_.update(result.duration, (ros::WallTime::now() - wall0).toSec());
    }
    states_.checkClock();
    const std::string restarted = states_.restart();
    if (!restarted.empty()) {
      result.code = rascal_msgs::GripperResult::DRIVER_RESTARTED;
      result.message = restartMessage(restarted);
      return result;
    }
    if (decision.done()) {
      result.code = decision.status == GripperMonitor::Status::Done ? rascal_msgs::GripperResult::OK
                                                                    : rascal_msgs::GripperResult::TIMEOUT;
      result.holding = decision.holding;
      result.message = decision.reason;
      // nothing between the fingers stops an open: one that ends short was stopped by something
      // outside them (or by the servo), which the caller's check of the width will refuse
      const double short_by = target.finger - monitor_.latest().position;
      if (target.finger > start && short_by > GripperMonitor::kFingerReached) {
        ROS_WARN("/rascal/gripper: opening stopped %.1f mm short of its target (left finger at %.1f mm, sent to "
                 "%.1f mm)", short_by * 1000.0, monitor_.latest().position * 1000.0, target.finger * 1000.0);
      }
      return result;
    }
    if ((now - last_feedback).toSec() >= 0.05 || now < last_feedback) {
      feedback.width = result.width;
      server_->publishFeedback(feedback);
      last_feedback = now;
    }
  }
}

}  // namespace rascal_control
