#include "rascal_sim/SherdMeshBuilder.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rascal_sim {

namespace {
using Vec2 = Eigen::Vector2d;

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

double signedArea(const std::vector<Vec2>& p) {
  double a = 0.0;
  for (size_t i = 0; i < p.size(); ++i) a += cross(p[i], p[(i + 1) % p.size()]);
  return a / 2;
}

bool inside(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  return cross(b - a, p - a) >= 0 && cross(c - b, p - b) >= 0 && cross(a - c, p - c) >= 0;
}

/// Ear clipping of a simple counter-clockwise polygon.
std::vector<std::array<int, 3>> earClip(const std::vector<Vec2>& p) {
  std::vector<int> idx(p.size());
  for (size_t i = 0; i < p.size(); ++i) idx[i] = static_cast<int>(i);
  std::vector<std::array<int, 3>> tris;
  int guard = 0;
  while (idx.size() > 3 && guard++ < 10000) {
    bool clipped = false;
    for (size_t i = 0; i < idx.size(); ++i) {
      const int a = idx[(i + idx.size() - 1) % idx.size()], b = idx[i], c = idx[(i + 1) % idx.size()];
      if (cross(p[b] - p[a], p[c] - p[b]) <= 1e-14) continue;
      bool ear = true;
      for (int j : idx) {
        if (j == a || j == b || j == c) continue;
        if (inside(p[j], p[a], p[b], p[c])) {
          ear = false;
          break;
        }
      }
      if (!ear) continue;
      tris.push_back({a, b, c});
      idx.erase(idx.begin() + static_cast<long>(i));
      clipped = true;
      break;
    }
    if (!clipped) break;  // degenerate: fan out the rest
  }
  for (size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[0], idx[i], idx[i + 1]});
  return tris;
}

struct Tri2 {
  Vec2 a, b, c;
};

void subdivide(const Tri2& t, int levels, std::vector<Tri2>& out) {
  if (levels == 0) {
    out.push_back(t);
    return;
  }
  const Vec2 ab = (t.a + t.b) / 2, bc = (t.b + t.c) / 2, ca = (t.c + t.a) / 2;
  subdivide({t.a, ab, ca}, levels - 1, out);
  subdivide({ab, t.b, bc}, levels - 1, out);
  subdivide({ca, bc, t.c}, levels - 1, out);
  subdivide({ab, bc, ca}, levels - 1, out);
}
// 6 strips over a 40-60 mm sherd: each under 10 mm wide, so the staircase stays within ~3 mm of
// a slanted edge while a resting sherd has a handful of contact boxes, not hundreds of triangles.
constexpr int kCollisionStrips = 6;
}  // namespace

OutlineAxes SherdMeshBuilder::principalAxes(const std::vector<Vec2>& p) {
  OutlineAxes ax;
  if (p.size() < 3) return ax;
  double a = 0.0, cx = 0.0, cy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2& u = p[i];
    const Vec2& v = p[(i + 1) % p.size()];
    const double c = cross(u, v);
    a += c;
    cx += (u.x() + v.x()) * c;
    cy += (u.y() + v.y()) * c;
    sxx += (u.x() * u.x() + u.x() * v.x() + v.x() * v.x()) * c;
    syy += (u.y() * u.y() + u.y() * v.y() + v.y() * v.y()) * c;
    sxy += (u.x() * v.y() + 2 * u.x() * u.y() + 2 * v.x() * v.y() + v.x() * u.y()) * c;
  }
  if (std::abs(a) < 1e-12) return ax;
  a /= 2;
  cx /= 6 * a;
  cy /= 6 * a;
  const double vxx = sxx / (12 * a) - cx * cx, vyy = syy / (12 * a) - cy * cy;
  const double vxy = sxy / (24 * a) - cx * cy;
  const double angle = 0.5 * std::atan2(2 * vxy, vxx - vyy);
  ax.major = {std::cos(angle), std::sin(angle)};
  const Vec2 minor(-ax.major.y(), ax.major.x());
  double lo = 1e9, hi = -1e9, lo2 = 1e9, hi2 = -1e9;
  for (const auto& q : p) {
    lo = std::min(lo, q.dot(ax.major));
    hi = std::max(hi, q.dot(ax.major));
    lo2 = std::min(lo2, q.dot(minor));
    hi2 = std::max(hi2, q.dot(minor));
  }
  ax.length = hi - lo;
  ax.width = hi2 - lo2;
  return ax;
}

