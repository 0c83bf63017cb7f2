#pragma once
// What the simulated table looks like: the rig's one workcell model (rascal_workcell::Workcell,
// stations found by type, fixture boxes computed once from config/rascal.yaml) plus what only the
// simulator needs: where the stations really stand, their calibration markers, colours and the
// folder of its data files.
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "rascal_sim/StationMarker.hpp"
#include "rascal_workcell/Parameters.hpp"
#include "rascal_workcell/Workcell.hpp"

namespace rascal_sim {

using rascal_workcell::FixtureBox;
using rascal_workcell::Station;
using rascal_workcell::StationType;
using rascal_workcell::TableRect;

struct WorldLayout {
  /// The stations as configured: where the arm controller and perception believe they stand.
  rascal_workcell::Workcell workcell;
  /// Where the stations really stand in the simulated world, and everything the world builds:
  /// the configured ones, moved by offsetStation (a scenario's station_offsets).
  std::vector<Station> stations;
  std::vector<FixtureBox> boxes;  ///< workcell.collisionBoxes(), moved with their stations
  std::vector<StationMarker> markers;
  Eigen::Vector3d table_colour{0.0, 0.0, 0.0};  ///< sRGB [0, 1] (simulator.table_colour)
  Eigen::Vector3d mat_colour{0.0, 0.0, 0.0};    ///< pickup and discard mats (simulator.mat_colour)
  std::array<Eigen::Vector3d, 2> scale_colours{};  ///< platform pan, rim (simulator.scale_colours)
  std::string data_dir;  ///< folder with the colour chart CSV, Munsell CSV, fragment STL

  /// The one station of a type, where it really stands (the workcell checked that there is
  /// exactly one).
  const Station& station(StationType type) const;
  /// By name, where it really stands; nullptr when unknown.
  const Station* find(const std::string& name) const;

  /// Moves station `name` to where the rig really has it: (dx, dy) [m] in base_link and turned
  /// by dyaw [rad] about its centre. Throws std::invalid_argument naming an unknown station.
  void offsetStation(const std::string& name, double dx, double dy, double dyaw);

  /// Reads `stations.*` (through Workcell::fromParameters, and the markers) and the simulator's
  /// colours; throws rascal_workcell::ParameterError naming the key.
  static WorldLayout fromParameters(const rascal_workcell::Parameters& params, const std::string& data_dir);
};

}  // namespace rascal_sim
