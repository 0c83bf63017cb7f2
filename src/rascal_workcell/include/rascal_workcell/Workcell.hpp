#pragma once
// The workcell: the stations on the table and the fixtures that stand on it (scale, discard box
// walls, camera stand, colour chart, scale bar), computed once from the configuration. The arm
// controller checks collisions against collisionBoxes(), the simulator builds its world from the
// same boxes, perception takes station surfaces from here. Stations are found by type, never by
// name: a site may call its camera station anything.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "rascal_workcell/Parameters.hpp"

namespace rascal_workcell {

/// Bin: a sorting box like the discard box (walls, a mat), for the sherds its rule picks.
/// Other: a station type of a task-layer plug-in (a profile scanner): a place on the table the
/// nodes know by its area and surface only.
enum class StationType { Pickup, Scale, ArchivalCamera, Discard, Bin, Other };

/// "pickup" | "scale" | "archival_camera" | "discard" | "bin" (the config's `type`).
std::string toString(StationType type);
StationType stationTypeFromString(const std::string& name);  ///< Other for any other name

/// A rectangle on the table: centre and size [along its own x, along its own y] in base_link,
/// metres, turned by yaw [rad] about +z (its station's yaw; 0 = square to the arm's base).
struct TableRect {
  Eigen::Vector2d centre{0.0, 0.0};
  Eigen::Vector2d size{0.0, 0.0};
  double yaw = 0.0;
  bool contains(const Eigen::Vector2d& p) const;
  /// p (base_link) in the rectangle's own frame: origin at its centre, axes along its sides.
  Eigen::Vector2d toLocal(const Eigen::Vector2d& p) const;
  /// A point of the rectangle's own frame in base_link.
  Eigen::Vector2d toTable(const Eigen::Vector2d& local) const;
};

/// A box standing on the table, in base_link, metres, turned by yaw [rad] about +z (its
/// station's yaw): what the arm must not touch.
struct FixtureBox {
  std::string name;        ///< e.g. "scale housing", "discard box wall +y", "camera stand"
  std::string station;     ///< the station it belongs to
  Eigen::Vector3d centre{0.0, 0.0, 0.0};
  Eigen::Vector3d size{0.0, 0.0, 0.0};
  bool is_support = false; ///< a surface sherds are put on (the scale platform): the arm may
                           ///< touch its top while placing, a held sherd may rest on it
  double yaw = 0.0;
  /// What it covers of the table (its outline seen from above).
  TableRect footprint() const { return {centre.head<2>(), size.head<2>(), yaw}; }
};

struct Station {
  std::string name;
  StationType type = StationType::Pickup;
  TableRect area;                 ///< the mat, platform, field of view or box floor
  double surface_z = 0.0;         ///< [m] top surface above the table
  Eigen::Vector2d place_at{0.0, 0.0};  ///< where a sherd is put (the centre unless configured)
  // discard box and sorting bins
  double wall_height = 0.0;       ///< [m] walls above the table
  // archival camera
  double camera_height = 0.0;     ///< [m] lens above the surface
  TableRect colour_chart, scale_bar, stand;
  double stand_height = 0.0;      ///< [m]
};

class Workcell {
 public:
  // Fixture dimensions that are not in the configuration (the site measures only what it places).
  /// [m] discard box walls (a 5 mm plastic or plywood tray; not measured on the rig).
  static constexpr double kDiscardWallThickness = 0.005;
  /// [m] the scale's housing reaches this far beyond its weighing platform on every side
  /// (bench balances of 0.1 g readability: platform ~130 mm, housing ~160 mm wide).
  static constexpr double kScaleHousingMargin = 0.015;
  /// [m] the weighing platform's own thickness (the housing below it carries the load cell).
  static constexpr double kScalePlatformThickness = 0.010;

  /// Reads `stations.*` through the schema; throws ParameterError naming the key.
  static Workcell fromParameters(const Parameters& params);

  const std::vector<Station>& stations() const { return stations_; }
  /// The one station of a type; throws ParameterError when there is none or several.
  const Station& station(StationType type) const;
  /// By the name the task layer uses in requests; nullptr when unknown.
  const Station* find(const std::string& name) const;

  /// Everything standing on the table the arm must not hit, computed once: the scale housing and
  /// its platform, the four walls of the discard box and of each sorting bin, the camera
  /// stand's post.
  std::vector<FixtureBox> collisionBoxes() const;
  /// Flat marks lying on the table that perception must not take for sherds: chart and bar.
  std::vector<TableRect> flatFixtures() const;

 private:
  std::vector<Station> stations_;
};

}  // namespace rascal_workcell
