#include "rascal_sim/ScenarioGenerator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rascal_sim/Mesh.hpp"

namespace rascal_sim {

namespace {
constexpr double kPi = 3.141592653589793;

double uniform(std::mt19937& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

/// Gap between two turned boxes (centre x, y, yaw; half sizes) along the best separating axis;
/// negative when they overlap.
double boxGap(const Eigen::Vector3d& a, const Eigen::Vector2d& ha, const Eigen::Vector3d& b, const Eigen::Vector2d& hb) {
  const Eigen::Vector2d axes[4] = {{std::cos(a.z()), std::sin(a.z())}, {-std::sin(a.z()), std::cos(a.z())},
                                   {std::cos(b.z()), std::sin(b.z())}, {-std::sin(b.z()), std::cos(b.z())}};
  const Eigen::Vector2d d = b.head<2>() - a.head<2>();
  double gap = -1e9;
  for (const auto& n : axes) {
    const double ra = ha.x() * std::abs(n.dot(axes[0])) + ha.y() * std::abs(n.dot(axes[1]));
    const double rb = hb.x() * std::abs(n.dot(axes[2])) + hb.y() * std::abs(n.dot(axes[3]));
    gap = std::max(gap, std::abs(n.dot(d)) - ra - rb);
  }
  return gap;
}

/// Extents along x and y of a length x width box turned by yaw.
Eigen::Vector2d turnedExtents(double length, double width, double yaw) {
  const double c = std::abs(std::cos(yaw)), s = std::abs(std::sin(yaw));
  return {length * c + width * s, length * s + width * c};
}

// Ware colours seen on sherds (facts sherds_and_colour.md §2d), filtered by the table.
const char* const kWareChips[] = {
    "2.5YR 5/6", "2.5YR 6/6", "2.5YR 6/8", "5YR 5/4", "5YR 6/6", "5YR 7/4", "5YR 7/6",
    "7.5YR 6/4", "7.5YR 5/4", "7.5YR 7/4", "10YR 7/3", "10YR 8/2", "10YR 6/3", "2.5Y 7/3",
    "2.5Y 8/3", "10YR 5/1", "10YR 6/1", "10YR 4/2", "5Y 5/1", "N5", "10YR 3/1"};
}  // namespace

ScenarioGenerator::ScenarioGenerator(const MunsellTable& munsell) : munsell_(munsell) {}

std::vector<Eigen::Vector2d> ScenarioGenerator::irregularOutline(double length, double width,
                                                                 std::mt19937& rng) {
  // few corners and uneven radii: broken edges are straight-ish with sharp corners
  const int n = 6 + static_cast<int>(rng() % 5);
  std::vector<double> radius(n);
  for (auto& r : radius) r = uniform(rng, 0.70, 1.10);
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * (i + uniform(rng, -0.3, 0.3)) / n;
    // light smoothing keeps the outline from getting spiky
    const double r = 0.7 * radius[i] + 0.15 * radius[(i + 1) % n] + 0.15 * radius[(i + n - 1) % n];
    pts.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  Eigen::Vector2d lo = pts[0], hi = pts[0];
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d centre = (lo + hi) / 2, ext = hi - lo;
  for (auto& p : pts) {
    p = Eigen::Vector2d((p.x() - centre.x()) / ext.x() * length, (p.y() - centre.y()) / ext.y() * width);
  }
  return pts;
}

std::vector<SherdSpec> ScenarioGenerator::generate(const GeneratorOptions& o) const {
  std::mt19937 rng(o.seed);
  std::vector<SherdSpec> out;
  if (o.count <= 0) return out;
  // grid of cells that gives every sherd the largest room
  int best_rows = 1;
  double best = -1;
  for (int rows = 1; rows <= o.count; ++rows) {
    const int cols = (o.count + rows - 1) / rows;
    const double m = std::min(o.area.size.x() / cols, o.area.size.y() / rows);
    if (m > best) {
      best = m;
      best_rows = rows;
    }
  }
  const int rows = best_rows, cols = (o.count + rows - 1) / rows;
  const Eigen::Vector2d cell(o.area.size.x() / cols, o.area.size.y() / rows);
  const bool long_along_y = cell.y() > cell.x();
  const double cell_long = std::max(cell.x(), cell.y()), cell_short = std::min(cell.x(), cell.y());

  std::vector<std::string> chips;
  for (const char* c : kWareChips) {
    if (munsell_.has(c)) chips.emplace_back(c);
  }
  if (chips.empty()) chips.push_back(munsell_.notations().front());

  std::vector<Eigen::Vector2d> extents(o.count);  // outline length and width of each sherd
  for (int i = 0; i < o.count; ++i) {
    SherdSpec s;
    char name[32];
    std::snprintf(name, sizeof name, "sherd_%02d", i);
    s.name = name;
    // on a grid a sherd fits its cell; in a heap sherds lie on each other
    const double max_len = o.heap ? o.length_max : std::max(0.02, cell_long - o.min_spacing);
    const double max_wid = o.heap ? o.width_max : std::max(0.02, cell_short - o.min_spacing);
    double length = uniform(rng, std::min(o.length_min, max_len), std::min(o.length_max, max_len));
    double width = uniform(rng, std::min(o.width_min, max_wid), std::min(o.width_max, max_wid));
    width = std::min(width, length);
    s.thickness = uniform(rng, o.thickness_min, o.thickness_max);
    s.curvature = uniform(rng, 0.0, 15.0);
    s.curvature_long = uniform(rng, 0.0, 4.0);
    s.convex_up = (rng() % 4) != 0;
    s.density = uniform(rng, o.density_min, o.density_max);
    s.munsell = chips[rng() % chips.size()];
    s.colour = munsell_.srgb(s.munsell);
    if (uniform(rng, 0.0, 1.0) < o.painted_fraction) {
      s.pattern = (rng() % 2) ? "stripes" : "band";
      static const Eigen::Vector3d paints[] = {{0.12, 0.09, 0.07}, {0.55, 0.20, 0.12}, {0.88, 0.83, 0.70}};
      s.pattern_colour = paints[rng() % 3];
    }
    if (i < o.mesh_count && !o.mesh_file.empty()) {
      s.mesh_file = o.mesh_file;
      const Mesh m = Mesh::loadStl(o.mesh_file, s.colour);
      const Eigen::Vector3d ext = m.maxCorner() - m.minCorner();
      length = std::max(ext.x(), ext.y());
      width = std::min(ext.x(), ext.y());
    } else {
      s.outline = irregularOutline(length, width, rng);
    }
    // major axis along the cell's long side, turned a little where the cell leaves room
    double yaw = long_along_y ? kPi / 2 : 0.0;
    double jitter = uniform(rng, -0.35, 0.35);
    for (int k = 0; k < 8; ++k, jitter *= 0.5) {
      const Eigen::Vector2d e = turnedExtents(length, width, yaw + jitter);
      if (e.x() <= cell.x() - o.min_spacing && e.y() <= cell.y() - o.min_spacing) break;
    }
    yaw += jitter + ((rng() % 2) ? kPi : 0.0);
    const Eigen::Vector2d ext = turnedExtents(length, width, yaw);
    const int r = i / cols, c = i % cols;
    // in the mat's own frame (a turned mat turns its grid)
    Eigen::Vector2d centre(-o.area.size.x() / 2 + (c + 0.5) * cell.x(), -o.area.size.y() / 2 + (r + 0.5) * cell.y());
    const Eigen::Vector2d slack = (cell - ext - Eigen::Vector2d::Constant(o.min_spacing)).cwiseMax(0.0);
    centre.x() += uniform(rng, -slack.x() / 2, slack.x() / 2 + 1e-12);
    centre.y() += uniform(rng, -slack.y() / 2, slack.y() / 2 + 1e-12);
    const Eigen::Vector2d at = o.area.toTable(centre);
    s.pose = Eigen::Vector3d(at.x(), at.y(), std::remainder(yaw + o.area.yaw, 2 * kPi));
    extents[i] = Eigen::Vector2d(length, width);
    out.push_back(s);
  }
  if (o.heap) {
    heapUp(out, extents, o, rng);
    return out;
  }
  // touching pairs: neighbours in a row pushed together along x until their (collision) boxes
  // are 0.2 mm apart
  int pairs = 0;
  for (int i = 0; i + 1 < o.count && pairs < o.touching_pairs; i += 2) {
    if (i / cols != (i + 1) / cols) continue;
    const Eigen::Vector2d ha = extents[i] / 2, hb = extents[i + 1] / 2;
    double lo_s = 0.0, hi_s = out[i + 1].pose.x() - out[i].pose.x();
    for (int k = 0; k < 60; ++k) {
      const double mid = (lo_s + hi_s) / 2;
      Eigen::Vector3d a = out[i].pose, b = out[i + 1].pose;
      a.x() += mid / 2;
      b.x() -= mid / 2;
      (boxGap(a, ha, b, hb) > 0.0002 ? lo_s : hi_s) = mid;
    }
    out[i].pose.x() += lo_s / 2;
    out[i + 1].pose.x() -= lo_s / 2;
    ++pairs;
  }
  return out;
}

void ScenarioGenerator::heapUp(std::vector<SherdSpec>& sherds, const std::vector<Eigen::Vector2d>& extents,
                               const GeneratorOptions& o, std::mt19937& rng) {
  std::vector<double> top(sherds.size(), 0.0);  // [m] top of each sherd as let go, above the table
  std::vector<int> layer(sherds.size(), 0);     // 1: on the mat, 2: on a sherd on the mat, ...
  for (size_t i = 0; i < sherds.size(); ++i) {
    SherdSpec& s = sherds[i];
    // the box the sherd occupies: its wall plus the bend of a shell over its half length
    // (sag = k r^2 / 2, the simulator's shell), a millimetre more for the outline's corners
    const double r = extents[i].x() / 2;
    const double height = s.thickness + 0.5 * (std::abs(s.curvature) + std::abs(s.curvature_long)) * r * r + 0.001;
    // where it falls: about the heap's centre, on the mat, never deeper than heap_layers (a
    // sherd that would come to lie higher rolls off the pile: drawn again, a little wider)
    double spread = o.heap_spread;
    for (int attempt = 0;; ++attempt) {
      std::normal_distribution<double> scatter(0.0, spread);
      const double yaw = uniform(rng, -kPi, kPi);  // in the mat's own frame, as lo and hi
      const Eigen::Vector2d half = turnedExtents(extents[i].x(), extents[i].y(), yaw) / 2;
      const Eigen::Vector2d lo = -o.area.size / 2 + half, hi = o.area.size / 2 - half;
      const Eigen::Vector2d scattered = o.area.toLocal(o.heap_centre) + Eigen::Vector2d(scatter(rng), scatter(rng));
      const Eigen::Vector2d c = o.area.toTable(scattered.cwiseMax(lo).cwiseMin(hi));
      s.pose = Eigen::Vector3d(c.x(), c.y(), yaw + o.area.yaw);
      double under = 0.0;
      int depth = 1;
      for (size_t j = 0; j < i; ++j) {
        if (boxGap(sherds[j].pose, extents[j] / 2, s.pose, extents[i] / 2) < 0.0) {
          under = std::max(under, top[j]);
          depth = std::max(depth, layer[j] + 1);
        }
      }
      if (depth <= o.heap_layers || attempt >= 200) {
        s.drop_height = o.heap_drop_height + under;
        top[i] = s.drop_height + height;
        layer[i] = depth;
        break;
      }
      if (attempt % 10 == 9) spread *= 1.2;
    }
  }
}

}  // namespace rascal_sim