std::vector<Vec2> SherdMeshBuilder::convexHull(std::vector<Vec2> p) {
  std::sort(p.begin(), p.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (p.size() < 3) return p;
  std::vector<Vec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {  // lower hull
    while (k >= 2 && cross(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {  // upper hull
    while (k >= t && cross(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

std::vector<CollisionBox> SherdMeshBuilder::collisionStrips(const std::vector<Vec2>& outline,
                                                            double height, int strips) {
  const std::vector<Vec2> hull = convexHull(outline);
  std::vector<CollisionBox> boxes;
  if (hull.size() < 3) return boxes;
  double x0 = hull[0].x(), x1 = hull[0].x();
  for (const auto& p : hull) {
    x0 = std::min(x0, p.x());
    x1 = std::max(x1, p.x());
  }
  const double dx = (x1 - x0) / strips;
  for (int i = 0; i < strips; ++i) {
    const double a = x0 + i * dx, b = a + dx;
    // A convex polygon's y extent over [a, b] is reached at a vertex inside the strip or where
    // an edge crosses x = a or x = b.
    double lo = 1e9, hi = -1e9;
    auto take = [&](double y) {
      lo = std::min(lo, y);
      hi = std::max(hi, y);
    };
    for (size_t j = 0; j < hull.size(); ++j) {
      const Vec2& p = hull[j];
      const Vec2& q = hull[(j + 1) % hull.size()];
      if (p.x() >= a - 1e-12 && p.x() <= b + 1e-12) take(p.y());
      for (double x : {a, b}) {
        if ((p.x() - x) * (q.x() - x) < 0) take(p.y() + (q.y() - p.y()) * (x - p.x()) / (q.x() - p.x()));
      }
    }
    if (hi <= lo) continue;
    boxes.push_back({{(a + b) / 2, (lo + hi) / 2, 0.0}, {dx, hi - lo, height}});
  }
  return boxes;
}

SherdGeometry SherdMeshBuilder::build(const SherdSpec& spec) {
  SherdGeometry g;
  const Eigen::Vector3f top = Mesh::srgbToLinear(spec.colour);
  const Eigen::Vector3f bottom = Mesh::srgbToLinear(spec.colour * 0.9);
  const Eigen::Vector3f side = Mesh::srgbToLinear(spec.colour * 0.75 + Eigen::Vector3d(0.05, 0.05, 0.05));
  const Eigen::Vector3f paint = Mesh::srgbToLinear(spec.pattern_colour);

  if (!spec.mesh_file.empty()) {
    g.mesh = Mesh::loadStl(spec.mesh_file, spec.colour);
    const Eigen::Vector3d centre = (g.mesh.minCorner() + g.mesh.maxCorner()) / 2;
    for (auto& v : g.mesh.vertices) v -= centre;
    g.box_size = g.mesh.maxCorner() - g.mesh.minCorner();
    g.volume = g.mesh.volume();
    g.length = std::max(g.box_size.x(), g.box_size.y());
    g.width = std::min(g.box_size.x(), g.box_size.y());
    std::vector<Vec2> top_view;
    top_view.reserve(g.mesh.vertices.size());
    for (const auto& v : g.mesh.vertices) top_view.emplace_back(v.x(), v.y());
    g.outline = convexHull(std::move(top_view));
  } else {
    if (spec.outline.size() < 3) throw std::runtime_error("sherd " + spec.name + ": outline needs >= 3 points");
    std::vector<Vec2> outline = spec.outline;
    if (signedArea(outline) < 0) std::reverse(outline.begin(), outline.end());
    // resample each edge so the walls follow the curved surface
    std::vector<Vec2> ring;
    for (size_t i = 0; i < outline.size(); ++i) {
      const Vec2& a = outline[i];
      const Vec2& b = outline[(i + 1) % outline.size()];
      const int seg = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.006)));
      for (int s = 0; s < seg; ++s) ring.push_back(a + (b - a) * (static_cast<double>(s) / seg));
    }
    const double sign = spec.convex_up ? 1.0 : -1.0;
    auto mid = [&](const Vec2& p) {
      return -sign * (spec.curvature * p.y() * p.y() + spec.curvature_long * p.x() * p.x()) / 2;
    };
    const double ht = spec.thickness / 2;
    Vec2 lo = ring[0], hi = ring[0];
    for (const auto& p : ring) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const double width = hi.y() - lo.y();
    Mesh& m = g.mesh;
    auto vert = [&](const Vec2& p, double z) {
      m.vertices.emplace_back(p.x(), p.y(), z);
      return static_cast<int>(m.vertices.size()) - 1;
    };
    auto painted = [&](const Vec2& c) {
      if (spec.pattern == "stripes") return std::sin(2 * M_PI * c.x() / 0.014) > 0.55;
      if (spec.pattern == "band") return std::abs(c.y() - 0.2 * width) < 0.005;
      return false;
    };
    std::vector<Tri2> fine;
    for (const auto& t : earClip(ring)) subdivide({ring[t[0]], ring[t[1]], ring[t[2]]}, 2, fine);
    for (const auto& t : fine) {
      const Vec2 c = (t.a + t.b + t.c) / 3;
      const int a = vert(t.a, mid(t.a) + ht), b = vert(t.b, mid(t.b) + ht), cc = vert(t.c, mid(t.c) + ht);
      m.addTriangle(a, b, cc, painted(c) ? paint : top);
      const int d = vert(t.a, mid(t.a) - ht), e = vert(t.b, mid(t.b) - ht), f = vert(t.c, mid(t.c) - ht);
      m.addTriangle(d, f, e, bottom);
    }
    for (size_t i = 0; i < ring.size(); ++i) {
      const Vec2& a = ring[i];
      const Vec2& b = ring[(i + 1) % ring.size()];
      const int a0 = vert(a, mid(a) - ht), b0 = vert(b, mid(b) - ht);
      const int a1 = vert(a, mid(a) + ht), b1 = vert(b, mid(b) + ht);
      m.addTriangle(a0, b0, b1, side);
      m.addTriangle(a0, b1, a1, side);
    }
    const Eigen::Vector3d lo3 = m.minCorner(), hi3 = m.maxCorner();
    const Eigen::Vector3d centre = (lo3 + hi3) / 2;
    for (auto& v : m.vertices) v -= centre;
    g.box_size = hi3 - lo3;
    g.volume = m.volume();
    g.length = hi.x() - lo.x();
    g.width = width;
    for (const auto& p : outline) g.outline.push_back(p - centre.head<2>());
  }
  g.mass = g.volume * spec.density;
  g.collision = collisionStrips(g.outline, g.box_size.z(), kCollisionStrips);
  g.mesh.cull_back_faces = spec.mesh_file.empty();  // our shells are wound outwards
  g.mesh.updateBounds();
  return g;
}

}  // namespace rascal_sim
