#include "rascal_sim/Mesh.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rascal_sim {

namespace {
float toLinear(double c) {
  c = std::min(1.0, std::max(0.0, c));
  return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}
}  // namespace

Eigen::Vector3f Mesh::srgbToLinear(const Eigen::Vector3d& srgb) {
  return {toLinear(srgb.x()), toLinear(srgb.y()), toLinear(srgb.z())};
}

void Mesh::addTriangle(int a, int b, int c, const Eigen::Vector3f& linear_rgb) {
  triangles.push_back({a, b, c});
  colours.push_back(linear_rgb);
}

void Mesh::addBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& size,
                  const Eigen::Vector3d& srgb, double yaw) {
  const int base = static_cast<int>(vertices.size());
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (int i = 0; i < 8; ++i) {
    Eigen::Vector3d c((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
    vertices.push_back(centre + turn * c.cwiseProduct(size));
  }
  const Eigen::Vector3f lin = srgbToLinear(srgb);
  static const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    addTriangle(base + f[0], base + f[1], base + f[2], lin);
    addTriangle(base + f[0], base + f[2], base + f[3], lin);
  }
}

void Mesh::addRect(double cx, double cy, double sx, double sy, double z,
                   const Eigen::Vector3d& srgb, double yaw) {
  const Eigen::Rotation2Dd turn(yaw);
  auto at = [&](double lx, double ly) {
    const Eigen::Vector2d p = Eigen::Vector2d(cx, cy) + turn * Eigen::Vector2d(lx, ly);
    return Eigen::Vector3d(p.x(), p.y(), z);
  };
  addQuad(at(-sx / 2, -sy / 2), at(sx / 2, -sy / 2), at(sx / 2, sy / 2), at(-sx / 2, sy / 2), srgb);
}

void Mesh::addQuad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d, const Eigen::Vector3d& srgb) {
  const int base = static_cast<int>(vertices.size());
  vertices.insert(vertices.end(), {a, b, c, d});
  const Eigen::Vector3f lin = srgbToLinear(srgb);
  addTriangle(base, base + 1, base + 2, lin);
  addTriangle(base, base + 2, base + 3, lin);
}

void Mesh::updateBounds() {
  radius = 0.0;
  for (const auto& v : vertices) radius = std::max(radius, v.norm());
}

double Mesh::volume() const {
  double v = 0.0;
  for (const auto& t : triangles) {
    v += vertices[t[0]].dot(vertices[t[1]].cross(vertices[t[2]]));
  }
  return std::abs(v) / 6.0;
}

Eigen::Vector3d Mesh::minCorner() const {
  Eigen::Vector3d m = Eigen::Vector3d::Constant(1e30);
  for (const auto& v : vertices) m = m.cwiseMin(v);
  return m;
}

Eigen::Vector3d Mesh::maxCorner() const {
  Eigen::Vector3d m = Eigen::Vector3d::Constant(-1e30);
  for (const auto& v : vertices) m = m.cwiseMax(v);
  return m;
}

Mesh Mesh::loadStl(const std::string& path, const Eigen::Vector3d& srgb) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read STL file " + path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string data = buffer.str();
  Mesh mesh;
  const Eigen::Vector3f lin = srgbToLinear(srgb);
  auto addTri = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const int base = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back(a);
    mesh.vertices.push_back(b);
    mesh.vertices.push_back(c);
    mesh.addTriangle(base, base + 1, base + 2, lin);
  };
  if (data.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, data.data() + 80, 4);
    if (data.size() == 84 + static_cast<size_t>(n) * 50) {
      for (uint32_t i = 0; i < n; ++i) {
        const char* p = data.data() + 84 + i * 50 + 12;
        float f[9];
        std::memcpy(f, p, sizeof f);
        addTri({f[0], f[1], f[2]}, {f[3], f[4], f[5]}, {f[6], f[7], f[8]});
      }
      return mesh;
    }
  }
  std::istringstream text(data);
  std::string word;
  std::vector<Eigen::Vector3d> corners;
  while (text >> word) {
    if (word == "vertex") {
      Eigen::Vector3d v;
      text >> v.x() >> v.y() >> v.z();
      corners.push_back(v);
      if (corners.size() == 3) {
        addTri(corners[0], corners[1], corners[2]);
        corners.clear();
      }
    }
  }
  if (mesh.triangles.empty()) throw std::runtime_error("no triangles in STL file " + path);
  return mesh;
}

}  // namespace rascal_sim
