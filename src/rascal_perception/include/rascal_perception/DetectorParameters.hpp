#pragma once
// Everything sherd_detector reads from config/rascal.yaml (reader "sherd_detector" of the
// parameter schema), checked once: the perception configuration, the workcell's stations and the
// node's own settings; the gripper comes from the URDF. Used by the node (from the parameter
// server), tests and tools (from the shipped file). No ROS.
#include "rascal_perception/Types.hpp"
#include "rascal_workcell/GripperGeometry.hpp"
#include "rascal_workcell/Parameters.hpp"
#include "rascal_workcell/Workcell.hpp"

namespace rascal_perception {

struct DetectorParameters {
  PerceptionConfig config;             ///< perception.*, arm.grasp_margin, the gripper
  rascal_workcell::Workcell workcell;  ///< stations: a request names one, its surface_z is used
  double frame_wait = 1.0;             ///< [s] perception.frame_wait
  double refresh_period = 0.0;         ///< [s] perception.refresh_period (0 = never)

  /// Reads every key the schema lists for "sherd_detector" and checks that none is left unread.
  /// Throws rascal_workcell::ParameterError naming the key.
  static DetectorParameters read(const rascal_workcell::Parameters& params,
                                 const rascal_workcell::GripperGeometry& gripper);
};

}  // namespace rascal_perception
