#include "rascal_sim/WorldLayout.hpp"

namespace rascal_sim {

WorldLayout WorldLayout::fromParameters(const rascal_workcell::Parameters& p, const std::string& data_dir) {
  WorldLayout l;
  l.workcell = rascal_workcell::Workcell::fromParameters(p);
  l.table_colour = p.vector3("simulator.table_colour");
  l.mat_colour = p.vector3("simulator.mat_colour");
  const auto sc = p.vectors("simulator.scale_colours");
  l.scale_colours = {Eigen::Vector3d(sc[0][0], sc[0][1], sc[0][2]), Eigen::Vector3d(sc[1][0], sc[1][1], sc[1][2])};
  l.data_dir = data_dir;
  return l;
}

}  // namespace rascal_sim
