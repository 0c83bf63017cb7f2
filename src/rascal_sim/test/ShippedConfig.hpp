#pragma once
// Test helper: the simulator's parameters as the node would read them, from the shipped
// config/rascal.yaml and the package URDF (read once per test binary).
#include "rascal_sim/SimParameters.hpp"

namespace rascal_sim_test {

inline const rascal_sim::SimParameters& shipped() {
  static const rascal_sim::SimParameters p =
      rascal_sim::SimParameters::read(rascal_workcell::Parameters::fromFile(RASCAL_CONFIG_PATH, "sim"),
                                      rascal_workcell::GripperGeometry::fromPackageUrdf(), RASCAL_SIM_DATA_DIR);
  return p;
}
inline const rascal_sim::WorldLayout& layout() { return shipped().layout; }
inline const rascal_workcell::GripperGeometry& gripper() { return shipped().options.gripper; }

}  // namespace rascal_sim_test
