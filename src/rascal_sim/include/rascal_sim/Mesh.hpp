#pragma once
// A triangle mesh with one linear-RGB colour per triangle (what the renderer draws).
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

namespace rascal_sim {

struct Mesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;
  std::vector<Eigen::Vector3f> colours;  ///< linear RGB per triangle
  bool cull_back_faces = false;          ///< closed, outward-wound: back faces are never visible
  double radius = -1.0;                  ///< bounding sphere about the origin (updateBounds())

  void updateBounds();

  void addTriangle(int a, int b, int c, const Eigen::Vector3f& linear_rgb);
  /// Adds a box (centre, size along its own axes, turned by yaw [rad] about +z) with one sRGB colour.
  void addBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& size, const Eigen::Vector3d& srgb,
              double yaw = 0.0);
  /// Adds a flat rectangle at height z (centre x, y; size x, y along its own axes, turned by yaw
  /// [rad] about +z) with one sRGB colour.
  void addRect(double cx, double cy, double sx, double sy, double z, const Eigen::Vector3d& srgb,
               double yaw = 0.0);
  /// Adds a flat quadrilateral a, b, c, d (counter-clockwise seen from its front) with one sRGB colour.
  void addQuad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
               const Eigen::Vector3d& d, const Eigen::Vector3d& srgb);
  /// Signed volume enclosed by a closed mesh [m^3] (absolute value returned).
  double volume() const;
  Eigen::Vector3d minCorner() const;
  Eigen::Vector3d maxCorner() const;

  static Eigen::Vector3f srgbToLinear(const Eigen::Vector3d& srgb);
  /// Reads a binary or ASCII STL file (metres); throws std::runtime_error naming the file.
  static Mesh loadStl(const std::string& path, const Eigen::Vector3d& srgb);
};

}  // namespace rascal_sim
