#include "rascal_sim/WorldLayout.hpp"

namespace rascal_sim {

WorldLayout WorldLayout::defaults(const std::string& data_dir) {
  WorldLayout l;
  l.pickup = {{0.16, 0.25}, {0.30, 0.16}};
  l.scale = {{0.30, 0.0}, {0.13, 0.13}};
  l.scale_surface_z = 0.025;
  l.camera = {{0.31, -0.30}, {0.26, 0.18}};
  l.camera_place_at = {0.28, -0.30};
  l.camera_height = 0.55;
  l.colour_chart = {{0.39, -0.245}, {0.07, 0.045}};
  l.scale_bar = {{0.39, -0.35}, {0.10, 0.015}};
  l.stand = {{0.50, -0.30}, {0.04, 0.04}};
  l.stand_height = 0.60;
  l.discard = {{0.02, -0.31}, {0.14, 0.13}};
  l.discard_wall_height = 0.04;
  l.data_dir = data_dir;
  return l;
}

}  // namespace rascal_sim
