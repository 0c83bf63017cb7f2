#pragma once
// Everything the simulator reads from config/rascal.yaml (reader "sim" of the parameter schema),
// checked once: the world layout, the simulator options (finger limits from the URDF) and the
// node's own settings. Used by the node (from the parameter server), tests and tools (from the
// shipped file). No ROS.
#include <string>

#include "rascal_sim/Simulator.hpp"
#include "rascal_sim/WorldLayout.hpp"
#include "rascal_workcell/GripperGeometry.hpp"
#include "rascal_workcell/Parameters.hpp"

namespace rascal_sim {

struct SimParameters {
  WorldLayout layout;
  SimulatorOptions options;
  std::string scenario;             ///< simulator.scenario, as written (relative to the workspace root)
  std::string spool_dir;            ///< simulator.spool_dir, as written
  double real_time_factor = 0.0;    ///< 0 = as fast as possible
  double clock_period = 0.0;        ///< [s] sim time between /clock messages
  double joint_state_period = 0.0;  ///< [s] sim time between /joint_states messages
  bool point_cloud = false;

  /// Reads every key the schema lists for "sim" (and checks that none is left unread); the
  /// initial joints must lie within the arm's joint limits and the initial finger within the
  /// gripper's. Throws rascal_workcell::ParameterError naming the key.
  static SimParameters read(const rascal_workcell::Parameters& params,
                            const rascal_workcell::GripperGeometry& gripper, const std::string& data_dir);
};

}  // namespace rascal_sim
