#include "rascal_sim/WorldLayout.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rascal_sim {

namespace {
using rascal_workcell::ParameterError;

/// The station's markers, or none: `marker_ids` and `marker_positions` come together.
std::vector<StationMarker> readMarkers(const rascal_workcell::Parameters& p, const Station& s) {
  const std::string ids_key = "stations." + s.name + ".marker_ids";
  const std::string positions_key = "stations." + s.name + ".marker_positions";
  // has() counts as reading the key: a station without markers has not ignored it
  const bool has_ids = p.has(ids_key), has_positions = p.has(positions_key);
  if (has_ids != has_positions) {
    const std::string& missing = has_ids ? positions_key : ids_key;
    throw ParameterError(missing + ": missing; give both " + ids_key + " and " + positions_key + ", or neither");
  }
  if (!has_ids) return {};
  const std::vector<double> ids = p.vector(ids_key);
  const std::vector<std::vector<double>> positions = p.vectors(positions_key);
  std::vector<StationMarker> markers;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (std::floor(ids[i]) != ids[i]) throw ParameterError(ids_key + ": expected whole ArUco ids");
    StationMarker m;
    m.station = s.name;
    m.id = static_cast<int>(ids[i]);
    m.centre = s.area.toTable({positions[i][0], positions[i][1]});
    m.yaw = s.area.yaw;
    markers.push_back(m);
  }
  return markers;
}
}  // namespace

const Station& WorldLayout::station(StationType type) const { return *find(workcell.station(type).name); }

const Station* WorldLayout::find(const std::string& name) const {
  for (const Station& s : stations) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

// The station moves as one rigid piece: its area, chart, bar, stand, place, fixture boxes and
// markers turn by dyaw about the station's configured centre and shift by (dx, dy).
void WorldLayout::offsetStation(const std::string& name, double dx, double dy, double dyaw) {
  const auto s = std::find_if(stations.begin(), stations.end(), [&](const Station& t) { return t.name == name; });
  if (s == stations.end()) throw std::invalid_argument("station_offsets." + name + ": no such station");
  const Eigen::Vector2d old_centre = s->area.centre, new_centre = old_centre + Eigen::Vector2d(dx, dy);
  const Eigen::Rotation2Dd turn(dyaw);
  auto move = [&](const Eigen::Vector2d& p) { return Eigen::Vector2d(new_centre + turn * (p - old_centre)); };
  for (TableRect* r : {&s->area, &s->colour_chart, &s->scale_bar, &s->stand}) {
    r->centre = move(r->centre);
    r->yaw += dyaw;
  }
  s->place_at = move(s->place_at);
  for (FixtureBox& b : boxes) {
    if (b.station != name) continue;
    b.centre.head<2>() = move(b.centre.head<2>());
    b.yaw += dyaw;
  }
  for (StationMarker& m : markers) {
    if (m.station != name) continue;
    m.centre = move(m.centre);
    m.yaw += dyaw;
  }
}

WorldLayout WorldLayout::fromParameters(const rascal_workcell::Parameters& p, const std::string& data_dir) {
  WorldLayout l;
  l.workcell = rascal_workcell::Workcell::fromParameters(p);
  l.stations = l.workcell.stations();
  l.boxes = l.workcell.collisionBoxes();
  for (const Station& s : l.stations) {
    for (const StationMarker& m : readMarkers(p, s)) l.markers.push_back(m);
  }
  l.table_colour = p.vector3("simulator.table_colour");
  l.mat_colour = p.vector3("simulator.mat_colour");
  const auto sc = p.vectors("simulator.scale_colours");
  l.scale_colours = {Eigen::Vector3d(sc[0][0], sc[0][1], sc[0][2]), Eigen::Vector3d(sc[1][0], sc[1][1], sc[1][2])};
  l.data_dir = data_dir;
  return l;
}

}  // namespace rascal_sim
