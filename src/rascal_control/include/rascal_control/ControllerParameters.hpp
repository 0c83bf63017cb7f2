// Everything arm_controller reads from config/rascal.yaml (reader "arm_controller" of the
// parameter schema), checked once: the move and gripper settings, the named poses (within the
// URDF's joint limits) and the workcell's fixture boxes. Used by the node (from the parameter
// server) and the tests (from the shipped file). No ROS.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "rascal_control/GripperMonitor.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/MoveMonitor.hpp"
#include "rascal_workcell/Parameters.hpp"
#include "rascal_workcell/Workcell.hpp"

namespace rascal_control {

struct ControllerParameters {
  std::map<std::string, JointVector> named_poses;  // arm.named_poses.<name> [rad]
  double speed_scale = 1.0;          // arm.speed_scale: multiplies every goal's speed scale
  double acceleration_share = 0.95;  // arm.acceleration_share of the 5 rad/s^2 limit
  double command_period = 0.02;      // [s] arm.command_period
  double state_timeout = 1.0;        // [s] arm.state_timeout
  bool publish_tf = true;            // arm.publish_tf
  MoveMonitor::Settings move;        // arm.goal_tolerance, arm.settle_timeout, arm.tracking_tolerance
  GripperMonitor::Settings gripper;  // arm.gripper.stroke_time, timeout, held_margin
  double fingertip_pads = 0.0;       // [m] arm.gripper.fingertip_pads (GripperGeometry::pad)
  std::vector<rascal_workcell::FixtureBox> fixtures;  // Workcell::collisionBoxes() of stations.*

  // Reads every key the schema lists for "arm_controller" and checks that none is left unread.
  // Throws rascal_workcell::ParameterError naming the key (a named pose outside the joint limits
  // of `model` included).
  static ControllerParameters read(const rascal_workcell::Parameters& params, const KinematicModel& model);
};

}  // namespace rascal_control
