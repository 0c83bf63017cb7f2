#include "rascal_perception/ScaleBarFinder.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace rascal_perception {

namespace {

// One near-square blob of the adaptive threshold: a chequer square candidate.
struct Square {
  cv::Point2d centre;
  double side;   ///< estimated side (the erosion added back)
  double angle;  ///< edge direction in [0, pi/2)
  bool bright;
};

// A lattice hypothesis: square (i, j) has its centre at origin + i * a + j * b; |a| = pitch along
// the bar, b across it (perp(a) unless both rows were seen: a bar seen obliquely is foreshortened).
struct Lattice {
  cv::Point2d origin, a, b;
  std::vector<int> members;  ///< indices into the squares
  std::vector<cv::Point> cells;
  double residual = 0.0;
};

cv::Point2d perp(const cv::Point2d& v) { return {-v.y, v.x}; }

double wrapQuarter(double angle) {
  angle = std::fmod(angle, CV_PI / 2);
  return angle < 0 ? angle + CV_PI / 2 : angle;
}

double quarterDiff(double a, double b) {
  const double d = std::fabs(wrapQuarter(a - b));
  return std::min(d, CV_PI / 2 - d);
}

// Near-square blobs of both polarities. Eroding cuts the corner contacts of a chequer's diagonal
// neighbours (blur and bloom join them there; twice where a row cut by the frame leaves a sliver);
// two block sizes cover 8-30 px squares.
void collectSquares(const cv::Mat& gray, std::vector<Square>& squares) {
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  for (const int block : {21, 51}) {
    cv::Mat mean;
    cv::blur(gray, mean, {block, block}, {-1, -1}, cv::BORDER_REPLICATE);
    for (const bool bright : {true, false}) {
      cv::Mat bin = bright ? gray > mean + 6 : gray < mean - 6;
      for (int erosions = 1; erosions <= 2; ++erosions) {
        cv::erode(bin, bin, kernel);
        std::vector<std::vector<cv::Point>> contours;
        std::vector<cv::Vec4i> hierarchy;
        cv::findContours(bin, contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_SIMPLE);
        for (size_t k = 0; k < contours.size(); ++k) {
          if (hierarchy[k][3] >= 0) continue;  // a hole: the inside of a hollow square, not a square
          const std::vector<cv::Point>& c = contours[k];
          const cv::Rect r = cv::boundingRect(c);
          if (r.width < 3 || r.height < 3 || r.width > 60 || r.height > 60) continue;
          const cv::Moments m = cv::moments(c);
          if (m.m00 < 9) continue;
          const cv::RotatedRect box = cv::minAreaRect(c);
          const double w = box.size.width, h = box.size.height;
          // aspect of the square before erosion; a bar seen obliquely foreshortens them
          if (std::max(w, h) + 2 * erosions > 1.4 * (std::min(w, h) + 2 * erosions)) continue;
          if (m.m00 < 0.75 * w * h) continue;  // a square fills its box; a blob of texture does not
          const double side = std::sqrt(m.m00) + 2.0 * erosions;
          if (side < 6 || side > 40) continue;
          const cv::Point2d centre(m.m10 / m.m00, m.m01 / m.m00);
          bool dup = false;
          for (const Square& s : squares) {
            if (s.bright == bright && cv::norm(s.centre - centre) < 0.3 * side) dup = true;
          }
          if (!dup) squares.push_back({centre, side, wrapQuarter(box.angle * CV_PI / 180.0), bright});
        }
      }
    }
  }
}

// Least squares of centre = origin + i * a + j * b over the members: linear. With one row (or one
// column) seen, b = perp(a).
bool fitLattice(const std::vector<Square>& squares, Lattice& lat) {
  const int n = (int)lat.members.size();
  int imin = 99, imax = -99, jmin = 99, jmax = -99;
  for (const cv::Point& c : lat.cells) {
    imin = std::min(imin, c.x), imax = std::max(imax, c.x), jmin = std::min(jmin, c.y), jmax = std::max(jmax, c.y);
  }
  const bool affine = n >= 4 && imax > imin && jmax > jmin;
  cv::Mat A = cv::Mat::zeros(2 * n, affine ? 6 : 4, CV_64F), rhs(2 * n, 1, CV_64F);
  for (int k = 0; k < n; ++k) {
    const double i = lat.cells[k].x, j = lat.cells[k].y;
    const cv::Point2d& c = squares[lat.members[k]].centre;
    double* rx = A.ptr<double>(2 * k);
    double* ry = A.ptr<double>(2 * k + 1);
    if (affine) {  // (ox, oy, ax, ay, bx, by)
      rx[0] = 1, rx[2] = i, rx[4] = j;
      ry[1] = 1, ry[3] = i, ry[5] = j;
    } else {  // (ox, oy, ax, ay), b = (-ay, ax)
      rx[0] = 1, rx[2] = i, rx[3] = -j;
      ry[1] = 1, ry[2] = j, ry[3] = i;
    }
    rhs.at<double>(2 * k) = c.x, rhs.at<double>(2 * k + 1) = c.y;
  }
  cv::Mat x;
  if (!cv::solve(A, rhs, x, cv::DECOMP_SVD)) return false;
  lat.origin = {x.at<double>(0), x.at<double>(1)};
  lat.a = {x.at<double>(2), x.at<double>(3)};
  lat.b = affine ? cv::Point2d(x.at<double>(4), x.at<double>(5)) : perp(lat.a);
  const cv::Mat r = A * x - rhs;
  lat.residual = std::sqrt(r.dot(r) / std::max(1, r.rows));
  const double na = cv::norm(lat.a), nb = cv::norm(lat.b);
  // a chequer seen from above: rows at most 40 % shorter, roughly square to the bar
  return na > 3 && nb > 0.6 * na && nb < 1.4 * na && std::fabs(lat.a.dot(lat.b)) < 0.3 * na * nb;
}

// Squares that sit on the lattice (within `tol` of a cell; more across, for foreshortening), with
// the colour parity of a chequer and the lattice's edge direction.
void collectMembers(const std::vector<Square>& squares, const std::vector<int>& near, int seed, Lattice& lat,
                    double tol) {
  const double det = lat.a.x * lat.b.y - lat.a.y * lat.b.x;
  const double pitch = cv::norm(lat.a);
  lat.members.clear();
  lat.cells.clear();
  for (const int k : near) {
    const Square& q = squares[k];
    if (q.side < 0.6 * pitch || q.side > 1.4 * pitch) continue;
    const cv::Point2d d = q.centre - lat.origin;
    const double x = (d.x * lat.b.y - d.y * lat.b.x) / det, y = (lat.a.x * d.y - lat.a.y * d.x) / det;
    const int i = (int)std::lround(x), j = (int)std::lround(y);
    if (std::abs(i) > 5 || std::abs(j) > 5) continue;  // a seed is at most 4 columns from the others
    if (std::fabs(x - i) > tol || std::fabs(y - j) > 1.5 * tol) continue;
    if (((std::abs(i + j) % 2) == 0) != (q.bright == squares[seed].bright)) continue;
    if (quarterDiff(q.angle, std::atan2(lat.a.y, lat.a.x)) > 0.25) continue;
    bool taken = false;
    for (size_t m = 0; m < lat.cells.size(); ++m) taken |= lat.cells[m] == cv::Point(i, j);
    if (taken) continue;
    lat.members.push_back(k);
    lat.cells.emplace_back(i, j);
  }
}

// Keeps the members inside the best 5 x 2 window of the lattice (either axis may be the bar's),
// re-indexed so the window's corner is (0, 0) and i runs along the bar.
void bestWindow(Lattice& lat) {
  int best = -1;
  Lattice out;
  for (int axis = 0; axis < 2; ++axis) {
    for (int i0 = -5; i0 <= 5; ++i0) {
      for (int j0 = -5; j0 <= 5; ++j0) {
        int n = 0;
        for (const cv::Point& c : lat.cells) {
          const int i = axis == 0 ? c.x : c.y, j = axis == 0 ? c.y : c.x;
          n += i >= i0 && i < i0 + 5 && j >= j0 && j < j0 + 2;
        }
        if (n <= best) continue;
        best = n;
        out = Lattice();
        for (size_t k = 0; k < lat.cells.size(); ++k) {
          const cv::Point& c = lat.cells[k];
          const int i = axis == 0 ? c.x : c.y, j = axis == 0 ? c.y : c.x;
          if (i >= i0 && i < i0 + 5 && j >= j0 && j < j0 + 2) {
            out.members.push_back(lat.members[k]);
            // along the other axis the rows run the other way: a' = b, b' = -a
            out.cells.emplace_back(i - i0, axis == 0 ? j - j0 : j0 + 1 - j);
          }
        }
        if (axis == 0) {
          out.a = lat.a, out.b = lat.b;
          out.origin = lat.origin + i0 * lat.a + j0 * lat.b;
        } else {
          // centre = o + i b + j a = o' + (i - i0) b + (j0 + 1 - j) (-a)
          out.a = lat.b, out.b = -lat.a;
          out.origin = lat.origin + i0 * lat.b + (j0 + 1) * lat.a;
        }
      }
    }
  }
  lat = out;
}

// Mean grey of a patch half a cell wide around p (integral image), clipped to the image: a bar
// touching the frame still shows part of its outer row. NaN when the centre is off the image.
double cellMean(const cv::Mat& integral, const cv::Point2d& p, double half) {
  const int w = integral.cols - 1, h = integral.rows - 1;
  if (p.x < 0 || p.y < 0 || p.x >= w || p.y >= h) return std::nan("");
  const int x0 = std::max(0, (int)std::lround(p.x - half)), x1 = std::min(w, (int)std::lround(p.x + half) + 1);
  const int y0 = std::max(0, (int)std::lround(p.y - half)), y1 = std::min(h, (int)std::lround(p.y + half) + 1);
  const double s = integral.at<double>(y1, x1) - integral.at<double>(y0, x1) - integral.at<double>(y1, x0) +
                   integral.at<double>(y0, x0);
  return s / ((x1 - x0) * (y1 - y0));
}

// Where the bar lies along the lattice: chequer columns [first, first + 5), solid half on `side`.
struct Layout {
  int first = 0;
  int side = 0;  ///< +1: solid half after the chequer along a, -1: before it
  double chequer = 0, solid = 0;
  int chequer_ok = 0, solid_ok = 0;
  int steps = 0;  ///< tone steps along a row between cells that should match
};

// Reads the row difference of each column (row 0 minus row 1). A chequer column's sign alternates;
// the solid half's is the same over five columns. The chequer squares found fix the alternation.
bool readLayout(const cv::Mat& integral, const std::vector<Square>& squares, const Lattice& lat, Layout& best) {
  const double pitch = cv::norm(lat.a);
  const cv::Point2d b = lat.b;
  const int lo = -10, hi = 15;
  std::vector<double> d(hi - lo), row0(hi - lo), row1(hi - lo);
  for (int c = lo; c < hi; ++c) {
    // each row sampled nearer the bar's middle line than its centre: a foreshortened or cut
    // outer row still lies under the patch
    const double g0 = cellMean(integral, lat.origin + c * lat.a + 0.15 * b, 0.2 * pitch);
    const double g1 = cellMean(integral, lat.origin + c * lat.a + 0.85 * b, 0.2 * pitch);
    // a contrast ratio: a shadow across the bar scales both rows alike
    d[c - lo] = std::isnan(g0) || std::isnan(g1) ? 0.0 : (g0 - g1) / (g0 + g1 + 10.0);
    row0[c - lo] = g0, row1[c - lo] = g1;
  }
  // sign of row 0 minus row 1 in column 0 of the chequer
  const cv::Point& c0 = lat.cells[0];
  const bool bright0 = squares[lat.members[0]].bright;
  const int sigma0 = ((bright0 == (c0.y == 0)) ? 1 : -1) * ((c0.x % 2) ? -1 : 1);
  std::vector<double> mags;
  int imin = 99, imax = -99;
  for (const cv::Point& c : lat.cells) {
    mags.push_back(std::fabs(d[c.x - lo]));
    imin = std::min(imin, c.x), imax = std::max(imax, c.x);
  }
  std::nth_element(mags.begin(), mags.begin() + mags.size() / 2, mags.end());
  const double contrast = mags[mags.size() / 2];
  if (contrast < 0.1) return false;
  bool any = false;
  for (int first = imax - 4; first <= imin; ++first) {
    double chequer = 0;
    int chequer_ok = 0;
    for (int c = first; c < first + 5; ++c) {
      const double v = sigma0 * ((c % 2) ? -1 : 1) * d[c - lo] / contrast;
      chequer += v / 5;
      chequer_ok += v > 0.4;
    }
    for (const int side : {1, -1}) {
      const int s0 = side > 0 ? first + 5 : first - 5;
      double sum = 0;
      for (int c = s0; c < s0 + 5; ++c) sum += d[c - lo];
      const double sgn = sum >= 0 ? 1 : -1;
      int ok = 0;
      for (int c = s0; c < s0 + 5; ++c) ok += sgn * d[c - lo] / contrast > 0.4;
      const double solid = std::fabs(sum) / 5 / contrast;
      // each row keeps its tones: a chequer cell like the one two columns on, a solid cell like
      // its neighbour, measured against the columns' own black-to-white (a shadow changes tones
      // slowly or at one edge; a mosaic everywhere). Within rows, so a shadow along the bar
      // darkening one row is no step.
      int steps = 0;
      auto step = [&](int c, int c2) {
        for (const std::vector<double>* row : {&row0, &row1}) {
          const double g = (*row)[c - lo], h = (*row)[c2 - lo];
          if (std::isnan(g) || std::isnan(h) || std::isnan(row0[c2 - lo] - row1[c2 - lo])) continue;
          const double swing =
              0.5 * (std::fabs(row0[c - lo] - row1[c - lo]) + std::fabs(row0[c2 - lo] - row1[c2 - lo]));
          steps += std::fabs(g - h) > 0.35 * swing;
        }
      };
      for (int c = first; c + 2 < first + 5; ++c) step(c, c + 2);
      for (int c = s0; c + 1 < s0 + 5; ++c) step(c, c + 1);
      const double score = chequer + solid + 0.2 * (ok - steps);
      if (!any || score > best.chequer + best.solid + 0.2 * (best.solid_ok - best.steps)) {
        best = {first, side, chequer, solid, chequer_ok, ok, steps};
        any = true;
      }
    }
  }
  return any;
}

// Sub-pixel crossings of the level halfway between neighbouring cells, along the middle of each
// row, at the chequer's four inner edges per row. Same-direction edges are 2 cells apart whatever
// the bloom, so the pitch is fitted with one intercept per row and direction.
bool edgePitch(const cv::Mat& gray, const Lattice& lat, const Layout& lay, double& pitch, double& spread) {
  const double p = cv::norm(lat.a);
  const cv::Point2d u = lat.a / p, b = lat.b;
  const double step = 0.25;
  std::vector<double> xs, ys;  // (index, position) pairs per group
  std::vector<int> group;
  for (int row = 0; row < 2; ++row) {
    // three lines along the row (nearer the middle line, as above), averaged: less noise than one
    const int n = (int)std::ceil(7 * p / step);
    cv::Mat mapx(1, n, CV_32F), mapy(1, n, CV_32F), prof = cv::Mat::zeros(1, n, CV_32F);
    for (const double off : {-0.1, 0.0, 0.1}) {
      const cv::Point2d start = lat.origin + (lay.first - 1.0) * lat.a + (0.15 + 0.7 * row + off) * b;
      for (int k = 0; k < n; ++k) {
        const cv::Point2d q = start + k * step * u;
        mapx.at<float>(k) = (float)q.x, mapy.at<float>(k) = (float)q.y;
      }
      cv::Mat line;
      cv::remap(gray, line, mapx, mapy, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      cv::Mat f;
      line.convertTo(f, CV_32F);
      prof += f / 3.0;
    }
    // edge e (1..4) between chequer columns e-1 and e lies near (e + 0.5) p from the start
    for (int e = 1; e <= 4; ++e) {
      const double x0 = (e + 0.5) * p / step;  // expected edge, in samples
      const int left = (int)std::lround(x0 - 0.5 * p / step), right = (int)std::lround(x0 + 0.5 * p / step);
      auto mean = [&](int from, int to) {
        double s = 0;
        int cnt = 0;
        for (int k = std::max(0, from); k <= std::min(n - 1, to); ++k) s += prof.at<float>(k), ++cnt;
        return cnt ? s / cnt : 0.0;
      };
      const int w = std::max(1, (int)std::lround(0.2 * p / step));
      const double gl = mean(left - w, left + w), gr = mean(right - w, right + w);
      if (std::fabs(gl - gr) < 10) continue;
      const double level = 0.5 * (gl + gr);
      // the crossing nearest the expected edge, searched within a third of a cell
      const int r = (int)std::lround(0.35 * p / step);
      double best = -1, bestDist = 1e9;
      for (int k = std::max(0, (int)x0 - r); k < std::min(n - 1, (int)x0 + r); ++k) {
        const double v0 = prof.at<float>(k) - level, v1 = prof.at<float>(k + 1) - level;
        if ((v0 <= 0) == (v1 <= 0) || v0 == v1) continue;
        const double pos = k + v0 / (v0 - v1);
        if (std::fabs(pos - x0) < bestDist) bestDist = std::fabs(pos - x0), best = pos;
      }
      if (best < 0) continue;
      xs.push_back(e);
      ys.push_back(best * step);
      group.push_back(row * 2 + (gr > gl ? 1 : 0));
    }
  }
  // y = slope * e + intercept[group]; only groups with two edges carry the slope
  int counts[4] = {0, 0, 0, 0};
  for (int g : group) ++counts[g];
  double sxx = 0, sxy = 0;
  double mx[4] = {0, 0, 0, 0}, my[4] = {0, 0, 0, 0};
  for (size_t k = 0; k < xs.size(); ++k) {
    mx[group[k]] += xs[k] / counts[group[k]], my[group[k]] += ys[k] / counts[group[k]];
  }
  std::vector<double> pairs;
  for (size_t k = 0; k < xs.size(); ++k) {
    if (counts[group[k]] < 2) continue;
    sxx += (xs[k] - mx[group[k]]) * (xs[k] - mx[group[k]]);
    sxy += (xs[k] - mx[group[k]]) * (ys[k] - my[group[k]]);
    for (size_t m = k + 1; m < xs.size(); ++m) {
      if (group[m] == group[k]) pairs.push_back((ys[m] - ys[k]) / (xs[m] - xs[k]));
    }
  }
  if (pairs.size() < 2 || sxx <= 0) return false;
  pitch = sxy / sxx;
  double var = 0;
  for (double q : pairs) var += (q - pitch) * (q - pitch);
  spread = std::sqrt(var / pairs.size()) / pitch;
  return std::fabs(pitch - p) < 0.1 * p;
}

// The bar's length from its ends: the mean across both rows (half black, half white over the
// solid half, and about so over the chequer) against the cloth beyond, crossed halfway, within
// half a cell of where the lattice puts each end. 0 when an end is off the image or unclear.
double endToEnd(const cv::Mat& gray, const Lattice& lat, const Layout& lay) {
  const double p = cv::norm(lat.a), step = 0.25;
  const cv::Point2d u = lat.a / p;
  const double lo = std::min(lay.first, lay.first + 5 * lay.side) - 0.5;  // in cells from the origin
  const double hi = lo + 10;
  double ends[2];
  for (int e = 0; e < 2; ++e) {
    const double at = e == 0 ? lo : hi, dir = e == 0 ? -1 : 1;  // outwards
    const int n = (int)std::ceil(2 * p / step);  // one cell in, one cell out
    cv::Mat mapx(5, n, CV_32F), mapy(5, n, CV_32F);
    for (int r = 0; r < 5; ++r) {
      for (int k = 0; k < n; ++k) {
        const cv::Point2d q = lat.origin + (at - dir) * lat.a + (0.1 + 0.2 * r) * lat.b + dir * k * step * u;
        mapx.at<float>(r, k) = (float)q.x, mapy.at<float>(r, k) = (float)q.y;
        if (q.x < 0 || q.y < 0 || q.x > gray.cols - 1 || q.y > gray.rows - 1) return 0.0;
      }
    }
    cv::Mat lines, prof;
    cv::remap(gray, lines, mapx, mapy, cv::INTER_LINEAR);
    cv::reduce(lines, prof, 0, cv::REDUCE_AVG, CV_32F);
    const int w = std::max(1, (int)std::lround(0.3 * p / step));
    const double inside = cv::mean(prof.colRange(0, w))[0], outside = cv::mean(prof.colRange(n - w, n))[0];
    if (std::fabs(inside - outside) < 15) return 0.0;
    const double level = 0.5 * (inside + outside);
    double found = -1;
    for (int k = w; k < n - w && found < 0; ++k) {  // first crossing going out
      const double v0 = prof.at<float>(k) - level, v1 = prof.at<float>(k + 1) - level;
      if ((v0 <= 0) != (v1 <= 0) && v0 != v1) found = k + v0 / (v0 - v1);
    }
    if (found < 0) return 0.0;
    ends[e] = (at - dir) * p + dir * found * step;  // along a, from the origin
  }
  return ends[1] - ends[0];
}

}  // namespace

ScaleBar findScaleBar(const cv::Mat& rgb, const ScaleBarOptions& options) {
  ScaleBar result;
  if (rgb.empty() || rgb.type() != CV_8UC3) return result;
  cv::Mat gray;
  cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
  std::vector<Square> squares;
  collectSquares(gray, squares);
  cv::Mat integral;
  cv::integral(gray, integral, CV_64F);

  // Each square seeds a lattice along its edge direction. Its size is only a first guess of the
  // pitch (bloom, erosion, foreshortening): each neighbour read as a lattice step of the right
  // colour parity proposes a pitch, and the proposal with most members wins. The hypotheses with
  // most squares are then checked for the solid half.
  std::vector<Lattice> hypotheses;
  for (int s = 0; s < (int)squares.size(); ++s) {
    const Square& seed = squares[s];
    const cv::Point2d u(std::cos(seed.angle), std::sin(seed.angle));
    // squares a 5 x 5 lattice around the seed can reach (pitch at most 1.5 x its side)
    std::vector<int> near;
    for (int m = 0; m < (int)squares.size(); ++m) {
      if (cv::norm(squares[m].centre - seed.centre) < 11 * seed.side) near.push_back(m);
    }
    Lattice best;
    for (const int m : near) {
      const cv::Point2d d = squares[m].centre - seed.centre;
      const double dist = cv::norm(d);
      if (m == s || dist > 5 * seed.side || dist < 0.5 * seed.side) continue;
      const double x = d.dot(u), y = d.dot(perp(u));
      for (int i = -4; i <= 4; ++i) {
        for (int j = -4; j <= 4; ++j) {
          if (std::min(std::abs(i), std::abs(j)) > 1 || (i == 0 && j == 0)) continue;
          if (((std::abs(i + j) % 2) == 0) != (squares[m].bright == seed.bright)) continue;
          const double p = dist / std::hypot(i, j);
          if (p < 0.75 * seed.side || p > 1.5 * seed.side) continue;
          if (std::hypot(x / p - i, y / p - j) > 0.3) continue;
          Lattice lat;
          lat.origin = seed.centre;
          lat.a = p * u;
          lat.b = perp(lat.a);
          collectMembers(squares, near, s, lat, 0.2);
          if (lat.members.size() > best.members.size()) best = lat;
        }
      }
    }
    Lattice lat = best;
    if (lat.members.size() < 3 || !fitLattice(squares, lat)) continue;
    collectMembers(squares, near, s, lat, 0.15);  // again with the fitted lattice
    if (lat.members.size() < 3) continue;
    bestWindow(lat);
    if (lat.members.size() < 3 || !fitLattice(squares, lat)) continue;
    if (lat.residual > 0.12 * cv::norm(lat.a)) continue;
    bool seen = false;  // other seeds of the same chequer find the same squares
    std::vector<int> sorted = lat.members;
    std::sort(sorted.begin(), sorted.end());
    for (const Lattice& other : hypotheses) {
      std::vector<int> o = other.members;
      std::sort(o.begin(), o.end());
      seen |= o == sorted;
    }
    if (seen) continue;
    hypotheses.push_back(lat);
    // one row seen: it may be either row of the bar
    bool one_row = true;
    for (const cv::Point& c : lat.cells) one_row &= c.y == lat.cells[0].y;
    if (one_row) {
      for (cv::Point& c : lat.cells) c.y = 1 - c.y;
      lat.origin += (1 - 2 * lat.cells[0].y) * lat.b;
      hypotheses.push_back(lat);
    }
  }
  std::sort(hypotheses.begin(), hypotheses.end(), [](const Lattice& x, const Lattice& y) {
    return x.members.size() != y.members.size() ? x.members.size() > y.members.size() : x.residual < y.residual;
  });

  const double square_cm = options.bar_length_cm / 10.0;
  int chosen = -1;
  Layout lay;
  for (int h = 0; h < (int)std::min<size_t>(hypotheses.size(), 12); ++h) {
    const Lattice& lat = hypotheses[h];
    Layout l;
    const bool rl = readLayout(integral, squares, lat, l);
    // chequer columns alternating, the solid half beside them; a curled end costs about three
    // steps, a sharp shadow edge two
    if (!rl || l.chequer < 0.5 || l.solid_ok < 3 || l.steps > 4) continue;
    // most squares first; among equals (a row read either way) the clearer layout
    if (chosen >= 0 && (hypotheses[chosen].members.size() > lat.members.size() ||
                        l.chequer + l.solid <= lay.chequer + lay.solid)) continue;
    chosen = h;
    lay = l;
  }
  if (chosen >= 0) {
    const Lattice& lat = hypotheses[chosen];
    double pitch = cv::norm(lat.a), spread = 0;
    const bool edges = edgePitch(gray, lat, lay, pitch, spread);
    result.found = true;
    result.px_per_cm = pitch / square_cm;
    result.pitch_spread = spread;
    result.squares = (int)lat.members.size();
    // the bar's middle is the boundary between its halves
    const double mid = lay.side > 0 ? lay.first + 4.5 : lay.first - 0.5;
    const cv::Point2d centre = lat.origin + mid * lat.a + 0.5 * lat.b;
    result.box = cv::RotatedRect(cv::Point2f((float)centre.x, (float)centre.y),
                                 cv::Size2f((float)(10 * pitch), (float)(2 * cv::norm(lat.b))),
                                 (float)(std::atan2(lat.a.y, lat.a.x) * 180.0 / CV_PI));
    // the ends only confirm: a curled end or one in a shadow shortens the bar
    const double length = endToEnd(gray, lat, lay);
    const double by_ends = length / options.bar_length_cm;
    result.ends_px_per_cm = by_ends;
    if (length > 0 && std::fabs(by_ends / result.px_per_cm - 1) > 0.05) {
      result.doubt = "the bar's ends give " + std::to_string((int)std::lround(by_ends * 10) / 10.0).substr(0, 5) +
                     " px/cm, the chequer " + std::to_string(result.px_per_cm).substr(0, 5);
    }
    // a whole bar reads as about 1 in both halves (the same inks); less is a cut or curled bar,
    // or a pattern that only resembles it
    if (lay.chequer < 0.7 || lay.solid < 0.6 || lay.solid_ok < 4) {
      result.doubt = "weak bar pattern (cut, curled or not a bar)";
    }
    if (!edges) {
      result.doubt = "chequer edges unreadable: px/cm from the square centres only";
    } else if (lat.members.size() < 4) {
      result.doubt = "only " + std::to_string(lat.members.size()) + " chequer squares found";
    } else if (spread > 0.03) {
      result.doubt = "chequer pitch spread " + std::to_string((int)std::lround(spread * 100)) + " %";
    }
  }
  return result;
}

}  // namespace rascal_perception
