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
    m.centre = s.area.centre + Eigen::Vector2d(positions[i][0], positions[i][1]);
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

// The workcell has no station yaw (stations are axis-aligned rectangles, as the arm controller
// and perception model them), so a station's own bodies (mat, platform, walls, stand, chart,
// bar) only move by (dx, dy); its markers carry the turn as well, which is what the calibration
// measures.
void WorldLayout::offsetStation(const std::string& name, double dx, double dy, double dyaw) {
  const auto s = std::find_if(stations.begin(), stations.end(), [&](const Station& t) { return t.name == name; });
  if (s == stations.end()) throw std::invalid_argument("station_offsets." + name + ": no such station");
  const Eigen::Vector2d shift(dx, dy), old_centre = s->area.centre;
  for (TableRect* r : {&s->area, &s->colour_chart, &s->scale_bar, &s->stand}) r->centre += shift;
  s->place_at += shift;
  for (FixtureBox& b : boxes) {
    if (b.station == name) b.centre.head<2>() += shift;
  }
  for (StationMarker& m : markers) {
    if (m.station != name) continue;
    m.centre = s->area.centre + Eigen::Rotation2Dd(dyaw) * (m.centre - old_centre);
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
