#pragma once
// A scenario: the sherds on the table, the lighting and where the stations really stand, read
// from a YAML file.
#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

namespace rascal_sim {

struct SherdSpec {
  std::string name;
  std::vector<Eigen::Vector2d> outline;  ///< [m] polygon in the sherd frame (x = major axis)
  double thickness = 0.007;              ///< [m] wall thickness
  double curvature = 0.0;                ///< [1/m] bend across the sherd's width (vessel wall)
  double curvature_long = 0.0;           ///< [1/m] bend along the sherd's length
  bool convex_up = true;                 ///< outer vessel surface facing up
  double density = 1850.0;               ///< [kg/m^3]
  std::string munsell = "5YR 6/6";       ///< surface colour chip
  Eigen::Vector3d colour{0.76, 0.52, 0.40};  ///< sRGB [0, 1], resolved from `munsell`
  std::string pattern = "none";          ///< none | stripes | band (painted decoration)
  Eigen::Vector3d pattern_colour{0.15, 0.10, 0.08};
  std::string mesh_file;                 ///< optional STL (metres); replaces the outline shell
  Eigen::Vector3d pose{0.0, 0.0, 0.0};   ///< [m, m, rad] x, y, yaw on the table
  double drop_height = 0.0;              ///< [m] gap under the sherd when spawned
  /// [rad] turned about its own long axis when spawned (pi/2: standing on its long edge, as a
  /// tipped-out bag leaves some leaning on others; alone it falls once the world steps)
  double tilt = 0.0;
};

/// What makes a wrist frame look like a field photo (all 0 = the plain rendering). Wrist camera
/// only: the archival camera keeps the sherd's colour as its Munsell chip gives it.
struct Realism {
  double texture = 0.0;      ///< [1] 0 .. 1: cloth and sherd surface textures sampled from real photos
  double cast_shadow = 0.0;  ///< [1] 0 .. 0.8: fraction of light a sherd's cast shadow takes from the cloth
  double glare = 0.0;        ///< [1] 0 .. 1: specular highlights on the sherds (glaze, slip)
  double light_azimuth = 2.4;     ///< [rad] direction the light comes from, about +z in base_link
  double light_elevation = 0.8;   ///< [rad] above the table
  bool any() const { return texture > 0.0 || cast_shadow > 0.0 || glare > 0.0; }
};

struct Lighting {
  double brightness = 1.0;            ///< [1] 0.3 .. 1.5
  double colour_temperature = 6500;   ///< [K] 2500 .. 10000; 6500 = neutral
  double shadow_strength = 0.0;       ///< [1] fraction of light the shadow takes away, 0 .. 0.8
  double shadow_radius = 0.08;        ///< [m]
  Eigen::Vector2d shadow_start{0.0, 0.4};     ///< [m] shadow centre on the table at t = 0
  Eigen::Vector2d shadow_velocity{0.0, -0.01};  ///< [m/s] it drifts across the table
  double colour_noise = 2.0;          ///< [8-bit counts] sigma of the colour sensor noise
  Realism realism;
};

/// Where a station really stands against the configuration (the rig set up off its measured
/// layout): what the marker calibration must find.
struct StationOffset {
  static constexpr double kMaxShift = 0.1;  ///< [m] |dx|, |dy|
  static constexpr double kMaxTurn = 0.2;   ///< [rad] |dyaw|
  double dx = 0.0, dy = 0.0;  ///< [m] in base_link
  double dyaw = 0.0;          ///< [rad] about the station's centre (only its markers show it)
  bool operator==(const StationOffset& o) const { return dx == o.dx && dy == o.dy && dyaw == o.dyaw; }
  bool operator!=(const StationOffset& o) const { return !(*this == o); }
};

struct Scenario {
  std::string name = "empty";
  unsigned seed = 1;
  Lighting lighting;
  std::vector<SherdSpec> sherds;
  std::map<std::string, StationOffset> station_offsets;  ///< by station name; none = as configured
};

}  // namespace rascal_sim
