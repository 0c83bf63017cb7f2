#pragma once
// What the simulated table looks like: the rig's one workcell model (rascal_workcell::Workcell,
// stations found by type, fixture boxes computed once from config/rascal.yaml) plus what only the
// simulator needs: colours and the folder of its data files.
#include <Eigen/Core>
#include <array>
#include <string>

#include "rascal_workcell/Parameters.hpp"
#include "rascal_workcell/Workcell.hpp"

namespace rascal_sim {

using rascal_workcell::Station;
using rascal_workcell::StationType;
using rascal_workcell::TableRect;

struct WorldLayout {
  rascal_workcell::Workcell workcell;
  Eigen::Vector3d table_colour{0.0, 0.0, 0.0};  ///< sRGB [0, 1] (simulator.table_colour)
  Eigen::Vector3d mat_colour{0.0, 0.0, 0.0};    ///< pickup and discard mats (simulator.mat_colour)
  std::array<Eigen::Vector3d, 2> scale_colours{};  ///< platform pan, rim (simulator.scale_colours)
  std::string data_dir;  ///< folder with the colour chart CSV, Munsell CSV, fragment STL

  /// The one station of a type (the workcell checked that there is exactly one).
  const Station& station(StationType type) const { return workcell.station(type); }

  /// Reads `stations.*` (through Workcell::fromParameters) and the simulator's colours; throws
  /// rascal_workcell::ParameterError naming the key.
  static WorldLayout fromParameters(const rascal_workcell::Parameters& params, const std::string& data_dir);
};

}  // namespace rascal_sim
